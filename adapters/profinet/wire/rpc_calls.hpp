#pragma once
// Whole PNIO RPC datagrams: an RPC header, the NDR wrapper and the blocks, for the calls after
// Connect (record Read/Write, Control PrmEnd/ApplicationReady, Release), and the decoders that
// check a datagram is a PNIO request or response before its blocks are read
// [IEC 61158-6-10 §4.10.3, §5.1.2].
//
// Composers write into a caller's buffer (no allocation) and return the datagram size, 0 when it
// does not fit or a value is invalid. The RPC header `h` is the caller's: object, interface,
// activity, sequence number, opnum and byte order (pnio_request_header builds one).
#include <cstddef>
#include <cstdint>
#include <span>

#include "adapters/profinet/wire/blocks_control.hpp"
#include "adapters/profinet/wire/blocks_record.hpp"
#include "adapters/profinet/wire/rpc.hpp"

namespace drivegate::profinet {

// A request header: packet type Request, flags1 idempotent, interface version 1, no hints.
// `interface` is kPnioDeviceInterface for calls to a device, kPnioControllerInterface for the
// device's ApplicationReady to the controller.
RpcHeader pnio_request_header(const Uuid& object, const Uuid& interface, const Uuid& activity,
                              std::uint32_t sequence_number, Opnum opnum,
                              ByteOrder order = ByteOrder::Little) noexcept;

struct PnioRequestView {
  WireError error = WireError::None;
  RpcHeader header{};
  NdrRequest ndr{};
};
// A request to a PNIO interface (device, controller or supervisor), opnum 0..5.
PnioRequestView decode_pnio_request(std::span<const std::uint8_t> datagram) noexcept;

struct PnioResponseView {
  WireError error = WireError::None;
  RpcHeader header{};
  NdrResponse ndr{};
};
PnioResponseView decode_pnio_response(std::span<const std::uint8_t> datagram) noexcept;

// Control (opnum 4) and Release (opnum 1): one control block.
std::size_t encode_control_request(const RpcHeader& h, std::uint32_t args_maximum, const ControlBlock& b,
                                   std::span<std::uint8_t> out) noexcept;
std::size_t encode_control_response(const RpcHeader& h, const PnioStatus& status, std::uint32_t maximum_count,
                                    const ControlBlock& b, std::span<std::uint8_t> out) noexcept;

// Write (opnum 3): IODWriteReqHeader with record_data_length = data.size(), then the data.
std::size_t encode_write_request(const RpcHeader& h, std::uint32_t args_maximum, RecordReqHeader rh,
                                 std::span<const std::uint8_t> data, std::span<std::uint8_t> out) noexcept;
std::size_t encode_write_response(const RpcHeader& h, const PnioStatus& status, std::uint32_t maximum_count,
                                  const RecordResHeader& rh, std::span<std::uint8_t> out) noexcept;
// Read (opnum 2) / ReadImplicit (5): IODReadReqHeader; record_data_length is the most it takes.
std::size_t encode_read_request(const RpcHeader& h, std::uint32_t args_maximum, const RecordReqHeader& rh,
                                std::span<std::uint8_t> out) noexcept;
// IODReadResHeader with record_data_length = data.size(), then the data.
std::size_t encode_read_response(const RpcHeader& h, const PnioStatus& status, std::uint32_t maximum_count,
                                 RecordResHeader rh, std::span<const std::uint8_t> data,
                                 std::span<std::uint8_t> out) noexcept;

}  // namespace drivegate::profinet
