#pragma once
// One AR's cyclic data for the RtProvider/RtConsumer tests: a DAP (no IO), a drive submodule with
// 4 octets each way (a telegram-1-like STW1/NSOLL and ZSW1/NIST) and a 2-octet input submodule;
// 1 ms send clock (factor 32) with reduction ratio 2 and phase 2, data hold factor 3. Input frames
// are built here the way a device sends them.
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "adapters/profinet/controller/rt_cyclic.hpp"

namespace drivegate::profinet::test {

using Bytes = std::vector<std::uint8_t>;

inline constexpr MacAddress kController{0x02, 0x00, 0x00, 0x00, 0x00, 0x01};
inline constexpr MacAddress kDevice{0x00, 0x1B, 0x1B, 0x12, 0x34, 0x56};
inline constexpr std::uint16_t kOutputFrameId = 0x8001;
inline constexpr std::uint16_t kInputFrameId = 0x8002;
inline constexpr std::array<IoSubmodule, 3> kSubmodules{
    {{IoKind::NoIo, 0, 0}, {IoKind::InputOutput, 4, 4}, {IoKind::Input, 2, 0}}};
inline constexpr std::size_t kDrive = 1;  // index of the drive submodule
inline constexpr std::size_t kSensor = 2;

inline RtIocrConfig iocr(std::uint16_t frame) {
  RtIocrConfig c;
  c.frame_id = frame;
  c.controller_mac = kController;
  c.device_mac = kDevice;
  c.send_clock_factor = 32;
  c.reduction_ratio = 2;
  c.phase = 2;
  c.data_hold_factor = 3;
  c.submodules = kSubmodules;
  return c;
}

// A device's input frame: the input CR's C_SDU with every IOPS and IOCS good unless changed by
// `edit`, the drive's data 11 22 33 44, the sensor's AB CD.
struct InputFrame {
  std::uint16_t cycle = 0;
  std::uint8_t data_status = data_status::kGood;
  std::uint8_t transfer_status = 0;
  std::uint16_t frame_id = kInputFrameId;
  MacAddress source = kDevice;
  std::uint8_t drive_iops = iox_status::kGood;
  std::uint8_t sensor_iops = iox_status::kGood;
};

inline Bytes input_frame(const InputFrame& f) {
  std::array<IoPlacement, 3> p{};
  const CsduLayout l = compute_csdu_layout(CrDirection::Input, kSubmodules, p);
  std::array<std::uint8_t, kMaxCsduLength> c_sdu{};
  for (const IoPlacement& q : p) {
    if (q.iops_offset != kNoOffset) c_sdu[q.iops_offset] = iox_status::kGood;
    if (q.iocs_offset != kNoOffset) c_sdu[q.iocs_offset] = iox_status::kGood;
  }
  const std::array<std::uint8_t, 4> drive{0x11, 0x22, 0x33, 0x44};
  std::copy(drive.begin(), drive.end(), c_sdu.begin() + p[kDrive].data_offset);
  c_sdu[p[kSensor].data_offset] = 0xAB;
  c_sdu[p[kSensor].data_offset + 1] = 0xCD;
  c_sdu[p[kDrive].iops_offset] = f.drive_iops;
  c_sdu[p[kSensor].iops_offset] = f.sensor_iops;
  EthernetHeader h;
  h.dst = kController;
  h.src = f.source;
  h.vlan = true;
  h.priority = kPriorityRtCyclic;
  h.frame_id = f.frame_id;
  Bytes out(kMaxFrameSize);
  const std::size_t at = encode_ethernet_header(h, out);
  const ApduStatus s{f.cycle, f.data_status, f.transfer_status};
  const std::size_t n = encode_rt_cyclic(std::span(out).subspan(at), std::span(c_sdu).first(l.used), l.length, s);
  out.resize(pad_frame(out, at + n));
  return out;
}

}  // namespace drivegate::profinet::test
