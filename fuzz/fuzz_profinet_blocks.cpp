// The PNIO block decoders (adapters/profinet/wire/blocks*.hpp) on the args of a request or
// response: BlockWalker over the input, each block given to the decoder of its type (and the
// record headers with the data that follows them).
// Invariants: every view inside the input; a decoded block's size is the walker's block size; a
// fixed-layout block (AR req/res, IOCR res, AlarmCR req/res, control, I&M0, record headers)
// re-encodes to bytes that decode to the same value; the flat readers of IOCR, ExpectedSubmodule
// and ModuleDiff end without error on a block the decoder accepted, and the ModuleDiff report fits
// its buffer.
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <span>
#include <string_view>

#include "adapters/profinet/wire/blocks.hpp"
#include "adapters/profinet/wire/blocks_control.hpp"
#include "adapters/profinet/wire/blocks_record.hpp"
#include "adapters/profinet/wire/blocks_submodule.hpp"

namespace {

using namespace drivegate::profinet;

std::span<const std::uint8_t> input;
std::array<std::uint8_t, 65536 + 64> out{};

void inside(std::span<const std::uint8_t> s) {
  if (s.empty()) return;
  if (s.data() < input.data() || s.data() + s.size() > input.data() + input.size()) std::abort();
}
void inside(std::string_view s) {
  inside(std::span<const std::uint8_t>(reinterpret_cast<const std::uint8_t*>(s.data()), s.size()));
}

// decode -> encode -> decode gives the same value.
template <typename View, typename Decode, typename Encode>
void round_trip(const View& v, Decode&& decode, Encode&& encode) {
  if (v.error != WireError::None) return;
  const std::size_t n = encode(v, std::span<std::uint8_t>(out));
  if (n == 0) std::abort();
  const View again = decode(std::span<const std::uint8_t>(out).first(n));
  if (again.error != WireError::None || !(again.block == v.block)) std::abort();
}

void check_block(const BlockView& b, std::span<const std::uint8_t> rest) {
  const auto sized = [&b](std::size_t size) {
    if (size != b.block.size()) std::abort();
  };
  switch (b.header.type) {
    case block_type::kArBlockReq: {
      const ArBlockReqView v = decode_ar_block_req(b.block);
      if (v.error != WireError::None) return;
      sized(v.size);
      inside(v.block.station_name);
      const std::size_t n = encode_ar_block_req(v.block, out);
      if (n != v.size) std::abort();
      const ArBlockReqView again = decode_ar_block_req(std::span<const std::uint8_t>(out).first(n));
      if (again.error != WireError::None || again.block.station_name != v.block.station_name ||
          again.block.ar_uuid != v.block.ar_uuid || again.block.properties != v.block.properties) {
        std::abort();
      }
      return;
    }
    case block_type::kArBlockRes:
      round_trip(decode_ar_block_res(b.block), [](auto in) { return decode_ar_block_res(in); },
                 [](const auto& v, auto o) { return encode_ar_block_res(v.block, o); });
      return;
    case block_type::kIocrBlockRes:
      round_trip(decode_iocr_block_res(b.block), [](auto in) { return decode_iocr_block_res(in); },
                 [](const auto& v, auto o) { return encode_iocr_block_res(v.block, o); });
      return;
    case block_type::kAlarmCrBlockReq:
      round_trip(decode_alarm_cr_block_req(b.block), [](auto in) { return decode_alarm_cr_block_req(in); },
                 [](const auto& v, auto o) { return encode_alarm_cr_block_req(v.block, o); });
      return;
    case block_type::kAlarmCrBlockRes:
      round_trip(decode_alarm_cr_block_res(b.block), [](auto in) { return decode_alarm_cr_block_res(in); },
                 [](const auto& v, auto o) { return encode_alarm_cr_block_res(v.block, o); });
      return;
    case block_type::kPrmEndReq:
    case block_type::kApplicationReadyReq:
    case block_type::kReleaseReq:
    case block_type::kPrmEndRes:
    case block_type::kApplicationReadyRes:
    case block_type::kReleaseRes:
      round_trip(decode_control_block(b.block), [](auto in) { return decode_control_block(in); },
                 [](const auto& v, auto o) { return encode_control_block(v.block, o); });
      return;
    case block_type::kIm0: {
      const Im0View v = decode_im0(b.block);
      if (v.error != WireError::None) return;
      inside(v.im0.order_id);
      inside(v.im0.serial_number);
      const std::size_t n = encode_im0(v.im0, out);
      if (n != kIm0Size) std::abort();
      const Im0View again = decode_im0(std::span<const std::uint8_t>(out).first(n));
      if (again.error != WireError::None || !(again.im0 == v.im0)) std::abort();
      return;
    }
    case block_type::kIocrBlockReq: {
      const IocrBlockReqView v = decode_iocr_block_req(b.block);
      if (v.error != WireError::None) return;
      sized(v.size);
      inside(v.apis);
      IocrEntryReader r(v);
      IocrEntry e;
      while (r.next(e)) {
      }
      return;
    }
    case block_type::kExpectedSubmoduleBlockReq: {
      const ExpectedSubmoduleBlockView v = decode_expected_submodule_block(b.block);
      if (v.error != WireError::None) return;
      sized(v.size);
      inside(v.apis);
      ExpectedSubmoduleReader r(v);
      ExpectedEntry e;
      std::size_t entries = 0;
      while (r.next(e)) ++entries;
      if (v.api_count > 0 && entries < v.api_count) std::abort();
      return;
    }
    case block_type::kModuleDiffBlock: {
      const ModuleDiffBlockView v = decode_module_diff_block(b.block);
      if (v.error != WireError::None) return;
      sized(v.size);
      inside(v.apis);
      static std::array<char, 300> text{};
      const std::string_view t = module_diff_report(v, {}, text);
      if (t.size() > text.size()) std::abort();
      return;
    }
    case block_type::kWriteReqHeader:
    case block_type::kReadReqHeader: {
      const RecordReqView v = decode_record_request(rest);
      if (v.error != WireError::None) return;
      inside(v.data);
      const std::size_t n = encode_record_req_header(v.header, out);
      if (n != kRecordHeaderSize) std::abort();
      // A write header alone lacks its data: only a read request re-decodes on its own.
      if (v.header.type == block_type::kReadReqHeader) {
        const RecordReqView again = decode_record_request(std::span<const std::uint8_t>(out).first(n));
        if (again.error != WireError::None || !(again.header == v.header)) std::abort();
      }
      return;
    }
    case block_type::kWriteResHeader:
    case block_type::kReadResHeader: {
      const RecordResView v = decode_record_response(rest);
      if (v.error != WireError::None) return;
      inside(v.data);
      const std::size_t n = encode_record_res_header(v.header, out);
      if (n != kRecordHeaderSize) std::abort();
      if (v.header.type == block_type::kWriteResHeader) {
        const RecordResView again = decode_record_response(std::span<const std::uint8_t>(out).first(n));
        if (again.error != WireError::None || !(again.header == v.header)) std::abort();
      }
      return;
    }
    default: return;
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size > 65536) return 0;
  input = std::span<const std::uint8_t>(data, size);
  BlockWalker w(input);
  BlockView b;
  std::size_t offset = 0;
  while (w.next(b)) {
    inside(b.block);
    if (b.block.data() != data + offset || b.body.size() + kBlockHeaderSize != b.block.size()) std::abort();
    check_block(b, input.subspan(offset));
    offset += b.block.size();
  }
  return 0;
}
