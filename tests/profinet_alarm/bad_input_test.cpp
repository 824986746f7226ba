// Frames the controller's AlarmChannel must count and drop without taking an alarm: foreign
// sources and endpoints, RTA-PDUs and blocks that do not decode, blocks of the wrong priority or
// kind, DATA out of sequence (NACKed), stale ACKs, and notifications beyond its AlarmAck queue (not
// acknowledged, so the device sends them again); a NACK sends the AlarmAck again at once. The
// channel keeps working afterwards.
#include <gtest/gtest.h>

#include "tests/profinet_alarm/alarm_wire.hpp"

namespace drivegate::profinet::test {
namespace {

struct Pdu {
  MacAddress src = kDeviceMac;
  AlarmPriority frame = AlarmPriority::High;  // picks the FrameID
  std::uint16_t dst_ref = kControllerRef;
  std::uint16_t src_ref = kDeviceRef;
  RtaPduType type = RtaPduType::Data;
  std::uint16_t send_seq = 0xFFFF;
  std::uint16_t ack_seq = 0xFFFE;
};

// A device's alarm frame with `block` as the RTA-SDU.
Bytes frame_of(const Pdu& p, std::span<const std::uint8_t> block) {
  Bytes out(kMaxFrameSize);
  EthernetHeader h;
  h.dst = kControllerMac;
  h.src = p.src;
  h.vlan = true;
  h.priority = p.frame == AlarmPriority::High ? kPriorityAlarmHigh : kPriorityAlarmLow;
  h.frame_id = p.frame == AlarmPriority::High ? frame_id::kAlarmHigh : frame_id::kAlarmLow;
  const std::size_t at = encode_ethernet_header(h, out);
  RtaHeader r;
  r.dst_endpoint = p.dst_ref;
  r.src_endpoint = p.src_ref;
  r.type = p.type;
  r.tack = p.type == RtaPduType::Data;
  r.send_seq = p.send_seq;
  r.ack_seq = p.ack_seq;
  const std::size_t n = encode_rta(std::span(out).subspan(at), r, block);
  out.resize(pad_frame(out, at + n));
  return out;
}

Bytes notification_block(const AlarmNotification& n) {
  Bytes b(kMaxPayloadSize);
  b.resize(encode_alarm_notification(b, n));
  return b;
}

// Polls the controller and returns the frames it sends.
std::vector<Bytes> drain(AlarmChannel& c, core::TimePoint now) {
  std::vector<Bytes> out;
  std::array<std::uint8_t, kMaxFrameSize> buf{};
  while (const std::size_t n = c.poll(now, buf)) out.emplace_back(buf.begin(), buf.begin() + static_cast<std::ptrdiff_t>(n));
  return out;
}

TEST(PnAlarmBadInput, ForeignAndMalformedFramesAreCountedAndDropped) {
  Recorder rec;
  AlarmChannel c(channel_config(), &rec);
  const core::TimePoint now{std::chrono::seconds(1)};
  const Bytes good = notification_block(alarm(alarm_type::kProcess));

  // Before open(): inactive.
  EXPECT_TRUE(c.on_frame(frame_of({}, good), now));
  EXPECT_EQ(c.counters().inactive, 1U);
  c.open();

  Pdu p;
  p.src = {0x00, 0x1B, 0x1B, 0x99, 0x99, 0x99};
  EXPECT_TRUE(c.on_frame(frame_of(p, good), now));
  p = {};
  p.dst_ref = 0x0042;
  EXPECT_TRUE(c.on_frame(frame_of(p, good), now));
  p = {};
  p.src_ref = 0x0042;
  EXPECT_TRUE(c.on_frame(frame_of(p, good), now));
  // An RTA header that is cut, a PDU type 7, a VarPartLen beyond the frame (the RTA header
  // starts at 20, behind the tagged header and the FrameID).
  Bytes cut = frame_of({}, good);
  cut.resize(20 + 8);
  EXPECT_TRUE(c.on_frame(cut, now));
  Bytes bad_type = frame_of({}, good);
  bad_type[20 + 4] = 0x17;
  EXPECT_TRUE(c.on_frame(bad_type, now));
  Bytes long_var = frame_of({}, good);
  long_var[20 + 10] = 0x05;
  EXPECT_TRUE(c.on_frame(long_var, now));
  // A notification whose BlockLength lies.
  Bytes lying = good;
  lying[3] = static_cast<std::uint8_t>(lying[3] + 2);
  EXPECT_TRUE(c.on_frame(frame_of({}, lying), now));
  // The low block in the high FrameID, an AlarmAck block from the device.
  EXPECT_TRUE(c.on_frame(frame_of({}, notification_block(alarm(alarm_type::kProcess, AlarmPriority::Low))), now));
  Bytes ack(kAlarmAckSize);
  (void)encode_alarm_ack(ack, ack_for(alarm(alarm_type::kProcess)));
  EXPECT_TRUE(c.on_frame(frame_of({}, ack), now));
  // Not an alarm frame at all: not ours.
  Bytes cyclic = frame_of({}, good);
  cyclic[18] = 0x80;
  cyclic[19] = 0x01;
  EXPECT_FALSE(c.on_frame(cyclic, now));

  const AlarmChannelCounters& k = c.counters();
  EXPECT_EQ(k.wrong_source, 1U);
  EXPECT_EQ(k.wrong_endpoint, 2U);
  EXPECT_EQ(k.malformed, 4U);
  EXPECT_EQ(k.wrong_priority, 1U);
  EXPECT_EQ(k.unexpected_block, 1U);
  EXPECT_TRUE(rec.alarms.empty());
  EXPECT_TRUE(drain(c, now).empty());  // none of them is acknowledged

  // DATA out of sequence: NACKed with the last number taken.
  p = {};
  p.send_seq = 5;
  EXPECT_TRUE(c.on_frame(frame_of(p, good), now));
  std::vector<Bytes> sent = drain(c, now);
  ASSERT_EQ(sent.size(), 1U);
  EXPECT_EQ(rta_of(sent[0]).header.type, RtaPduType::Nack);
  EXPECT_EQ(rta_of(sent[0]).header.ack_seq, 0xFFFE);
  EXPECT_EQ(c.rta_counters(AlarmPriority::High).out_of_sequence, 1U);

  // The right one is still taken.
  EXPECT_TRUE(c.on_frame(frame_of({}, good), now));
  EXPECT_EQ(rec.alarms.size(), 1U);
  sent = drain(c, now);
  ASSERT_EQ(sent.size(), 2U);  // ACK, AlarmAck
  EXPECT_EQ(rta_of(sent[0]).header.type, RtaPduType::Ack);
  EXPECT_TRUE(is_block(sent[1], alarm_block::kAckHigh));

  // A NACK sends the AlarmAck in flight again at once; an ACK of another number confirms nothing;
  // the ACK of its number does.
  p = {};
  p.type = RtaPduType::Nack;
  EXPECT_TRUE(c.on_frame(frame_of(p, {}), now));
  sent = drain(c, now);
  ASSERT_EQ(sent.size(), 1U);
  EXPECT_TRUE(is_block(sent[0], alarm_block::kAckHigh));
  EXPECT_EQ(c.rta_counters(AlarmPriority::High).nacks_received, 1U);
  EXPECT_EQ(c.rta_counters(AlarmPriority::High).retransmissions, 1U);
  p.type = RtaPduType::Ack;
  p.ack_seq = 0x0000;
  EXPECT_TRUE(c.on_frame(frame_of(p, {}), now));
  EXPECT_EQ(c.rta_counters(AlarmPriority::High).stale_acks, 1U);
  EXPECT_EQ(c.counters().acks_confirmed, 0U);
  p.ack_seq = 0xFFFF;
  EXPECT_TRUE(c.on_frame(frame_of(p, {}), now));
  EXPECT_EQ(c.counters().acks_confirmed, 1U);
  EXPECT_EQ(c.next_deadline(), core::TimePoint::max());
  EXPECT_EQ(c.state(), AlarmChannelState::Open);
}

TEST(PnAlarmBadInput, NotificationsBeyondTheAckQueueAreNotAcknowledged) {
  Recorder rec;
  AlarmChannel c(channel_config(), &rec);
  c.open();
  const core::TimePoint now{std::chrono::seconds(1)};
  // A device that never acknowledges our AlarmAcks but keeps sending alarms (piggybacking nothing):
  // one AlarmAck on its way, kAckQueueDepth waiting, then the queue is full.
  std::uint16_t seq = 0xFFFF;
  const std::size_t fits = 1 + AlarmChannel::kAckQueueDepth;
  for (std::size_t i = 0; i <= fits; ++i) {
    Pdu p;
    p.send_seq = seq;
    EXPECT_TRUE(c.on_frame(frame_of(p, notification_block(alarm(alarm_type::kProcess))), now));
    (void)drain(c, now);
    if (i < fits) seq = next_rta_seq(seq);
  }
  EXPECT_EQ(rec.alarms.size(), fits);
  EXPECT_EQ(c.counters().queue_full, 1U);
  EXPECT_EQ(c.rta_counters(AlarmPriority::High).taken, fits);
  EXPECT_EQ(c.rta_counters(AlarmPriority::High).acks_sent, fits);
}

TEST(PnAlarmBadInput, APollBufferTooSmallLosesTheFrameWithoutSpinning) {
  AlarmWire w;
  ASSERT_TRUE(w.device.send(alarm(alarm_type::kProcess)));
  // Deliver the notification by hand, then poll the controller with a tiny buffer.
  std::array<std::uint8_t, kMaxFrameSize> buf{};
  const std::size_t n = w.device.poll(w.now, buf);
  ASSERT_GT(n, 0U);
  EXPECT_TRUE(w.controller.on_frame(std::span<const std::uint8_t>(buf).first(n), w.now));
  std::array<std::uint8_t, 30> tiny{};
  int polls = 0;
  while (w.controller.next_deadline() <= w.now && polls < 10) {
    EXPECT_EQ(w.controller.poll(w.now, tiny), 0U);
    ++polls;
  }
  EXPECT_EQ(polls, 1);  // the ACK and the AlarmAck's first send lost; the AlarmAck's timer runs
  EXPECT_EQ(w.controller.rta_counters(AlarmPriority::High).tx_too_small, 2U);
  EXPECT_EQ(w.controller.next_deadline(), w.now + 100ms);
  // With a proper buffer the exchange recovers by retransmission.
  ASSERT_TRUE(w.settle());
  EXPECT_EQ(w.device.counters().acknowledged, 1U);
  EXPECT_EQ(w.recorder.alarms.size(), 1U);
}

}  // namespace
}  // namespace drivegate::profinet::test
