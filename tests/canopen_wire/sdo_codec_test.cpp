// SDO codec against the byte-exact vectors of the reference digests.
#include <gtest/gtest.h>

#include <vector>

#include "adapters/canopen/wire/can_frame.hpp"
#include "adapters/canopen/wire/sdo_codec.hpp"

namespace drivegate::canopen {
namespace {

using Bytes = std::vector<std::uint8_t>;
Bytes v(const SdoBytes& b) { return {b.begin(), b.end()}; }

// SD6 digest §11.1 TV-1: segmented download of 01..10h (object 2000h:01 for the IL IH SS bytes).
TEST(SdoCodec, Sd6SegmentedDownloadTv1) {
  const ObjectId o{0x2000, 0x01};
  EXPECT_EQ(v(sdo_download_initiate(o, 16)), (Bytes{0x21, 0x00, 0x20, 0x01, 0x10, 0, 0, 0}));
  const std::uint8_t data[16] = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16};
  EXPECT_EQ(v(sdo_download_segment(false, {data, 7}, false)), (Bytes{0x00, 1, 2, 3, 4, 5, 6, 7}));
  EXPECT_EQ(v(sdo_download_segment(true, {data + 7, 7}, false)), (Bytes{0x10, 8, 9, 10, 11, 12, 13, 14}));
  EXPECT_EQ(v(sdo_download_segment(false, {data + 14, 2}, true)), (Bytes{0x0B, 0x0F, 0x10, 0, 0, 0, 0, 0}));
  EXPECT_EQ(v(sdo_download_response(o)), (Bytes{0x60, 0x00, 0x20, 0x01, 0, 0, 0, 0}));
  EXPECT_EQ(v(sdo_download_segment_response(false)), (Bytes{0x20, 0, 0, 0, 0, 0, 0, 0}));
  EXPECT_EQ(v(sdo_download_segment_response(true)), (Bytes{0x30, 0, 0, 0, 0, 0, 0, 0}));

