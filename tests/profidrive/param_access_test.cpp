// Base mode parameter access against akd-profinet-profidrive.md §5.2..§5.6.
#include "profiles/profidrive/param_access.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include "tests/support/alloc_counter.hpp"

namespace drivegate::profidrive {
namespace {

using Bytes = std::vector<std::uint8_t>;

constexpr std::uint16_t kPnuOpMode = 930;   // §11.1
constexpr std::uint16_t kPnuFaultCount = 944;
constexpr std::uint16_t kPnuFaults = 947;
constexpr std::uint16_t kPnuDrvOpMode = 2135;  // DRV.OPMODE, Byte [§5.6]

Bytes encode_read(std::uint8_t ref, std::initializer_list<ParamAddress> params) {
  std::array<std::uint8_t, kMaxParamRecord> out{};
  const std::vector<ParamAddress> p(params);
  const EncodeResult r = encode_read_request(out, ref, p);
  EXPECT_EQ(r.error, ParamError::None) << to_string(r.error);
  return Bytes(out.begin(), out.begin() + static_cast<std::ptrdiff_t>(r.size));
}

// Bytes kept alive until the end of the test program: decoded blocks are views into them.
const Bytes& keep(Bytes b) {
  static std::vector<std::unique_ptr<Bytes>> kept;
  kept.push_back(std::make_unique<Bytes>(std::move(b)));
  return *kept.back();
}
ResponseResult decode_kept(Bytes b) { return decode_param_response(keep(std::move(b))); }

ParamRequest request_of(Bytes b) {
  const RequestResult r = decode_param_request(keep(std::move(b)));
  EXPECT_EQ(r.error, ParamError::None) << to_string(r.error) << " at " << r.at;
  return r.request;
}

TEST(ProfidriveParam, WriteOperatingModeVectorOfTheManual) {
  // §5.5: PNU 930 := 2 (position mode), reference 5.
  const std::array<std::uint32_t, 1> value{2};
  const std::array<ParamChange, 1> change{ParamChange{ParamAddress{Attribute::Value, 1, kPnuOpMode, 0}, format::kWord, value}};
  std::array<std::uint8_t, kMaxParamRecord> out{};
  const EncodeResult e = encode_change_request(out, 5, change);
  ASSERT_EQ(e.error, ParamError::None);
  const Bytes request(out.begin(), out.begin() + static_cast<std::ptrdiff_t>(e.size));
  EXPECT_EQ(request, (Bytes{0x05, 0x02, 0x00, 0x01, 0x10, 0x01, 0x03, 0xA2, 0x00, 0x00, 0x42, 0x01, 0x00, 0x02}));

  // The AKD's 6-byte reply (§5.3 quirk, §23.3) and the standard's 4-byte header both answer it.
  const ParamRequest q = request_of(request);
  EXPECT_EQ(q.id, RequestId::Change);
  EXPECT_EQ(q.values[0].value(0), 2U);
  for (const Bytes& reply : {Bytes{0x05, 0x02, 0x00, 0x01, 0x00, 0x00}, Bytes{0x05, 0x02, 0x00, 0x01}}) {
    const ResponseResult r = decode_param_response(reply);
    ASSERT_EQ(r.error, ParamError::None) << to_string(r.error);
    EXPECT_TRUE(r.response.positive());
    EXPECT_TRUE(r.response.is_change());
    EXPECT_EQ(r.response.reference, 5);
    EXPECT_EQ(check_response(q, r.response).mismatch, ParamMismatch::None);
  }
  // The same reply to another reference is someone else's answer.
  const ResponseResult stale = decode_kept(Bytes{0x04, 0x02, 0x00, 0x01, 0x00, 0x00});
  ASSERT_EQ(stale.error, ParamError::None);
  EXPECT_EQ(check_response(q, stale.response).mismatch, ParamMismatch::Reference);
}

TEST(ProfidriveParam, ConstructedReadVectors) {
  // §5.6.
  EXPECT_EQ(encode_read(6, {{Attribute::Value, 1, kPnuOpMode, 0}}),
            (Bytes{0x06, 0x01, 0x00, 0x01, 0x10, 0x01, 0x03, 0xA2, 0x00, 0x00}));
  EXPECT_EQ(encode_read(7, {{Attribute::Value, 1, kPnuFaultCount, 0}}),
            (Bytes{0x07, 0x01, 0x00, 0x01, 0x10, 0x01, 0x03, 0xB0, 0x00, 0x00}));
  EXPECT_EQ(encode_read(8, {{Attribute::Value, 8, kPnuFaults, 0}}),
            (Bytes{0x08, 0x01, 0x00, 0x01, 0x10, 0x08, 0x03, 0xB3, 0x00, 0x00}));
  EXPECT_EQ(encode_read(9, {{Attribute::Value, 1, kPnuFaultCount, 0}, {Attribute::Value, 1, kPnuOpMode, 0}}),
            (Bytes{0x09, 0x01, 0x00, 0x02, 0x10, 0x01, 0x03, 0xB0, 0x00, 0x00, 0x10, 0x01, 0x03, 0xA2, 0x00, 0x00}));

  // The expected answer to "read PNU 930": 06 01 00 01 42 01 00 0m.
  const ParamRequest q = request_of(encode_read(6, {{Attribute::Value, 1, kPnuOpMode, 0}}));
  const ResponseResult r = decode_kept(Bytes{0x06, 0x01, 0x00, 0x01, 0x42, 0x01, 0x00, 0x02});
  ASSERT_EQ(r.error, ParamError::None);
  ASSERT_EQ(r.response.values().size(), 1U);
  EXPECT_EQ(r.response.values()[0].format, format::kWord);
  EXPECT_EQ(r.response.values()[0].value(0), 2U);
  EXPECT_EQ(check_response(q, r.response).mismatch, ParamMismatch::None);
}

TEST(ProfidriveParam, ConstructedByteWriteIsPadded) {
  // §5.6: DRV.OPMODE through PNU 2135 as a Byte, followed by a pad byte.
  const std::array<std::uint32_t, 1> value{2};
  const std::array<ParamChange, 1> change{
      ParamChange{ParamAddress{Attribute::Value, 1, kPnuDrvOpMode, 0}, format::kByte, value}};
  std::array<std::uint8_t, 32> out{};
  const EncodeResult e = encode_change_request(out, 0x0A, change);
  ASSERT_EQ(e.error, ParamError::None);
  EXPECT_EQ(Bytes(out.begin(), out.begin() + static_cast<std::ptrdiff_t>(e.size)),
            (Bytes{0x0A, 0x02, 0x00, 0x01, 0x10, 0x01, 0x08, 0x57, 0x00, 0x00, 0x41, 0x01, 0x02, 0x00}));
  const RequestResult back = decode_param_request(std::span(out).first(e.size));
  ASSERT_EQ(back.error, ParamError::None);
  EXPECT_EQ(back.request.values[0].value(0), 2U);
  // Without the pad (the last block) it still reads.
  EXPECT_EQ(decode_param_request(std::span(out).first(e.size - 1)).error, ParamError::None);
}

TEST(ProfidriveParam, SeveralParametersPerRequestAndResponse) {
  // Change three parameters: a Byte pair (padded), a DWord and a Word array.
  const std::array<std::uint32_t, 1> b{0x7F};
  const std::array<std::uint32_t, 1> d{0x01020304};
  const std::array<std::uint32_t, 2> w{0x1111, 0x2222};
  const std::array<ParamChange, 3> change{ParamChange{{Attribute::Value, 1, 2135, 0}, format::kByte, b},
                                          ParamChange{{Attribute::Value, 1, 3014, 0}, format::kDWord, d},
                                          ParamChange{{Attribute::Value, 2, 915, 3}, format::kWord, w}};
  std::array<std::uint8_t, kMaxParamRecord> out{};
  const EncodeResult e = encode_change_request(out, 0x21, change);
  ASSERT_EQ(e.error, ParamError::None);
  EXPECT_EQ(Bytes(out.begin(), out.begin() + static_cast<std::ptrdiff_t>(e.size)),
            (Bytes{0x21, 0x02, 0x00, 0x03,                    //
                   0x10, 0x01, 0x08, 0x57, 0x00, 0x00,        // PNU 2135
                   0x10, 0x01, 0x0B, 0xC6, 0x00, 0x00,        // PNU 3014
                   0x10, 0x02, 0x03, 0x93, 0x00, 0x03,        // PNU 915[3..4]
                   0x41, 0x01, 0x7F, 0x00,                    // Byte + pad
                   0x43, 0x01, 0x01, 0x02, 0x03, 0x04,        // DWord
                   0x42, 0x02, 0x11, 0x11, 0x22, 0x22}));     // 2 Words
  const ParamRequest q = request_of(Bytes(out.begin(), out.begin() + static_cast<std::ptrdiff_t>(e.size)));
  ASSERT_EQ(q.count, 3);
  EXPECT_EQ(q.params[2], (ParamAddress{Attribute::Value, 2, 915, 3}));
  EXPECT_EQ(q.values[2].value(1), 0x2222U);

  // A negative change response: the second parameter failed (limit exceeded), the others are "zero".
  const ResponseResult r = decode_kept(
      Bytes{0x21, 0x82, 0x00, 0x03, 0x40, 0x00, 0x44, 0x01, 0x00, 0x02, 0x40, 0x00});
  ASSERT_EQ(r.error, ParamError::None) << to_string(r.error);
  EXPECT_FALSE(r.response.positive());
  EXPECT_TRUE(r.response.values()[1].is_error());
  EXPECT_EQ(r.response.values()[1].error_number(), 2);
  EXPECT_EQ(param_error_text(r.response.values()[1].error_number()), "low or high limit exceeded");
  EXPECT_EQ(check_response(q, r.response).mismatch, ParamMismatch::None);

  // A read of three: a Word, a Byte (padded before the next block), 8 fault entries.
  const ParamRequest rq = request_of(encode_read(
      0x22, {{Attribute::Value, 1, kPnuOpMode, 0}, {Attribute::Value, 1, 2135, 0}, {Attribute::Value, 8, kPnuFaults, 0}}));
  const Bytes reply{0x22, 0x01, 0x00, 0x03, 0x42, 0x01, 0x00, 0x02, 0x41, 0x01, 0x02, 0x00, 0x42, 0x08,
                    0x02, 0xBE, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00};
  const ResponseResult rr = decode_param_response(reply);
  ASSERT_EQ(rr.error, ParamError::None) << to_string(rr.error) << " at " << rr.at;
  EXPECT_EQ(rr.response.values()[1].value(0), 2U);
  EXPECT_EQ(rr.response.values()[2].count, 8);
  EXPECT_EQ(rr.response.values()[2].value(0), 702U);  // F702 [§18.3]
  EXPECT_EQ(check_response(rq, rr.response).mismatch, ParamMismatch::None);
}

TEST(ProfidriveParam, NegativeReadWithErrorNumbersAndInfo) {
  const ParamRequest q = request_of(
      encode_read(9, {{Attribute::Value, 1, kPnuFaultCount, 0}, {Attribute::Value, 1, kPnuOpMode, 0}}));
  // PNU 944 failed (impermissible PNU, with additional info 0), PNU 930 answered.
  const ResponseResult r = decode_kept(
      Bytes{0x09, 0x81, 0x00, 0x02, 0x44, 0x02, 0x00, 0x00, 0x00, 0x07, 0x42, 0x01, 0x00, 0x02});
  ASSERT_EQ(r.error, ParamError::None) << to_string(r.error);
  const ValueBlock& err = r.response.values()[0];
  EXPECT_TRUE(err.is_error());
  EXPECT_EQ(err.error_number(), 0);
  EXPECT_EQ(err.error_info(), std::optional<std::uint16_t>(7));
  EXPECT_EQ(r.response.values()[1].value(0), 2U);
  EXPECT_EQ(check_response(q, r.response).mismatch, ParamMismatch::None);
}

TEST(ProfidriveParam, MalformedAndLyingResponses) {
  const auto error_of = [](const Bytes& b) { return decode_param_response(b).error; };
  EXPECT_EQ(error_of({}), ParamError::Truncated);
  EXPECT_EQ(error_of({0x06, 0x01, 0x00}), ParamError::Truncated);
  EXPECT_EQ(error_of({0x06, 0x01, 0x00, 0x01}), ParamError::Truncated);  // a read needs its block
  EXPECT_EQ(error_of({0x06, 0x01, 0x00, 0x01, 0x42}), ParamError::Truncated);
  EXPECT_EQ(error_of({0x06, 0x03, 0x00, 0x01, 0x42, 0x01, 0x00, 0x02}), ParamError::UnknownId);
  EXPECT_EQ(error_of({0x06, 0x01, 0x00, 0x00}), ParamError::BadCount);
  EXPECT_EQ(error_of({0x06, 0x01, 0x00, 0x28, 0x42, 0x01, 0x00, 0x02}), ParamError::BadCount);
  // Counts beyond the data: 2 words announced, 1 present; 0xEA DWords in a short record.
  EXPECT_EQ(error_of({0x06, 0x01, 0x00, 0x01, 0x42, 0x02, 0x00, 0x02}), ParamError::CountBeyondData);
  EXPECT_EQ(error_of({0x06, 0x01, 0x00, 0x01, 0x43, 0xEA, 0x00, 0x02}), ParamError::CountBeyondData);
  // Two parameters announced, one block sent.
  EXPECT_EQ(error_of({0x09, 0x01, 0x00, 0x02, 0x42, 0x01, 0x00, 0x02}), ParamError::Truncated);
  EXPECT_EQ(error_of({0x06, 0x01, 0x00, 0x01, 0x45, 0x01, 0x00, 0x02}), ParamError::UnknownFormat);
  EXPECT_EQ(error_of({0x06, 0x01, 0x00, 0x01, 0x42, 0x01, 0x00, 0x02, 0x00}), ParamError::TrailingBytes);
  EXPECT_EQ(error_of({0x06, 0x81, 0x00, 0x01, 0x44, 0x03, 0x00, 0x01, 0x00, 0x00, 0x00, 0x00}), ParamError::BadErrorBlock);
  EXPECT_EQ(error_of({0x06, 0x81, 0x00, 0x01, 0x44, 0x00}), ParamError::BadErrorBlock);
  EXPECT_EQ(error_of({0x06, 0x01, 0x00, 0x01, 0x44, 0x01, 0x00, 0x00}), ParamError::ErrorInPositive);
  EXPECT_EQ(error_of({0x06, 0x81, 0x00, 0x01, 0x42, 0x01, 0x00, 0x02}), ParamError::NoErrorInNegative);
  EXPECT_EQ(error_of({0x06, 0x01, 0x00, 0x01, 0x00, 0x00}), ParamError::BadZeroBlock);  // 00h only in change replies
  EXPECT_EQ(error_of({0x05, 0x02, 0x00, 0x01, 0x40, 0x01, 0x00}), ParamError::BadZeroBlock);
  EXPECT_EQ(error_of({0x05, 0x02, 0x00, 0x01, 0x00, 0x00, 0x00}), ParamError::TrailingBytes);

  // Well-formed but not the answer to this request.
  const ParamRequest read930 = request_of(encode_read(6, {{Attribute::Value, 1, kPnuOpMode, 0}}));
  const auto mismatch_of = [&read930](const Bytes& b) {
    const ResponseResult r = decode_param_response(b);
    EXPECT_EQ(r.error, ParamError::None) << to_string(r.error);
    return check_response(read930, r.response).mismatch;
  };
  EXPECT_EQ(mismatch_of({0x07, 0x01, 0x00, 0x01, 0x42, 0x01, 0x00, 0x02}), ParamMismatch::Reference);
  EXPECT_EQ(mismatch_of({0x06, 0x02, 0x00, 0x01, 0x00, 0x00}), ParamMismatch::ResponseId);
  EXPECT_EQ(mismatch_of({0x06, 0x01, 0x01, 0x01, 0x42, 0x01, 0x00, 0x02}), ParamMismatch::Axis);
  EXPECT_EQ(mismatch_of({0x06, 0x01, 0x00, 0x02, 0x42, 0x01, 0x00, 0x02, 0x42, 0x01, 0x00, 0x02}),
            ParamMismatch::ParameterCount);
  EXPECT_EQ(mismatch_of({0x06, 0x01, 0x00, 0x01, 0x42, 0x02, 0x00, 0x02, 0x00, 0x03}), ParamMismatch::ValueCount);
  const ParamRequest write = request_of(Bytes{0x05, 0x02, 0x00, 0x01, 0x10, 0x01, 0x03, 0xA2, 0x00, 0x00, 0x42, 0x01, 0x00, 0x02});
  const ResponseResult echoed = decode_kept(Bytes{0x05, 0x02, 0x00, 0x01, 0x42, 0x01, 0x00, 0x02});
  ASSERT_EQ(echoed.error, ParamError::None);
  EXPECT_EQ(check_response(write, echoed.response).mismatch, ParamMismatch::ValuesInChange);
  EXPECT_EQ(to_string(ParamMismatch::Reference), "response reference differs from the request's");
}

TEST(ProfidriveParam, EncoderRefusesWhatTheProtocolDoesNot) {
  std::array<std::uint8_t, kMaxParamRecord> out{};
  const auto read_error = [&out](std::uint8_t ref, ParamAddress a) {
    const std::array<ParamAddress, 1> p{a};
    return encode_read_request(out, ref, p).error;
  };
  EXPECT_EQ(read_error(0, {Attribute::Value, 1, 930, 0}), ParamError::BadReference);
  EXPECT_EQ(read_error(1, {Attribute::Value, 0, 930, 0}), ParamError::BadElements);
  EXPECT_EQ(read_error(1, {Attribute::Value, 235, 930, 0}), ParamError::BadElements);
  EXPECT_EQ(read_error(1, {Attribute::Value, 1, 0, 0}), ParamError::BadPnu);
  EXPECT_EQ(read_error(1, {Attribute::Value, 1, 930, 0xFFFF}), ParamError::BadSubindex);
  EXPECT_EQ(read_error(1, {static_cast<Attribute>(0x40), 1, 930, 0}), ParamError::BadAttribute);
  EXPECT_EQ(read_error(1, {Attribute::Description, 1, 930, 0}), ParamError::None);
  EXPECT_EQ(read_error(1, {Attribute::Text, 1, 930, 0}), ParamError::None);
  EXPECT_EQ(encode_read_request(out, 1, std::span<const ParamAddress>{}).error, ParamError::BadCount);

  // 39 parameters fit 240 bytes exactly (238); 40 do not.
  std::array<ParamAddress, 40> many{};
  for (auto& a : many) a = ParamAddress{Attribute::Value, 1, 930, 0};
  EXPECT_EQ(encode_read_request(out, 1, std::span(many).first(39)).size, 238U);
  EXPECT_EQ(encode_read_request(out, 1, many).error, ParamError::BadCount);
  std::array<std::uint8_t, 9> small{};
  EXPECT_EQ(encode_read_request(small, 1, std::span(many).first(1)).error, ParamError::BufferTooSmall);

  const auto change_error = [&out](std::uint8_t fmt, std::uint8_t elements, std::span<const std::uint32_t> v) {
    const std::array<ParamChange, 1> c{ParamChange{{Attribute::Value, elements, 930, 0}, fmt, v}};
    return encode_change_request(out, 1, c).error;
  };
  const std::array<std::uint32_t, 1> big{0x10000};
  const std::array<std::uint32_t, 1> byte_big{0x100};
  const std::array<std::uint32_t, 2> two{1, 2};
  EXPECT_EQ(change_error(format::kWord, 1, big), ParamError::ValueTooWide);
  EXPECT_EQ(change_error(format::kByte, 1, byte_big), ParamError::ValueTooWide);
  EXPECT_EQ(change_error(format::kDWord, 1, big), ParamError::None);
  EXPECT_EQ(change_error(format::kError, 1, big), ParamError::BadFormat);
  EXPECT_EQ(change_error(format::kUnsigned16, 1, big), ParamError::BadFormat);
  EXPECT_EQ(change_error(format::kWord, 1, two), ParamError::ValueCountMismatch);
  // 39 DWord writes: 238 + 39 x 6 bytes > 240.
  std::array<ParamChange, 39> writes{};
  for (auto& w : writes) w = ParamChange{{Attribute::Value, 1, 930, 0}, format::kDWord, big};
  EXPECT_EQ(encode_change_request(out, 1, writes).error, ParamError::TooLong);
}

TEST(ProfidriveParam, ErrorNumberTexts) {
  // §5.4 and the PROFIdrive table.
  EXPECT_EQ(param_error_text(0x00), "impermissible parameter number (the parameter does not exist)");
  EXPECT_EQ(param_error_text(0x01), "parameter value cannot be changed (read-only)");
  EXPECT_EQ(param_error_text(0x03), "faulty subindex");
  EXPECT_EQ(param_error_text(0x0B), "no master control (no parameter change rights)");
  EXPECT_EQ(param_error_text(0x14), "value impermissible");
  EXPECT_EQ(param_error_text(0x15), "response too long");
  EXPECT_EQ(param_error_text(0x16), "parameter address impermissible (attribute, elements, PNU or subindex)");
  EXPECT_EQ(param_error_text(0x17), "illegal format");
  EXPECT_EQ(param_error_text(0x18), "number of values inconsistent");
  EXPECT_EQ(param_error_text(0x19), "drive object (axis) does not exist");
  EXPECT_EQ(param_error_text(0x08), "reserved error number");
  EXPECT_EQ(param_error_text(0x65), "manufacturer-specific error (not documented for the AKD)");
  EXPECT_EQ(param_error_text(0x1234), "reserved error number");
}

TEST(ProfidriveParam, RequestDecoderRefusesMalformedRequests) {
  const auto error_of = [](const Bytes& b) { return decode_param_request(b).error; };
  EXPECT_EQ(error_of({0x05, 0x02, 0x00}), ParamError::Truncated);
  EXPECT_EQ(error_of({0x00, 0x01, 0x00, 0x01, 0x10, 0x01, 0x03, 0xA2, 0x00, 0x00}), ParamError::BadReference);
  EXPECT_EQ(error_of({0x05, 0x03, 0x00, 0x01, 0x10, 0x01, 0x03, 0xA2, 0x00, 0x00}), ParamError::UnknownId);
  EXPECT_EQ(error_of({0x05, 0x01, 0x00, 0x01, 0x10, 0x01, 0x03, 0xA2, 0x00}), ParamError::Truncated);
  EXPECT_EQ(error_of({0x05, 0x02, 0x00, 0x01, 0x10, 0x01, 0x03, 0xA2, 0x00, 0x00, 0x42, 0x02, 0x00, 0x02, 0x00, 0x03}),
            ParamError::ValueCountMismatch);
  EXPECT_EQ(error_of({0x05, 0x02, 0x00, 0x01, 0x10, 0x01, 0x03, 0xA2, 0x00, 0x00, 0x44, 0x01, 0x00, 0x02}),
            ParamError::BadFormat);
  EXPECT_EQ(error_of({0x05, 0x02, 0x00, 0x01, 0x10, 0x01, 0x03, 0xA2, 0x00, 0x00, 0x42, 0x01, 0x00}),
            ParamError::CountBeyondData);
}

TEST(ProfidriveParam, ResponseEncoderForTheDriveSide) {
  // The §5.5 reply in its standard form, and a read reply with a padded Byte block, round trip.
  ParamResponse change;
  change.reference = 5;
  change.response_id = response_id::kChangeOk;
  change.count = 1;
  std::array<std::uint8_t, kMaxParamRecord> out{};
  EncodeResult e = encode_param_response(out, change);
  ASSERT_EQ(e.error, ParamError::None);
  EXPECT_EQ(Bytes(out.begin(), out.begin() + static_cast<std::ptrdiff_t>(e.size)), (Bytes{0x05, 0x02, 0x00, 0x01}));
  change.block_count = 1;
  change.blocks[0] = ValueBlock{format::kAkdNone, 0, {}};
  e = encode_param_response(out, change);
  EXPECT_EQ(Bytes(out.begin(), out.begin() + static_cast<std::ptrdiff_t>(e.size)),
            (Bytes{0x05, 0x02, 0x00, 0x01, 0x00, 0x00}));  // the AKD's form

  const Bytes reply = keep(Bytes{0x22, 0x01, 0x00, 0x02, 0x41, 0x01, 0x02, 0x00, 0x42, 0x01, 0x00, 0x05});
  const ResponseResult r = decode_param_response(reply);
  ASSERT_EQ(r.error, ParamError::None);
  e = encode_param_response(out, r.response);
  ASSERT_EQ(e.error, ParamError::None);
  EXPECT_EQ(Bytes(out.begin(), out.begin() + static_cast<std::ptrdiff_t>(e.size)), reply);

  ParamResponse bad = r.response;
  bad.blocks[1].count = 2;  // the data holds one word
  EXPECT_EQ(encode_param_response(out, bad).error, ParamError::CountBeyondData);
  bad = r.response;
  bad.response_id = 0x03;
  EXPECT_EQ(encode_param_response(out, bad).error, ParamError::UnknownId);
  bad = r.response;
  bad.block_count = 1;
  EXPECT_EQ(encode_param_response(out, bad).error, ParamError::BadCount);
}

TEST(ProfidriveParam, EncodeAndDecodeDoNotAllocate) {
  std::array<std::uint8_t, kMaxParamRecord> out{};
  const std::array<ParamAddress, 2> reads{ParamAddress{Attribute::Value, 1, 944, 0}, ParamAddress{Attribute::Value, 8, 947, 0}};
  const std::array<std::uint32_t, 1> v{2};
  const std::array<ParamChange, 1> change{ParamChange{{Attribute::Value, 1, 930, 0}, format::kWord, v}};
  const std::array<std::uint8_t, 14> reply{0x09, 0x81, 0x00, 0x02, 0x44, 0x02, 0x00, 0x00, 0x00, 0x07, 0x42, 0x01, 0x00, 0x02};
  test::AllocationScope scope;
  EXPECT_EQ(encode_read_request(out, 9, reads).error, ParamError::None);
  const RequestResult q = decode_param_request(std::span(out).first(16));
  EXPECT_EQ(encode_change_request(out, 5, change).error, ParamError::None);
  const ResponseResult r = decode_param_response(reply);
  EXPECT_EQ(r.error, ParamError::None);
  (void)check_response(q.request, r.response);
  (void)param_error_text(r.response.values()[0].error_number());
  EXPECT_EQ(scope.count(), 0U);
}

}  // namespace
}  // namespace drivegate::profidrive
