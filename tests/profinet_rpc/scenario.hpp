#pragma once
// One AR to an AKD-like drive (digest akd-profinet-profidrive.md §4, §24 step 5): slot 0 the DAP
// (one NO_IO submodule), slot 1 telegram 1 (4 output / 4 input bytes) in PROFIdrive API 0x3A00,
// one input and one output CR of RT class 1, send clock 1 ms × reduction ratio 16 = 16 ms (the
// AKD's fastest update time, digest §2). Vendor, device and ident numbers are placeholders: the
// digest says they come from the GSDML only.
#include <array>
#include <cstdint>

#include "adapters/profinet/wire/rpc_calls.hpp"
#include "adapters/profinet/wire/rpc_connect.hpp"

namespace drivegate::profinet::test {

inline constexpr MacAddress kControllerMac{0x02, 0x00, 0x00, 0x00, 0x00, 0x01};
inline constexpr MacAddress kDeviceMac{0x02, 0x00, 0x00, 0x00, 0x00, 0x02};
inline constexpr PnioObject kDevice{1, 0x0002, 0x1234};
inline constexpr PnioObject kController{1, 0x0000, 0x1234};
inline constexpr Uuid kArUuid{0x11223344, 0x5566, 0x7788, {0x99, 0xAA, 0xBB, 0xCC, 0xDD, 0xEE, 0xFF, 0x00}};
inline constexpr Uuid kActivity{0x01020304, 0x0506, 0x0708, {0x09, 0x0A, 0x0B, 0x0C, 0x0D, 0x0E, 0x0F, 0x10}};
inline constexpr Uuid kDeviceActivity{0xA1A2A3A4, 0xB1B2, 0xC1C2, {0xD1, 0xD2, 0xD3, 0xD4, 0xD5, 0xD6, 0xD7, 0xD8}};
inline constexpr std::uint32_t kProfidriveApi = 0x3A00;
inline constexpr std::uint32_t kDapModule = 0x00000001;
inline constexpr std::uint32_t kDapSubmodule = 0x00000001;
inline constexpr std::uint32_t kTelegram1Module = 0x00000101;
inline constexpr std::uint32_t kTelegram1Submodule = 0x00000001;
inline constexpr std::uint32_t kArgsMaximum = 16696;  // what common controllers offer

struct Scenario {
  std::array<ExpectedSubmodule, 1> dap_subs{{{1, kDapSubmodule, 0, {0, 1, 1}, {}}}};
  std::array<ExpectedSubmodule, 1> tg_subs{{{1, kTelegram1Submodule, 3, {4, 1, 1}, {4, 1, 1}}}};
  std::array<ExpectedSlot, 2> expected{{{0, 0, kDapModule, 0, dap_subs}, {kProfidriveApi, 1, kTelegram1Module, 0, tg_subs}}};
  // Input CR: IOPS of the DAP at 0, telegram data 1..4 with its IOPS at 5, IOCS of the telegram's
  // output at 6. Output CR: telegram data 0..3 with IOPS at 4, IOCS of the DAP at 5 and of the
  // telegram's input at 6.
  std::array<IoObjectRef, 1> in_dap_obj{{{0, 1, 0}}};
  std::array<IoObjectRef, 1> in_tg_obj{{{1, 1, 1}}};
  std::array<IoObjectRef, 1> in_tg_iocs{{{1, 1, 6}}};
  std::array<IocrApiSpec, 2> in_apis{{{0, in_dap_obj, {}}, {kProfidriveApi, in_tg_obj, in_tg_iocs}}};
  std::array<IoObjectRef, 1> out_tg_obj{{{1, 1, 0}}};
  std::array<IoObjectRef, 1> out_dap_iocs{{{0, 1, 5}}};
  std::array<IoObjectRef, 1> out_tg_iocs{{{1, 1, 6}}};
  std::array<IocrApiSpec, 2> out_apis{{{0, {}, out_dap_iocs}, {kProfidriveApi, out_tg_obj, out_tg_iocs}}};

  ConnectRequest connect() const {
    ConnectRequest c;
    c.ar.ar_uuid = kArUuid;
    c.ar.session_key = 1;
    c.ar.initiator_mac = kControllerMac;
    c.ar.initiator_object_uuid = make_pnio_object_uuid(kController);
    c.ar.activity_timeout_factor = 600;
    c.ar.station_name = "drivegate";
    c.input.reference = 1;
    c.input.frame_id = 0xC001;
    c.input.reduction_ratio = 16;
    c.input_apis = in_apis;
    c.output.reference = 2;
    c.output.frame_id = 0xC002;
    c.output.reduction_ratio = 16;
    c.output_apis = out_apis;
    c.expected = expected;
    return c;
  }
};

inline RpcHeader device_call(Opnum op, std::uint32_t seq, ByteOrder order = ByteOrder::Little) {
  return pnio_request_header(make_pnio_object_uuid(kDevice), kPnioDeviceInterface, kActivity, seq, op, order);
}

}  // namespace drivegate::profinet::test