  const Bytes last{0x0B, 0x0F, 0x10, 0, 0, 0, 0, 0};
  const auto d = decode_sdo_request(last);
  ASSERT_EQ(d.error, SdoDecodeError::None);
  EXPECT_EQ(d.message.command, SdoCommand::DownloadSegmentRequest);
  EXPECT_FALSE(d.message.toggle);
  EXPECT_TRUE(d.message.last);
  EXPECT_EQ(d.message.length, 2);
}

// SD6 digest §11.1 TV-2: segmented upload.
TEST(SdoCodec, Sd6SegmentedUploadTv2) {
  const ObjectId o{0x2000, 0x01};
  EXPECT_EQ(v(sdo_upload_request(o)), (Bytes{0x40, 0x00, 0x20, 0x01, 0, 0, 0, 0}));
  EXPECT_EQ(v(sdo_upload_initiate_response(o, 16)), (Bytes{0x41, 0x00, 0x20, 0x01, 0x10, 0, 0, 0}));
  EXPECT_EQ(v(sdo_upload_segment_request(false)), (Bytes{0x60, 0, 0, 0, 0, 0, 0, 0}));
  EXPECT_EQ(v(sdo_upload_segment_request(true)), (Bytes{0x70, 0, 0, 0, 0, 0, 0, 0}));
  const auto init = decode_sdo_response(Bytes{0x41, 0x00, 0x20, 0x01, 0x10, 0, 0, 0});
  ASSERT_EQ(init.error, SdoDecodeError::None);
  EXPECT_EQ(init.message.command, SdoCommand::InitiateUploadResponse);
  EXPECT_FALSE(init.message.expedited);
  EXPECT_TRUE(init.message.size_indicated);
  EXPECT_EQ(init.message.size, 16U);
  const auto seg = decode_sdo_response(Bytes{0x10, 8, 9, 10, 11, 12, 13, 14});
  EXPECT_EQ(seg.message.command, SdoCommand::UploadSegmentResponse);
  EXPECT_TRUE(seg.message.toggle);
  EXPECT_FALSE(seg.message.last);
  EXPECT_EQ(seg.message.length, 7);
}

// AKD part 1 §14 vectors 3-8, 10, 11, 16, 21, 22.
TEST(SdoCodec, AkdExpeditedVectors) {
  EXPECT_EQ(v(sdo_download_expedited({0x1800, 1}, 0xC0000181, 4)), (Bytes{0x23, 0x00, 0x18, 0x01, 0x81, 0x01, 0x00, 0xC0}));
  EXPECT_EQ(v(sdo_download_expedited({0x1A00, 0}, 0, 1)), (Bytes{0x2F, 0x00, 0x1A, 0x00, 0, 0, 0, 0}));
  EXPECT_EQ(v(sdo_download_expedited({0x1A00, 1}, 0x60410010, 4)), (Bytes{0x23, 0x00, 0x1A, 0x01, 0x10, 0x00, 0x41, 0x60}));
  EXPECT_EQ(v(sdo_download_expedited({0x1A00, 2}, 0x10020020, 4)), (Bytes{0x23, 0x00, 0x1A, 0x02, 0x20, 0x00, 0x02, 0x10}));
  EXPECT_EQ(v(sdo_download_expedited({0x1A00, 0}, 2, 1)), (Bytes{0x2F, 0x00, 0x1A, 0x00, 0x02, 0, 0, 0}));
  EXPECT_EQ(v(sdo_download_expedited({0x1800, 1}, 0x40000181, 4)), (Bytes{0x23, 0x00, 0x18, 0x01, 0x81, 0x01, 0x00, 0x40}));
  EXPECT_EQ(v(sdo_upload_request({0x1000, 0})), (Bytes{0x40, 0x00, 0x10, 0x00, 0, 0, 0, 0}));
  EXPECT_EQ(v(sdo_download_expedited({0x1017, 0}, 100, 2)), (Bytes{0x2B, 0x17, 0x10, 0x00, 0x64, 0, 0, 0}));
  EXPECT_EQ(v(sdo_download_expedited({0x1016, 1}, 0x007F00FA, 4)), (Bytes{0x23, 0x16, 0x10, 0x01, 0xFA, 0x00, 0x7F, 0x00}));

  const auto r = decode_sdo_response(Bytes{0x43, 0x00, 0x10, 0x00, 0x92, 0x01, 0x02, 0x00});
  ASSERT_EQ(r.error, SdoDecodeError::None);
  EXPECT_EQ(r.message.command, SdoCommand::InitiateUploadResponse);
  EXPECT_TRUE(r.message.expedited);
  EXPECT_EQ(r.message.length, 4);
  EXPECT_EQ(r.message.object, (ObjectId{0x1000, 0}));
  EXPECT_EQ(v(sdo_upload_expedited_response({0x1000, 0}, 0x00020192, 4)),
            (Bytes{0x43, 0x00, 0x10, 0x00, 0x92, 0x01, 0x02, 0x00}));

  const auto a = decode_sdo_response(Bytes{0x80, 0x22, 0x22, 0x00, 0x00, 0x00, 0x02, 0x06});
  EXPECT_EQ(a.message.command, SdoCommand::Abort);
  EXPECT_EQ(a.message.object, (ObjectId{0x2222, 0}));
  EXPECT_EQ(a.message.abort_code, 0x06020000U);
  EXPECT_EQ(v(sdo_abort({0x1A00, 0}, 0x06040042)), (Bytes{0x80, 0x00, 0x1A, 0x00, 0x42, 0x00, 0x04, 0x06}));
}

// SD6 sends 42h (expedited, size not indicated): all four bytes are handed up (SD6 digest §6.4);
// 63h for a download response is accepted as 60h (quirk 19).
TEST(SdoCodec, Sd6ToleratedVariants) {
  const auto r = decode_sdo_response(Bytes{0x42, 0x00, 0x10, 0x00, 0x92, 0x01, 0x02, 0x00});
  ASSERT_EQ(r.error, SdoDecodeError::None);
  EXPECT_TRUE(r.message.expedited);
  EXPECT_FALSE(r.message.size_indicated);
  EXPECT_EQ(r.message.length, 4);
  EXPECT_EQ(decode_sdo_response(Bytes{0x63, 0x17, 0x10, 0, 0, 0, 0, 0}).message.command,
            SdoCommand::InitiateDownloadResponse);
}

TEST(SdoCodec, BadFramesAreReported) {
  EXPECT_EQ(decode_sdo_response(Bytes{0x43, 0x00, 0x10}).error, SdoDecodeError::WrongLength);
  EXPECT_EQ(decode_sdo_response(Bytes{}).error, SdoDecodeError::WrongLength);
  EXPECT_EQ(decode_sdo_response(Bytes{0xE0, 0, 0, 0, 0, 0, 0, 0}).error, SdoDecodeError::UnknownCommand);
  EXPECT_EQ(decode_sdo_request(Bytes{0xE0, 0, 0, 0, 0, 0, 0, 0}).error, SdoDecodeError::UnknownCommand);
  EXPECT_EQ(decode_sdo_request(Bytes{0xC0, 0, 0, 0, 0, 0, 0, 0}).message.command, SdoCommand::Block);
}

}  // namespace
}  // namespace drivegate::canopen

namespace drivegate::canopen {
namespace {

// The byte helpers never read or write past the span or beyond 4 bytes, and a frame's payload is
// never longer than 8 bytes whatever its dlc says.
TEST(CanFrame, HelpersStayInBounds) {
  const std::uint8_t bytes[6] = {1, 2, 3, 4, 5, 6};
  EXPECT_EQ(get_le(bytes, 0, 7), 0x04030201U);
  EXPECT_EQ(get_le(bytes, 4, 4), 0x0605U);
  std::uint8_t out[3] = {};
  put_le(out, 1, 4, 0xAABBCCDD);
  EXPECT_EQ(out[0], 0);
  EXPECT_EQ(out[1], 0xDD);
  EXPECT_EQ(out[2], 0xCC);
  CanFrame f;
  f.dlc = 15;
  EXPECT_FALSE(f.valid());
  EXPECT_EQ(f.payload().size(), 8U);
  f.remote = true;
  EXPECT_TRUE(f.payload().empty());
}

}  // namespace
}  // namespace drivegate::canopen
