#include "adapters/profinet/wire/rpc_connect.hpp"

#include "adapters/profinet/wire/rpc_calls.hpp"

namespace drivegate::profinet {

namespace {

// Appends one encoded block to the area; false when it did not fit.
template <typename Encode>
bool append(std::span<std::uint8_t> area, std::size_t& used, Encode&& encode) noexcept {
  const std::size_t n = encode(area.subspan(used));
  used += n;
  return n != 0;
}

}  // namespace

std::size_t encode_connect_request(const RpcHeader& h, std::uint32_t args_maximum, const ConnectRequest& c,
                                   std::span<std::uint8_t> out) noexcept {
  if (h.opnum != static_cast<std::uint16_t>(Opnum::Connect)) return 0;
  const auto area = pnio_blocks_area(out);
  std::size_t used = 0;
  IocrParams input = c.input;
  input.type = iocr_type::kInput;
  IocrParams output = c.output;
  output.type = iocr_type::kOutput;
  if (!append(area, used, [&](std::span<std::uint8_t> o) { return encode_ar_block_req(c.ar, o); })) return 0;
  if (!append(area, used, [&](std::span<std::uint8_t> o) { return encode_iocr_block_req(input, c.input_apis, o); })) {
    return 0;
  }
  if (!append(area, used, [&](std::span<std::uint8_t> o) { return encode_iocr_block_req(output, c.output_apis, o); })) {
    return 0;
  }
  if (!append(area, used, [&](std::span<std::uint8_t> o) { return encode_alarm_cr_block_req(c.alarm, o); })) return 0;
  for (std::size_t i = 0; i < c.expected.size(); ++i) {
    const auto one = c.expected.subspan(i, 1);
    if (!append(area, used, [&](std::span<std::uint8_t> o) { return encode_expected_submodule_block(one, o); })) {
      return 0;
    }
  }
  return finish_pnio_request(h, args_maximum, used, out);
}

ConnectRequestView decode_connect_request(std::span<const std::uint8_t> datagram) noexcept {
  ConnectRequestView v;
  const PnioRequestView r = decode_pnio_request(datagram);
  v.header = r.header;
  v.args_maximum = r.ndr.args_maximum;
  auto fail = [&v](WireError e) {
    v.error = e;
    return v;
  };
  if (r.error != WireError::None) return fail(r.error);
  if (r.header.opnum != static_cast<std::uint16_t>(Opnum::Connect)) return fail(WireError::UnexpectedOpnum);
  bool has_ar = false;
  bool has_alarm = false;
  BlockWalker walker(r.ndr.blocks);
  BlockView b;
  while (walker.next(b)) {
    switch (b.header.type) {
      case block_type::kArBlockReq:
        if (has_ar) return fail(WireError::DuplicateBlock);
        v.ar = decode_ar_block_req(b.block);
        if (v.ar.error != WireError::None) return fail(v.ar.error);
        has_ar = true;
        break;
      case block_type::kIocrBlockReq:
        if (v.iocr_count == v.iocrs.size()) return fail(WireError::TooManyBlocks);
        v.iocrs[v.iocr_count] = decode_iocr_block_req(b.block);
        if (v.iocrs[v.iocr_count].error != WireError::None) return fail(v.iocrs[v.iocr_count].error);
        ++v.iocr_count;
        break;
      case block_type::kAlarmCrBlockReq:
        if (has_alarm) return fail(WireError::DuplicateBlock);
        v.alarm_cr = decode_alarm_cr_block_req(b.block);
        if (v.alarm_cr.error != WireError::None) return fail(v.alarm_cr.error);
        has_alarm = true;
        break;
      case block_type::kExpectedSubmoduleBlockReq:
        if (v.expected_count == v.expected.size()) return fail(WireError::TooManyBlocks);
        v.expected[v.expected_count] = decode_expected_submodule_block(b.block);
        if (v.expected[v.expected_count].error != WireError::None) return fail(v.expected[v.expected_count].error);
        ++v.expected_count;
        break;
      default: ++v.other_blocks; break;
    }
  }
  if (walker.error() != WireError::None) return fail(walker.error());
  if (!has_ar || v.iocr_count == 0 || !has_alarm) return fail(WireError::MissingBlock);
  return v;
}

const IocrBlockRes* ConnectResponseView::iocr(std::uint16_t type, std::uint16_t reference) const noexcept {
  for (std::size_t i = 0; i < iocr_count; ++i) {
    if (iocrs[i].type == type && iocrs[i].reference == reference) return &iocrs[i];
  }
  return nullptr;
}

ConnectResponseView decode_connect_response(std::span<const std::uint8_t> datagram) noexcept {
  ConnectResponseView v;
  const PnioResponseView r = decode_pnio_response(datagram);
  v.header = r.header;
  v.status = r.ndr.status;
  if (r.error != WireError::None) {
    v.error = r.error;
    return v;
  }
  if (r.header.opnum != static_cast<std::uint16_t>(Opnum::Connect)) {
    v.error = WireError::UnexpectedOpnum;
    return v;
  }
  BlockWalker walker(r.ndr.blocks);
  BlockView b;
  auto fail = [&v](WireError e) {
    v.error = e;
    return v;
  };
  while (walker.next(b)) {
    switch (b.header.type) {
      case block_type::kArBlockRes: {
        if (v.has_ar) return fail(WireError::DuplicateBlock);
        const ArBlockResView ar = decode_ar_block_res(b.block);
        if (ar.error != WireError::None) return fail(ar.error);
        v.ar = ar.block;
        v.has_ar = true;
        break;
      }
      case block_type::kIocrBlockRes: {
        if (v.iocr_count == v.iocrs.size()) return fail(WireError::TooManyBlocks);
        const IocrBlockResView io = decode_iocr_block_res(b.block);
        if (io.error != WireError::None) return fail(io.error);
        v.iocrs[v.iocr_count++] = io.block;
        break;
      }
      case block_type::kAlarmCrBlockRes: {
        if (v.has_alarm_cr) return fail(WireError::DuplicateBlock);
        const AlarmCrBlockResView al = decode_alarm_cr_block_res(b.block);
        if (al.error != WireError::None) return fail(al.error);
        v.alarm_cr = al.block;
        v.has_alarm_cr = true;
        break;
      }
      case block_type::kModuleDiffBlock: {
        if (v.has_module_diff) return fail(WireError::DuplicateBlock);
        v.module_diff = decode_module_diff_block(b.block);
        if (v.module_diff.error != WireError::None) return fail(v.module_diff.error);
        v.has_module_diff = true;
        break;
      }
      default: ++v.other_blocks; break;
    }
  }
  if (walker.error() != WireError::None) return fail(walker.error());
  if (v.status.ok() && !v.has_ar) return fail(WireError::MissingBlock);
  return v;
}

std::size_t encode_connect_response(const RpcHeader& h, const PnioStatus& status, std::uint32_t maximum_count,
                                    const ConnectResponse& c, std::span<std::uint8_t> out) noexcept {
  const auto area = pnio_blocks_area(out);
  std::size_t used = 0;
  if (!append(area, used, [&](std::span<std::uint8_t> o) { return encode_ar_block_res(c.ar, o); })) return 0;
  for (const IocrBlockRes& io : c.iocrs) {
    if (!append(area, used, [&](std::span<std::uint8_t> o) { return encode_iocr_block_res(io, o); })) return 0;
  }
  if (!append(area, used, [&](std::span<std::uint8_t> o) { return encode_alarm_cr_block_res(c.alarm_cr, o); })) {
    return 0;
  }
  if (!c.module_diff.empty() &&
      !append(area, used, [&](std::span<std::uint8_t> o) { return encode_module_diff_block(c.module_diff, o); })) {
    return 0;
  }
  return finish_pnio_response(h, status, maximum_count, used, out);
}

}  // namespace drivegate::profinet
