// PdoLayout and ProcessImage: mapping rules, sign extension, truncation and the byte layout of the
// reference drives' PDOs (NORD TV-B/TV-C/TV-D, AKD part 1 §14 vectors 30/31).
#include "tests/canopen_pdo/pdo_harness.hpp"

namespace drivegate::canopen::test {
namespace {

TEST(PdoLayout, OffsetsFollowTheMappingOrder) {
  // NORD TxPDO1 (nord-sk500p-ds402.md §8.1): SW | 6044h | 6061h | 6077h, 7 bytes.
  const auto l = layout({obj::kStatusword, obj::kVlVelocityActual, obj::kModesOfOperationDisplay, obj::kTorqueActual});
  ASSERT_EQ(l.count, 4);
  EXPECT_EQ(l.bytes, 7);
  EXPECT_EQ(l.fields[0].offset, 0);
  EXPECT_EQ(l.fields[1].offset, 2);
  EXPECT_EQ(l.fields[2].offset, 4);
  EXPECT_EQ(l.fields[3].offset, 5);
  EXPECT_EQ(l.fields[3].def.id, obj::kTorqueActual.id);
}

TEST(PdoLayout, RefusesBitLengthsThatAreNotTheObjectsSize) {
  PdoLayout l;
  EXPECT_EQ(l.add(obj::kControlword, 8), PdoLayout::Error::BadLength);   // U16 as 8 bit
  EXPECT_EQ(l.add(obj::kControlword, 32), PdoLayout::Error::BadLength);  // U16 as 32 bit
  EXPECT_EQ(l.add(obj::kControlword, 12), PdoLayout::Error::BadLength);  // not byte-granular
  EXPECT_EQ(l.add(obj::kTargetPosition, 24), PdoLayout::Error::BadLength);
  EXPECT_EQ(l.add(obj::kModesOfOperation, 0), PdoLayout::Error::BadLength);
  EXPECT_EQ(l.count, 0);
  EXPECT_EQ(l.bytes, 0);
  EXPECT_STRNE(to_string(PdoLayout::Error::BadLength), to_string(PdoLayout::Error::TooLong));
}

TEST(PdoLayout, RefusesMoreThanEightBytesAndLeavesTheLayoutUnchanged) {
  PdoLayout l;
  ASSERT_EQ(l.add(obj::kTargetPosition, 32), PdoLayout::Error::None);
  ASSERT_EQ(l.add(obj::kControlword, 16), PdoLayout::Error::None);
  ASSERT_EQ(l.add(obj::kModesOfOperation, 8), PdoLayout::Error::None);  // 7 bytes
  EXPECT_EQ(l.add(obj::kTargetTorque, 16), PdoLayout::Error::TooLong);  // would be 9
  EXPECT_EQ(l.count, 3);
  EXPECT_EQ(l.bytes, 7);
  EXPECT_EQ(l.add(obj::kModesOfOperation, 8), PdoLayout::Error::None);  // exactly 8 still fits
  EXPECT_EQ(l.bytes, 8);
}

TEST(PdoLayout, RefusesANinthEntry) {
  PdoLayout l;
  for (int i = 0; i < 8; ++i) {
    ASSERT_EQ(l.add({{0x2000, static_cast<std::uint8_t>(i)}, DataType::U8}, 8), PdoLayout::Error::None);
  }
  EXPECT_EQ(l.add({{0x2000, 9}, DataType::U8}, 8), PdoLayout::Error::TooManyEntries);
  EXPECT_EQ(l.count, 8);
  EXPECT_EQ(l.bytes, 8);
}

TEST(ProcessImage, SignExtendsAndTruncatesPerType) {
  ProcessImage img;
  for (const auto& d : {obj::kModesOfOperation, obj::kControlword, obj::kVlTargetVelocity, obj::kTargetPosition,
                        obj::kProfileVelocity, obj::kErrorRegister}) {
    ASSERT_TRUE(img.add(d));
  }
  img.set(obj::kModesOfOperation.id, 0xFF);  // I8
  EXPECT_EQ(img.get(obj::kModesOfOperation.id), -1);
  img.set(obj::kModesOfOperation.id, -6);
  EXPECT_EQ(img.get(obj::kModesOfOperation.id), -6);
  img.set(obj::kControlword.id, 0x1234F);  // U16 keeps the low 16 bits
  EXPECT_EQ(img.get(obj::kControlword.id), 0x234F);
  img.set(obj::kControlword.id, -1);
  EXPECT_EQ(img.get(obj::kControlword.id), 0xFFFF);
  img.set(obj::kVlTargetVelocity.id, 0x8000);  // I16
  EXPECT_EQ(img.get(obj::kVlTargetVelocity.id), -32768);
  img.set(obj::kTargetPosition.id, 0xFFFFFFFFLL);  // I32
  EXPECT_EQ(img.get(obj::kTargetPosition.id), -1);
  img.set(obj::kTargetPosition.id, 0x1'0000'0005LL);
  EXPECT_EQ(img.get(obj::kTargetPosition.id), 5);
  img.set(obj::kProfileVelocity.id, -1);  // U32
  EXPECT_EQ(img.get(obj::kProfileVelocity.id), 0xFFFFFFFFLL);
  img.set(obj::kErrorRegister.id, 0x1FF);  // U8
  EXPECT_EQ(img.get(obj::kErrorRegister.id), 0xFF);
}

TEST(ProcessImage, UnknownObjectsReadZeroAndIgnoreWrites) {
  ProcessImage img;
  ASSERT_TRUE(img.add(obj::kControlword));
  img.set(obj::kStatusword.id, 7);
  EXPECT_FALSE(img.contains(obj::kStatusword.id));
  EXPECT_EQ(img.get(obj::kStatusword.id), 0);
}

TEST(ProcessImage, MergesDuplicatesAndRefusesATypeConflictOrOverflow) {
  ProcessImage img;
  ASSERT_TRUE(img.add(obj::kControlword));
  img.set(obj::kControlword.id, 0x0F);
  EXPECT_TRUE(img.add(obj::kControlword));  // merged, value kept
  EXPECT_EQ(img.get(obj::kControlword.id), 0x0F);
  EXPECT_FALSE(img.add({obj::kControlword.id, DataType::I32}));
  for (std::size_t i = 1; i < ProcessImage::kCapacity; ++i) {
    ASSERT_TRUE(img.add({{0x2100, static_cast<std::uint8_t>(i)}, DataType::U8}));
  }
  EXPECT_FALSE(img.add({{0x2200, 0}, DataType::U8}));
  EXPECT_TRUE(img.add(obj::kControlword));  // still merged when full
}

TEST(ProcessImage, UnpackNeverReadsPastTheFrame) {
  ProcessImage img;
  const auto l = layout({obj::kStatusword, obj::kPositionActual});
  ASSERT_TRUE(img.add(obj::kStatusword));
  ASSERT_TRUE(img.add(obj::kPositionActual));
  img.set(obj::kPositionActual.id, 99);
  const std::uint8_t three[] = {0x37, 0x02, 0xAA};
  img.unpack(l, three);  // the 4-byte field does not fit: it keeps its value
  EXPECT_EQ(img.get(obj::kStatusword.id), 0x0237);
  EXPECT_EQ(img.get(obj::kPositionActual.id), 99);
}

// NORD TV-B / TV-C / TV-D (nord-sk500p-ds402.md §10): RxPDO1 CW | 6042h | 6060h padded to 8,
// RxPDO2 6083h | 6084h, RxPDO3 607Ah | 6081h, TxPDO1 SW | 6044h | 6061h | 6077h.
struct NordImage {
  PdoLayout rx1 = layout({obj::kControlword, obj::kVlTargetVelocity, obj::kModesOfOperation});
  PdoLayout rx2 = layout({obj::kProfileAcceleration, obj::kProfileDeceleration});
  PdoLayout rx3 = layout({obj::kTargetPosition, obj::kProfileVelocity});
  PdoLayout tx1 = layout({obj::kStatusword, obj::kVlVelocityActual, obj::kModesOfOperationDisplay, obj::kTorqueActual});
  ProcessImage img;
  NordImage() {
    for (const auto* l : {&rx1, &rx2, &rx3, &tx1}) {
      for (std::size_t i = 0; i < l->count; ++i) EXPECT_TRUE(img.add(l->fields[i].def));
    }
  }
  Bytes pack(const PdoLayout& l) const {
    std::array<std::uint8_t, 8> out{0xEE, 0xEE, 0xEE, 0xEE, 0xEE, 0xEE, 0xEE, 0xEE};
    img.pack(l, out);
    return {out.begin(), out.end()};
  }
};

TEST(NordVectors, TvbHomingRxPdo1Bytes) {
  NordImage n;
  n.img.set(obj::kModesOfOperation.id, 6);
  const std::pair<int, Bytes> steps[] = {
      {0x06, {0x06, 0, 0, 0, 0x06, 0, 0, 0}},  // B1
      {0x07, {0x07, 0, 0, 0, 0x06, 0, 0, 0}},  // B2
      {0x0F, {0x0F, 0, 0, 0, 0x06, 0, 0, 0}},  // B3
      {0x1F, {0x1F, 0, 0, 0, 0x06, 0, 0, 0}},  // B4..B6
  };
  for (const auto& [cw, bytes] : steps) {
    n.img.set(obj::kControlword.id, cw);
    EXPECT_EQ(n.pack(n.rx1), bytes) << "CW " << cw;  // padding bytes 5..7 are zero
  }
}

TEST(NordVectors, TvbTvcTxPdo1Decoding) {
  NordImage n;
  // B5: "37 12 xx xx 06 xx xx" with the don't-care bytes filled.
  n.img.unpack(n.tx1, Bytes{0x37, 0x12, 0x34, 0x12, 0x06, 0xFE, 0xFF});
  EXPECT_EQ(n.img.get(obj::kStatusword.id), 0x1237);
  EXPECT_EQ(n.img.get(obj::kVlVelocityActual.id), 0x1234);
  EXPECT_EQ(n.img.get(obj::kModesOfOperationDisplay.id), 6);
  EXPECT_EQ(n.img.get(obj::kTorqueActual.id), -2);
  // C8: target reached.
  n.img.unpack(n.tx1, Bytes{0x37, 0x06, 0x00, 0x00, 0x01, 0x00, 0x00});
  EXPECT_EQ(n.img.get(obj::kStatusword.id), 0x0637);
  EXPECT_EQ(n.img.get(obj::kModesOfOperationDisplay.id), 1);
  EXPECT_EQ(n.img.get(obj::kTorqueActual.id), 0);
}

TEST(NordVectors, TvcProfilePositionRxPdos) {
  NordImage n;
  n.img.set(obj::kProfileAcceleration.id, 750);  // C1: 750 rpm/s both ways
  n.img.set(obj::kProfileDeceleration.id, 750);
  EXPECT_EQ(n.pack(n.rx2), (Bytes{0xEE, 0x02, 0, 0, 0xEE, 0x02, 0, 0}));
  // C5 as printed (the digest notes the source error: the bytes are 9 490 435, not 200 rev).
  n.img.set(obj::kTargetPosition.id, 0x0090D003);
  n.img.set(obj::kProfileVelocity.id, 1000);
  EXPECT_EQ(n.pack(n.rx3), (Bytes{0x03, 0xD0, 0x90, 0x00, 0xE8, 0x03, 0, 0}));
  n.img.set(obj::kTargetPosition.id, 200000);  // the corrected 200.000 rev
  EXPECT_EQ(n.pack(n.rx3), (Bytes{0x40, 0x0D, 0x03, 0x00, 0xE8, 0x03, 0, 0}));
  // C6: new set-point with mode 1.
  n.img.set(obj::kControlword.id, 0x1F);
  n.img.set(obj::kModesOfOperation.id, 1);
  EXPECT_EQ(n.pack(n.rx1), (Bytes{0x1F, 0, 0, 0, 0x01, 0, 0, 0}));
}

TEST(NordVectors, TvdVelocityModeFrames) {
  NordImage n;
  n.img.set(obj::kControlword.id, 0x7F);
  n.img.set(obj::kVlTargetVelocity.id, 1500);
  n.img.set(obj::kModesOfOperation.id, 2);
  EXPECT_EQ(n.pack(n.rx1), (Bytes{0x7F, 0x00, 0xDC, 0x05, 0x02, 0, 0, 0}));
  n.img.set(obj::kControlword.id, 0x17F);  // halt
  EXPECT_EQ(n.pack(n.rx1), (Bytes{0x7F, 0x01, 0xDC, 0x05, 0x02, 0, 0, 0}));
  n.img.set(obj::kVlTargetVelocity.id, -1500);  // reverse: two's complement on the wire
  EXPECT_EQ(n.pack(n.rx1), (Bytes{0x7F, 0x01, 0x24, 0xFA, 0x02, 0, 0, 0}));
}

// AKD part 1 §14 vectors 30 and 31: default RPDO3 / TPDO3 (§12.5), node 1.
TEST(AkdVectors, DefaultRpdo3AndTpdo3) {
  ProcessImage img;
  const auto rpdo3 = layout({obj::kControlword, obj::kTargetPosition});
  const auto tpdo3 = layout({obj::kStatusword, obj::kPositionActual});
  for (const auto& d : {obj::kControlword, obj::kTargetPosition, obj::kStatusword, obj::kPositionActual}) {
    ASSERT_TRUE(img.add(d));
  }
  img.set(obj::kControlword.id, 0x1F);
  img.set(obj::kTargetPosition.id, 100000);
  std::array<std::uint8_t, 8> out{};
  img.pack(rpdo3, out);
  EXPECT_EQ(rpdo3.bytes, 6);
  EXPECT_EQ(Bytes(out.begin(), out.begin() + rpdo3.bytes), (Bytes{0x1F, 0x00, 0xA0, 0x86, 0x01, 0x00}));
  img.unpack(tpdo3, Bytes{0x37, 0x02, 0xE8, 0x03, 0x00, 0x00});
  EXPECT_EQ(img.get(obj::kStatusword.id), 0x0237);
  EXPECT_EQ(img.get(obj::kPositionActual.id), 1000);
  img.unpack(tpdo3, Bytes{0x37, 0x02, 0x18, 0xFC, 0xFF, 0xFF});
  EXPECT_EQ(img.get(obj::kPositionActual.id), -1000);
}

}  // namespace
}  // namespace drivegate::canopen::test
