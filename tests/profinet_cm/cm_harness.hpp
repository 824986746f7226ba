#pragma once
// A CmClient (controller) and a CmServer (simulated AKD-like device) on an in-memory UDP network
// with virtual time: every datagram either engine puts into its outbox is delivered to the other
// by shuttle(), through an optional filter that may drop, hold or duplicate it. The device model
// and the Connect come from tests/profinet_rpc/scenario.hpp (slot 0 DAP, slot 1 telegram 1 in API
// 3A00h).
#include <array>
#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "adapters/profinet/controller/cm_client.hpp"
#include "adapters/profinet/sim/cm_server.hpp"
#include "adapters/profinet/wire/rpc_calls.hpp"
#include "tests/profinet_rpc/scenario.hpp"

namespace drivegate::profinet::test {

using namespace std::chrono_literals;

inline constexpr std::uint32_t kPlcIp = 0xC0A80001;    // 192.168.0.1
inline constexpr std::uint32_t kDriveIp = 0xC0A80002;  // 192.168.0.2
inline constexpr std::uint16_t kPlcClientPort = 0xC001;
inline constexpr std::uint16_t kDriveClientPort = 0xC002;

// The AKD digest §24 step 8 write: PNU 930 = 2 (position mode) through record 47 on slot 1 (§5.5).
inline constexpr std::array<std::uint8_t, 14> kPnu930{0x05, 0x02, 0x00, 0x01, 0x10, 0x01, 0x03,
                                                      0xA2, 0x00, 0x00, 0x42, 0x01, 0x00, 0x02};
inline constexpr std::uint16_t kDeniedIndex = 0x1000;  // the device refuses writes here (access denied)

struct Packet {
  UdpEndpoint from{};
  UdpEndpoint to{};
  std::vector<std::uint8_t> bytes;
  [[nodiscard]] RpcHeader header() const { return decode_rpc(bytes).header; }
  [[nodiscard]] PacketType type() const { return static_cast<PacketType>(header().packet_type); }
  [[nodiscard]] Opnum opnum() const { return static_cast<Opnum>(header().opnum); }
  [[nodiscard]] bool to_device() const { return to.ip == kDriveIp; }
};

// The simulated device's records: index 47 keeps what was written, I&M0 reads back, kDeniedIndex
// refuses writes.
class DriveApp final : public CmServerApp {
 public:
  PnioStatus on_connect(const CmArSetup&) noexcept override { return {}; }
  PnioStatus on_record_write(const RecordReqHeader& h, std::span<const std::uint8_t> data) noexcept override {
    ++writes;
    if (h.index == kDeniedIndex) return {pnio_error_code::kWrite, pnio_error_decode::kPniorw, pniorw_error::kAccessDenied, 0};
    if (h.index != record_index::kAkdParameterAccess) {
      return {pnio_error_code::kWrite, pnio_error_decode::kPniorw, pniorw_error::kInvalidIndex, 0};
    }
    std::copy(data.begin(), data.end(), record47.begin());
    record47_size = std::min(data.size(), record47.size());
    return {};
  }
  PnioStatus on_record_read(const RecordReqHeader& h, std::span<std::uint8_t> into, std::size_t& length) noexcept override {
    ++reads;
    if (h.index == record_index::kIm0) {
      Im0 im;
      im.vendor_id = kDevice.vendor_id;
      im.order_id = "AKD-P00306-NBPN-0000";
      im.serial_number = "SN0000001";
      im.profile_id = 0x3A00;
      length = encode_im0(im, into);
      return length == 0 ? PnioStatus{pnio_error_code::kRead, pnio_error_decode::kPniorw, pniorw_error::kReadError, 0}
                         : PnioStatus{};
    }
    if (h.index == record_index::kAkdParameterAccess) {
      length = std::min(record47_size, into.size());
      std::copy_n(record47.begin(), length, into.begin());
      return {};
    }
    return {pnio_error_code::kRead, pnio_error_decode::kPniorw, pniorw_error::kInvalidIndex, 0};
  }
  void on_ar_state(CmServerState state, std::string_view) noexcept override { last_state = state; }

