#include "adapters/profinet/wire/rpc_calls.hpp"

#include <algorithm>

namespace drivegate::profinet {

RpcHeader pnio_request_header(const Uuid& object, const Uuid& interface, const Uuid& activity,
                              std::uint32_t sequence_number, Opnum opnum, ByteOrder order) noexcept {
  RpcHeader h;
  h.packet_type = static_cast<std::uint8_t>(PacketType::Request);
  // PNIO calls may be repeated safely: the device answers a repeated sequence number from its
  // cache [IEC 61158-6-10 §4.10.3.3], hence idempotent.
  h.flags1 = rpc_flag1::kIdempotent;
  h.order = order;
  h.object = object;
  h.interface = interface;
  h.activity = activity;
  h.sequence_number = sequence_number;
  h.opnum = static_cast<std::uint16_t>(opnum);
  return h;
}

namespace {

bool is_pnio_interface(const Uuid& u) noexcept {
  return u == kPnioDeviceInterface || u == kPnioControllerInterface || u == kPnioSupervisorInterface;
}

WireError check_pnio(const RpcHeader& h, PacketType expected) noexcept {
  if (h.packet_type != static_cast<std::uint8_t>(expected)) return WireError::UnexpectedPacketType;
  if (!is_pnio_interface(h.interface)) return WireError::UnexpectedInterface;
  if (h.opnum > static_cast<std::uint16_t>(Opnum::ReadImplicit)) return WireError::UnexpectedOpnum;
  return WireError::None;
}

}  // namespace

PnioRequestView decode_pnio_request(std::span<const std::uint8_t> datagram) noexcept {
  PnioRequestView v;
  const RpcView rpc = decode_rpc(datagram);
  v.header = rpc.header;
  v.error = rpc.error != WireError::None ? rpc.error : check_pnio(rpc.header, PacketType::Request);
  if (v.error != WireError::None) return v;
  const NdrRequestView ndr = decode_ndr_request(rpc.body, rpc.header.order);
  v.error = ndr.error;
  v.ndr = ndr.ndr;
  return v;
}

PnioResponseView decode_pnio_response(std::span<const std::uint8_t> datagram) noexcept {
  PnioResponseView v;
  const RpcView rpc = decode_rpc(datagram);
  v.header = rpc.header;
  v.error = rpc.error != WireError::None ? rpc.error : check_pnio(rpc.header, PacketType::Response);
  if (v.error != WireError::None) return v;
  const NdrResponseView ndr = decode_ndr_response(rpc.body, rpc.header.order);
  v.error = ndr.error;
  v.ndr = ndr.ndr;
  return v;
}

std::size_t encode_control_request(const RpcHeader& h, std::uint32_t args_maximum, const ControlBlock& b,
                                   std::span<std::uint8_t> out) noexcept {
  const std::size_t n = encode_control_block(b, pnio_blocks_area(out));
  return n == 0 ? 0 : finish_pnio_request(h, args_maximum, n, out);
}

std::size_t encode_control_response(const RpcHeader& h, const PnioStatus& status, std::uint32_t maximum_count,
                                    const ControlBlock& b, std::span<std::uint8_t> out) noexcept {
  const std::size_t n = encode_control_block(b, pnio_blocks_area(out));
  return n == 0 ? 0 : finish_pnio_response(h, status, maximum_count, n, out);
}

std::size_t encode_write_request(const RpcHeader& h, std::uint32_t args_maximum, RecordReqHeader rh,
                                 std::span<const std::uint8_t> data, std::span<std::uint8_t> out) noexcept {
  if (rh.type != block_type::kWriteReqHeader || data.size() > 0xFFFF) return 0;
  rh.record_data_length = static_cast<std::uint32_t>(data.size());
  const auto area = pnio_blocks_area(out);
  const std::size_t n = encode_record_req_header(rh, area);
  if (n == 0 || area.size() - n < data.size()) return 0;
  std::copy(data.begin(), data.end(), area.begin() + static_cast<std::ptrdiff_t>(n));
  return finish_pnio_request(h, args_maximum, n + data.size(), out);
}

std::size_t encode_write_response(const RpcHeader& h, const PnioStatus& status, std::uint32_t maximum_count,
                                  const RecordResHeader& rh, std::span<std::uint8_t> out) noexcept {
  if (rh.type != block_type::kWriteResHeader) return 0;
  const std::size_t n = encode_record_res_header(rh, pnio_blocks_area(out));
  return n == 0 ? 0 : finish_pnio_response(h, status, maximum_count, n, out);
}

std::size_t encode_read_request(const RpcHeader& h, std::uint32_t args_maximum, const RecordReqHeader& rh,
                                std::span<std::uint8_t> out) noexcept {
  if (rh.type != block_type::kReadReqHeader) return 0;
  const std::size_t n = encode_record_req_header(rh, pnio_blocks_area(out));
  return n == 0 ? 0 : finish_pnio_request(h, args_maximum, n, out);
}

std::size_t encode_read_response(const RpcHeader& h, const PnioStatus& status, std::uint32_t maximum_count,
                                 RecordResHeader rh, std::span<const std::uint8_t> data,
                                 std::span<std::uint8_t> out) noexcept {
  if (rh.type != block_type::kReadResHeader || data.size() > 0xFFFF) return 0;
  rh.record_data_length = static_cast<std::uint32_t>(data.size());
  const auto area = pnio_blocks_area(out);
  const std::size_t n = encode_record_res_header(rh, area);
  if (n == 0 || area.size() - n < data.size()) return 0;
  std::copy(data.begin(), data.end(), area.begin() + static_cast<std::ptrdiff_t>(n));
  return finish_pnio_response(h, status, maximum_count, n + data.size(), out);
}

}  // namespace drivegate::profinet
