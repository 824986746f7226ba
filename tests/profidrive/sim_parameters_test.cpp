// The simulated AKD PROFIdrive drive, acyclic side: record 47 with the digest's byte-exact vectors,
// negative responses, several parameters per request, the fault buffer read by the controller's
// reader, and the motion-task table [akd-profinet-profidrive.md §5, §11, §16, §18.2].
#include <gtest/gtest.h>

#include "profiles/profidrive/control_words.hpp"
#include "profiles/profidrive/fault_buffer.hpp"
#include "tests/profidrive/sim_harness.hpp"

namespace drivegate::profidrive::sim::test {
namespace {

std::uint16_t error_of(const ParamResponse& r, std::size_t i = 0) { return r.blocks[i].error_number(); }

TEST(ProfidriveSimParameters, Pnu930WriteVectorAndTheAkdChangeReply) {
  // §5.5: 05 02 00 01 10 01 03 A2 00 00 42 01 00 02 -> 05 02 00 01 00 00.
  Harness h(config_for(1));
  EXPECT_EQ(h.drive.operating_mode(), OperatingMode::Speed);
  const Bytes request{0x05, 0x02, 0x00, 0x01, 0x10, 0x01, 0x03, 0xA2, 0x00, 0x00, 0x42, 0x01, 0x00, 0x02};
  EXPECT_EQ(h.parameter(request), (Bytes{0x05, 0x02, 0x00, 0x01, 0x00, 0x00}));
  EXPECT_EQ(h.drive.operating_mode(), OperatingMode::Position);
  // §5.6: reading it back, 06 01 00 01 10 01 03 A2 00 00 -> 06 01 00 01 42 01 00 02.
  EXPECT_EQ(h.parameter(Bytes{0x06, 0x01, 0x00, 0x01, 0x10, 0x01, 0x03, 0xA2, 0x00, 0x00}),
            (Bytes{0x06, 0x01, 0x00, 0x01, 0x42, 0x01, 0x00, 0x02}));
}

TEST(ProfidriveSimParameters, DrvOpmodeAsByteWithPad) {
  // §5.6: 0A 02 00 01 10 01 08 57 00 00 41 01 02 00 (PNU 2135, Byte, pad byte).
  Harness h(config_for(9));
  const Bytes request{0x0A, 0x02, 0x00, 0x01, 0x10, 0x01, 0x08, 0x57, 0x00, 0x00, 0x41, 0x01, 0x01, 0x00};
  EXPECT_EQ(h.parameter(request), (Bytes{0x0A, 0x02, 0x00, 0x01, 0x00, 0x00}));
  EXPECT_EQ(h.drive.operating_mode(), OperatingMode::Speed);
  // A Byte read answers with its pad.
  EXPECT_EQ(h.parameter(Bytes{0x0B, 0x01, 0x00, 0x01, 0x10, 0x01, 0x08, 0x57, 0x00, 0x00}),
            (Bytes{0x0B, 0x01, 0x00, 0x01, 0x41, 0x01, 0x01, 0x00}));
}

TEST(ProfidriveSimParameters, RecordHandshake) {
  // [STD] A read with no request is a state conflict; so is a second request before the read.
  Harness h(config_for(1));
  std::array<std::uint8_t, kMaxParamRecord> buf{};
  EXPECT_EQ(h.drive.read_parameter_record(buf).status, RecordStatus::StateConflict);
  const Bytes read930{0x06, 0x01, 0x00, 0x01, 0x10, 0x01, 0x03, 0xA2, 0x00, 0x00};
  EXPECT_EQ(h.drive.write_parameter_record(read930), RecordStatus::Ok);
  EXPECT_EQ(h.drive.write_parameter_record(read930), RecordStatus::StateConflict);
  std::array<std::uint8_t, 4> small{};
  EXPECT_EQ(h.drive.read_parameter_record(small).status, RecordStatus::BufferTooSmall);  // still pending
  EXPECT_EQ(h.drive.read_parameter_record(buf).size, 8U);
  EXPECT_EQ(h.drive.read_parameter_record(buf).status, RecordStatus::StateConflict);
  EXPECT_EQ(h.drive.write_parameter_record(Bytes{0x06, 0x01, 0x00}), RecordStatus::WriteLengthError);
  EXPECT_EQ(h.drive.write_parameter_record(Bytes(241, 0x01)), RecordStatus::WriteLengthError);
}

TEST(ProfidriveSimParameters, SeveralParametersInOneRequest) {
  // §5.6: 09 01 00 02 10 01 03 B0 00 00 10 01 03 A2 00 00 -> counter and mode.
  Harness h(config_for(9));
  h.drive.inject_fault(702);
  EXPECT_EQ(h.parameter(Bytes{0x09, 0x01, 0x00, 0x02, 0x10, 0x01, 0x03, 0xB0, 0x00, 0x00, 0x10, 0x01, 0x03, 0xA2, 0x00, 0x00}),
            (Bytes{0x09, 0x01, 0x00, 0x02, 0x42, 0x01, 0x00, 0x01, 0x42, 0x01, 0x00, 0x02}));
  // Two changes: the AKD's 00 00 for each.
  const std::array<std::uint32_t, 1> jog{500};
  const std::array<std::uint32_t, 1> scale{2};
  const std::array<ParamChange, 2> p{ParamChange{{Attribute::Value, 1, 1004, 0}, format::kWord, jog},
                                     ParamChange{{Attribute::Value, 1, 1008, 0}, format::kWord, scale}};
  std::array<std::uint8_t, kMaxParamRecord> buf{};
  const EncodeResult e = encode_change_request(buf, 0x21, p);
  EXPECT_EQ(h.parameter(std::span(buf).first(e.size)), (Bytes{0x21, 0x02, 0x00, 0x02, 0x00, 0x00, 0x00, 0x00}));
  EXPECT_EQ(h.value(1004), 500U);
  EXPECT_EQ(h.value(1008), 2U);
}

TEST(ProfidriveSimParameters, NegativeResponsesCarryTheErrorNumbers) {
  // §5.3/§5.4 [STD]: 81h/82h with a 44h block per failed parameter.
  Harness h(config_for(1));
  EXPECT_EQ(h.parameter(Bytes{0x30, 0x01, 0x00, 0x01, 0x10, 0x01, 0x03, 0xE7, 0x00, 0x00}),  // PNU 999
            (Bytes{0x30, 0x81, 0x00, 0x01, 0x44, 0x01, 0x00, 0x00}));
  EXPECT_EQ(error_of(h.change(944, format::kWord, 3)), 0x01);      // read-only
  EXPECT_EQ(error_of(h.change(930, format::kWord, 7)), 0x02);      // out of range
  EXPECT_EQ(error_of(h.change(930, format::kDWord, 2)), 0x05);     // not its data type
  EXPECT_EQ(error_of(h.read(930, 1, 1)), 0x04);                    // not an array
  EXPECT_EQ(error_of(h.read(964, 2, 4)), 0x03);                    // past the array's end
  EXPECT_EQ(error_of(h.change(915, format::kWord, 1)), 0x01);      // fixed telegram: read-only
  EXPECT_EQ(error_of(h.change(3014, format::kDWord, 0)), 0x02);    // PN.POSSCALE 1..1e6 [§19.1]
  // Axis 1 does not exist (0x19).
  EXPECT_EQ(h.parameter(Bytes{0x31, 0x01, 0x01, 0x01, 0x10, 0x01, 0x03, 0xA2, 0x00, 0x00}),
            (Bytes{0x31, 0x81, 0x01, 0x01, 0x44, 0x01, 0x00, 0x19}));
  // Descriptions and texts are not offered.
  EXPECT_EQ(h.parameter(Bytes{0x32, 0x01, 0x00, 0x01, 0x20, 0x01, 0x03, 0xA2, 0x00, 0x00}),
            (Bytes{0x32, 0x81, 0x00, 0x01, 0x44, 0x01, 0x00, 0x09}));
  // Requests the drive cannot parse: a truncated address (0x16), format 44h in a change (0x17),
  // fewer values than elements (0x18).
  EXPECT_EQ(h.parameter(Bytes{0x33, 0x01, 0x00, 0x02, 0x10, 0x01, 0x03, 0xA2, 0x00, 0x00, 0x10}),
            (Bytes{0x33, 0x81, 0x00, 0x01, 0x44, 0x01, 0x00, 0x16}));
  EXPECT_EQ(h.parameter(Bytes{0x34, 0x02, 0x00, 0x01, 0x10, 0x01, 0x03, 0xA2, 0x00, 0x00, 0x44, 0x01, 0x00, 0x02}),
            (Bytes{0x34, 0x82, 0x00, 0x01, 0x44, 0x01, 0x00, 0x17}));
  EXPECT_EQ(h.parameter(Bytes{0x35, 0x02, 0x00, 0x01, 0x10, 0x02, 0x03, 0xA2, 0x00, 0x00, 0x42, 0x01, 0x00, 0x02}),
            (Bytes{0x35, 0x82, 0x00, 0x01, 0x44, 0x01, 0x00, 0x18}));
  EXPECT_EQ(h.drive.operating_mode(), OperatingMode::Speed);  // none of them changed anything
}

TEST(ProfidriveSimParameters, MixedChangeAppliesTheGoodOnes) {
  Harness h(config_for(1));
  const std::array<std::uint32_t, 1> good{2};
  const std::array<std::uint32_t, 1> bad{9};
  const std::array<ParamChange, 2> p{ParamChange{{Attribute::Value, 1, 930, 0}, format::kWord, good},
                                     ParamChange{{Attribute::Value, 1, 2135, 0}, format::kByte, bad}};
  std::array<std::uint8_t, kMaxParamRecord> buf{};
  const EncodeResult e = encode_change_request(buf, 0x40, p);
  EXPECT_EQ(h.parameter(std::span(buf).first(e.size)),
            (Bytes{0x40, 0x82, 0x00, 0x02, 0x40, 0x00, 0x44, 0x01, 0x00, 0x02}));
  EXPECT_EQ(h.drive.operating_mode(), OperatingMode::Position);
}

TEST(ProfidriveSimParameters, OperatingModeIsNotChangedInOperation) {
  Harness h(config_for(1));
  h.enable();
  EXPECT_EQ(error_of(h.change(930, format::kWord, 2)), 0x11);
  EXPECT_EQ(error_of(h.change(1002, format::kWord, 20)), 0x11);
}

TEST(ProfidriveSimParameters, IdentificationAndConfigurationReads) {
  DriveModelConfig c = config_for(352);
  c.watchdog_ms = 96;
  c.identification.manufacturer = 0x0123;
  Harness h(c);
  EXPECT_EQ(h.value(922), 352U);
  EXPECT_EQ(h.value(2157), 352U);  // FBUS.PARAM01 mirrors it [§18.4]
  EXPECT_EQ(h.value(965), 0x0329U);
  EXPECT_EQ(h.value(1002), 16U);
  EXPECT_EQ(h.value(3022), 96U);
  EXPECT_EQ(h.value(3014), 1000U);
  const ParamResponse id = h.read(964, 5);
  ASSERT_TRUE(id.positive());
  EXPECT_EQ(id.blocks[0].count, 5);
  EXPECT_EQ(id.blocks[0].value(0), 0x0123U);
  // P915/P916 of a fixed telegram show its layout [§13, §14.7].
  const ParamResponse l = h.read(915, 12);
  ASSERT_TRUE(l.positive());
  const std::array<std::uint16_t, 12> t352{1, 32, 3, 34, 34, 35, 35, 36, 37, 38, 100, 100};
  for (std::size_t i = 0; i < t352.size(); ++i) EXPECT_EQ(l.blocks[0].value(i), t352[i]) << i;
  EXPECT_EQ(error_of(h.read(916, 6)), 0x03);  // 5 actual words
}

TEST(ProfidriveSimParameters, SingleTurnBitsScaleXistA) {
  // §17.2: PNU 1002 sets the counts per revolution of the positions.
  DriveModelConfig c = config_for(351);
  c.start_position_rev = 2.0;
  Harness h(c);
  h.cycle();
  EXPECT_EQ(h.act.xist_a, 2 * 65536);
  EXPECT_TRUE(h.change(1002, format::kWord, 20).positive());
  h.cycle();
  EXPECT_EQ(h.act.xist_a, 2 * 1048576);
}

TEST(ProfidriveSimParameters, FaultBufferReadConsistentlyByTheControllerReader) {
  // §18.2, §24 step 12: PNU 944 -> 947 -> 944 with the gateway's FaultBufferReader.
  Harness h(config_for(1));
  h.drive.inject_fault(702);
  h.drive.inject_fault(439);
  FaultBufferReader reader;
  while (const auto a = reader.next_read()) {
    const ParamResponse r = h.read(a->pnu, a->elements, a->subindex);
    ASSERT_TRUE(r.positive());
    std::array<std::uint16_t, kFaultBufferEntries> v{};
    const auto n = u16_values(r.blocks[0], v);
    ASSERT_TRUE(n.has_value());
    reader.on_values(std::span(v).first(*n));
  }
  ASSERT_EQ(reader.status(), FaultBufferReader::Status::Consistent);
  EXPECT_EQ(reader.snapshot().counter, 1U);
  ASSERT_EQ(reader.snapshot().current().size(), 2U);
  EXPECT_EQ(reader.snapshot().current()[0], 702U);
  EXPECT_EQ(reader.snapshot().current()[1], 439U);
  // §5.6's constructed read of 8 elements from subindex 0.
  EXPECT_EQ(h.parameter(Bytes{0x08, 0x01, 0x00, 0x01, 0x10, 0x08, 0x03, 0xB3, 0x00, 0x00}),
            (Bytes{0x08, 0x01, 0x00, 0x01, 0x42, 0x08, 0x02, 0xBE, 0x01, 0xB7, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0}));
}

TEST(ProfidriveSimParameters, ResponseTooLong) {
  // Three reads of the whole fault buffer do not fit 240 bytes: the third answers 0x15.
  Harness h(config_for(1));
  const ParamAddress all{Attribute::Value, 64, 947, 0};
  const std::array<ParamAddress, 3> p{all, all, ParamAddress{Attribute::Value, 1, 944, 0}};
  std::array<std::uint8_t, kMaxParamRecord> buf{};
  const EncodeResult e = encode_read_request(buf, 0x50, p);
  const Bytes reply = h.parameter(std::span(buf).first(e.size));
  const ResponseResult r = decode_param_response(reply);
  ASSERT_EQ(r.error, ParamError::None);
  EXPECT_EQ(r.response.response_id, response_id::kReadFailed);
  EXPECT_EQ(r.response.blocks[0].count, 64);
  EXPECT_EQ(error_of(r.response, 1), 0x15);
  EXPECT_EQ(r.response.blocks[2].value(0), 0U);  // the counter still answered
}

TEST(ProfidriveSimParameters, MotionTasksThroughMtParameters) {
  // MT.NUM, MT.P, MT.V_32, MT.ACC, MT.DEC, MT.CNTL, MT.SET in one request, then program mode runs
  // the stored task [§16.2].
  Harness h(config_for(7));
  const std::array<std::uint32_t, 1> num{2}, pos{3 * 65536}, vel{0x08000000}, acc{8}, cntl{1}, set{0};
  const std::array<ParamChange, 7> p{
      ParamChange{{Attribute::Value, 1, 2274, 0}, format::kByte, num},
      ParamChange{{Attribute::Value, 1, 2275, 0}, format::kDWord, pos},
      ParamChange{{Attribute::Value, 1, 2283, 0}, format::kDWord, vel},
      ParamChange{{Attribute::Value, 1, 2263, 0}, format::kDWord, acc},
      ParamChange{{Attribute::Value, 1, 2268, 0}, format::kDWord, acc},
      ParamChange{{Attribute::Value, 1, 2266, 0}, format::kDWord, cntl},
      ParamChange{{Attribute::Value, 1, 2277, 0}, format::kByte, set}};
  std::array<std::uint8_t, kMaxParamRecord> buf{};
  const EncodeResult e = encode_change_request(buf, 0x60, p);
  ASSERT_EQ(e.error, ParamError::None);
  const Bytes reply = h.parameter(std::span(buf).first(e.size));
  ASSERT_GE(reply.size(), 2U);
  EXPECT_EQ(reply[1], response_id::kChangeOk);
  EXPECT_EQ(error_of(h.change(2274, format::kByte, 16)), 0x02);  // no task 16
  h.enable();
  h.send(stw1_word::kHoming);
  ASSERT_TRUE(h.until([&] { return h.drive.homed(); }, 50));
  h.sp.satzanw = 2;
  h.send(stw1_word::kTaskReady);
  h.send(stw1_word::kTaskActivate);
  ASSERT_TRUE(h.until([&] { return (h.act.zsw1 & zsw1::kTargetReached) != 0; }, 3000));
  EXPECT_NEAR(h.drive.position_rev(), 3.0, 0.002);
}

}  // namespace
}  // namespace drivegate::profidrive::sim::test