  int writes = 0;
  int reads = 0;
  std::array<std::uint8_t, 240> record47{};
  std::size_t record47_size = 0;
  CmServerState last_state = CmServerState::NoAr;
};

// Keeps every reply (copied out of the callback's views) unless `keep` is off: then only counts.
class Replies final : public CmRecordListener {
 public:
  struct Kept {
    CmRecordId id = 0;
    bool write = false;
    CmRecordOutcome outcome = CmRecordOutcome::Done;
    PnioStatus status{};
    std::vector<std::uint8_t> data;
    std::string text;
  };
  void on_record_reply(const CmRecordReply& r) noexcept override {
    ++count;
    last_outcome = r.outcome;
    if (keep) {
      replies.push_back({r.id, r.write, r.outcome, r.status, {r.data.begin(), r.data.end()}, std::string(r.text)});
    }
  }
  // The reply to `id`, or one with id 0 when none came.
  [[nodiscard]] Kept find(CmRecordId id) const {
    for (const Kept& k : replies) {
      if (k.id == id) return k;
    }
    return {};
  }
  [[nodiscard]] int count_of(CmRecordId id) const {
    int n = 0;
    for (const Kept& k : replies) n += k.id == id ? 1 : 0;
    return n;
  }
  bool keep = true;
  int count = 0;
  CmRecordOutcome last_outcome = CmRecordOutcome::Done;
  std::vector<Kept> replies;
};

inline std::array<CmModelSubmodule, 1> kDapSubs{{{1, kDapSubmodule}}};
inline std::array<CmModelSubmodule, 1> kTelegramSubs{{{1, kTelegram1Submodule}}};
inline std::array<CmModelSlot, 2> kDriveModel{{{0, 0, kDapModule, kDapSubs}, {kProfidriveApi, 1, kTelegram1Module, kTelegramSubs}}};

inline CmServerConfig drive_config(std::span<const CmModelSlot> model = kDriveModel) {
  CmServerConfig c;
  c.object = kDevice;
  c.mac = kDeviceMac;
  c.activity = kDeviceActivity;
  c.slots = model;
  return c;
}

struct Bench {
  Scenario scenario;
  std::array<CmRecordWrite, 1> parameters{{{kProfidriveApi, 1, 1, record_index::kAkdParameterAccess, kPnu930}}};
  CmClientConfig config;
  DriveApp app;
  Replies replies;
  std::unique_ptr<CmServer> drive;
  std::unique_ptr<CmClient> plc;
  CmOutbox plc_out;
  CmOutbox drive_out;
  core::TimePoint now{};
  std::vector<Packet> log;       // everything sent, in order (also what the filter dropped)
  bool capture = true;
  // Called for each datagram; returns how many times it is delivered (0 drops it, 2 duplicates).
  std::function<int(const Packet&)> filter;

  explicit Bench(std::span<const CmModelSlot> model = kDriveModel, ByteOrder order = ByteOrder::Little) {
    config.device = {kDriveIp, kRpcUdpPort};
    config.device_object = kDevice;
    config.activity = kActivity;
    config.order = order;
    config.connect = scenario.connect();
    config.parameters = parameters;
    drive = std::make_unique<CmServer>(drive_config(model), app);
    rebuild_client();
  }
  void rebuild_client() { plc = std::make_unique<CmClient>(config, &replies); }

  static UdpEndpoint source(const CmDatagram& d, bool plc) {
    if (plc) return {kPlcIp, d.from == CmSocket::Server ? kRpcUdpPort : kPlcClientPort};
    return {kDriveIp, d.from == CmSocket::Server ? kRpcUdpPort : kDriveClientPort};
  }
  void deliver(const UdpEndpoint& from, const UdpEndpoint& to, std::span<const std::uint8_t> bytes) {
    const CmSocket socket = to.port == kRpcUdpPort ? CmSocket::Server : CmSocket::Client;
    if (to.ip == kDriveIp) {
      drive->on_datagram(bytes, from, socket, now, drive_out);
    } else {
      plc->on_datagram(bytes, from, socket, now, plc_out);
    }
  }
  // Moves datagrams until both outboxes are empty.
  void shuttle() {
    for (int guard = 0; guard < 1000 && (!plc_out.empty() || !drive_out.empty()); ++guard) {
      const bool from_plc = !plc_out.empty();
      CmOutbox& box = from_plc ? plc_out : drive_out;
      const CmDatagram& d = box.front();
      Packet p{source(d, from_plc), d.to, {}};
      if (capture || filter) p.bytes.assign(d.bytes.begin(), d.bytes.begin() + static_cast<std::ptrdiff_t>(d.size));
      const int times = filter ? filter(p) : 1;
      std::array<std::uint8_t, kMaxRpcDatagram> copy{};
      std::copy_n(d.bytes.begin(), d.size, copy.begin());
      const std::size_t size = d.size;
      const UdpEndpoint from = source(d, from_plc);
      const UdpEndpoint to = d.to;
      box.pop();
      if (capture) log.push_back(std::move(p));
      for (int i = 0; i < times; ++i) deliver(from, to, std::span<const std::uint8_t>(copy).first(size));
    }
  }
  void poll() {
    plc->poll(now, plc_out);
    drive->poll(now, drive_out);
    shuttle();
  }
  // Advances the time in steps, polling and shuttling at each.
  void run_for(core::Duration d, core::Duration step = 10ms) {
    for (core::Duration t{}; t < d; t += step) {
      now += step;
      poll();
    }
  }
  void start() {
    plc->start(now, plc_out);
    shuttle();
  }
};

}  // namespace drivegate::profinet::test
