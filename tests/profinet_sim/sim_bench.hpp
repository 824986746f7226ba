#pragma once
// The controller's engines (DcpClient / StationFinder, CmClient, RtProvider / RtConsumer) against a
// PnSimNetwork of simulated devices, in memory on virtual time: every tick the controller side and
// the network are polled, and frames and datagrams are delivered until none is left. An AR plan
// (ArPlan) builds the Connect (expected submodules, both IOCRs with the frame offsets
// compute_csdu_layout gives) and the controller's cyclic engines for it; an AR may have the
// controller's AlarmChannel, which runs with the AR and takes the devices' alarm frames.
#include <chrono>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <span>
#include <vector>

#include "adapters/profinet/controller/alarm_channel.hpp"
#include "adapters/profinet/controller/cm_client.hpp"
#include "adapters/profinet/controller/rt_cyclic.hpp"
#include "adapters/profinet/controller/station_finder.hpp"
#include "adapters/profinet/sim/akd_persona.hpp"
#include "adapters/profinet/sim/generic_io_persona.hpp"
#include "adapters/profinet/sim/pn_sim_network.hpp"

namespace drivegate::profinet::test {

using namespace std::chrono_literals;
using Bytes = std::vector<std::uint8_t>;

inline constexpr MacAddress kControllerMac{0x02, 0x00, 0x00, 0x00, 0x00, 0x01};
inline constexpr std::uint32_t kControllerIp = 0xC0A80001;  // 192.168.0.1
inline constexpr std::uint16_t kControllerClientPort = 0xC001;
inline constexpr std::uint16_t kKollmorgen = 0x0118;       // [sim] vendor ID in the tests
inline constexpr std::uint16_t kAkdDeviceId = 0x0501;

inline MacAddress device_mac(std::uint8_t n) { return {0x00, 0x1B, 0x1B, 0x00, 0x0A, n}; }
inline IpSuite suite(std::uint8_t host) {
  IpSuite s;
  s.address = {192, 168, 0, host};
  s.netmask = {255, 255, 255, 0};
  s.gateway = {192, 168, 0, 1};
  return s;
}
inline std::uint32_t ip_of(std::uint8_t host) { return 0xC0A80000U | host; }

inline PnDeviceConfig device_config(std::uint8_t n, std::string name, IpSuite ip) {
  PnDeviceConfig c;
  c.dcp.mac = device_mac(n);
  c.dcp.type_of_station = "AKD";
  c.dcp.vendor_id = kKollmorgen;
  c.dcp.device_id = kAkdDeviceId;
  c.dcp.name_of_station = std::move(name);
  c.dcp.ip = ip;
  c.activity = {0xA0000000U + n, 0, 0, {1, 2, 3, 4, 5, 6, 7, n}};
  return c;
}

// One submodule of a planned AR.
struct PlanSub {
  std::uint32_t api = 0;
  std::uint16_t slot = 0;
  std::uint32_t module = 0;
  std::uint16_t subslot = 1;
  std::uint32_t ident = 0;
  IoKind kind = IoKind::NoIo;
  std::uint16_t in = 0;   // input octets
  std::uint16_t out = 0;  // output octets
};

// The AKD's submodules with `telegram` in slot 1 (the module idents the persona offers).
inline std::vector<PlanSub> akd_plan(std::uint16_t telegram, std::uint16_t in, std::uint16_t out) {
  return {{0, 0, akd::kDapModule, 1, akd::kDapSubmodule, IoKind::NoIo, 0, 0},
          {akd::kProfidriveApi, 1, akd::telegram_module(telegram), 1, akd::telegram_submodule(telegram),
           IoKind::InputOutput, in, out}};
}

// The Connect and the controller's cyclic engines of one AR.
class ArPlan {
 public:
  ArPlan(std::vector<PlanSub> subs, std::uint32_t device_ip, const MacAddress& device, std::uint16_t n,
         std::uint16_t reduction_ratio = 16, std::uint16_t data_hold = 3)
      : subs_(std::move(subs)) {
    for (const PlanSub& s : subs_) io_.push_back({s.kind, s.in, s.out});
    std::vector<IoPlacement> in_p(subs_.size()), out_p(subs_.size());
    const CsduLayout in_l = compute_csdu_layout(CrDirection::Input, io_, in_p);
    const CsduLayout out_l = compute_csdu_layout(CrDirection::Output, io_, out_p);
    // Expected submodules: one ExpectedSlot per slot.
    for (const PlanSub& s : subs_) {
      ExpectedSubmodule e;
      e.subslot = s.subslot;
      e.ident = s.ident;
      e.properties = static_cast<std::uint16_t>(s.kind);
      e.input = {s.in, 1, 1};
      e.output = {s.out, 1, 1};
      exp_subs_.push_back(std::vector<ExpectedSubmodule>{e});
      expected_.push_back({s.api, s.slot, s.module, 0, exp_subs_.back()});
    }
    // IOCR API lists: per API its data objects and IOCSs.
    std::vector<std::uint32_t> apis;
    for (const PlanSub& s : subs_) {
      if (std::find(apis.begin(), apis.end(), s.api) == apis.end()) apis.push_back(s.api);
    }
    refs_.resize(apis.size() * 4);
    for (std::size_t a = 0; a < apis.size(); ++a) {
      for (std::size_t i = 0; i < subs_.size(); ++i) {
        if (subs_[i].api != apis[a]) continue;
        const IoObjectRef r{subs_[i].slot, subs_[i].subslot, 0};
        auto add = [&](std::size_t list, std::uint16_t at) {
          if (at == kNoOffset) return;
          IoObjectRef x = r;
          x.frame_offset = at;
          refs_[a * 4 + list].push_back(x);
        };
        add(0, in_p[i].data_offset);
        add(1, in_p[i].iocs_offset);
        add(2, out_p[i].data_offset);
        add(3, out_p[i].iocs_offset);
      }
      in_apis_.push_back({apis[a], refs_[a * 4], refs_[a * 4 + 1]});
      out_apis_.push_back({apis[a], refs_[a * 4 + 2], refs_[a * 4 + 3]});
    }
    connect.ar.ar_uuid = {0x11220000U + n, 0x5566, 0x7788, {0x99, 0xAA, 0xBB, 0xCC, 0xDD, 0xEE, 0xFF, static_cast<std::uint8_t>(n)}};
    connect.ar.session_key = 1;
    connect.ar.initiator_mac = kControllerMac;
    connect.ar.initiator_object_uuid = make_pnio_object_uuid({1, 0, kKollmorgen});
    connect.ar.activity_timeout_factor = 600;
    connect.ar.station_name = "drivegate";
    connect.input.reference = 1;
    connect.input.frame_id = static_cast<std::uint16_t>(0xC000 + 2 * n + 1);
    connect.input.reduction_ratio = reduction_ratio;
    connect.input.data_hold_factor = data_hold;
    connect.input.data_length = in_l.length;
    connect.input_apis = in_apis_;
    connect.output.reference = 2;
    connect.output.frame_id = static_cast<std::uint16_t>(0xC000 + 2 * n + 2);
    connect.output.reduction_ratio = reduction_ratio;
    connect.output.data_hold_factor = data_hold;
    connect.output.data_length = out_l.length;
    connect.output_apis = out_apis_;
    connect.expected = expected_;

    config.device = {device_ip, kRpcUdpPort};
    config.device_object = {1, kAkdDeviceId, kKollmorgen};
    config.activity = {0x01020300U + n, 0x0506, 0x0708, {9, 10, 11, 12, 13, 14, 15, static_cast<std::uint8_t>(n)}};
    config.connect = connect;

    RtIocrConfig rt;
    rt.controller_mac = kControllerMac;
    rt.device_mac = device;
    rt.reduction_ratio = reduction_ratio;
    rt.data_hold_factor = data_hold;
    rt.submodules = io_;
    rt.frame_id = connect.output.frame_id;
    provider = std::make_unique<RtProvider>(rt);
    rt.frame_id = connect.input.frame_id;
    consumer = std::make_unique<RtConsumer>(rt);
  }

  // Index of the submodule in (slot, subslot).
  [[nodiscard]] std::size_t index(std::uint16_t slot, std::uint16_t subslot = 1) const {
    for (std::size_t i = 0; i < subs_.size(); ++i) {
      if (subs_[i].slot == slot && subs_[i].subslot == subslot) return i;
    }
    return subs_.size();
  }

  ConnectRequest connect;
  CmClientConfig config;
  std::unique_ptr<RtProvider> provider;
  std::unique_ptr<RtConsumer> consumer;

 private:
  std::vector<PlanSub> subs_;
  std::vector<IoSubmodule> io_;
  std::deque<std::vector<ExpectedSubmodule>> exp_subs_;
  std::vector<ExpectedSlot> expected_;
  std::vector<std::vector<IoObjectRef>> refs_;
  std::vector<IocrApiSpec> in_apis_, out_apis_;
};

// Keeps the last record reply.
class LastReply final : public CmRecordListener {
 public:
  void on_record_reply(const CmRecordReply& r) noexcept override {
    ++count;
    outcome = r.outcome;
    data.assign(r.data.begin(), r.data.end());
    text = std::string(r.text);
  }
  int count = 0;
  CmRecordOutcome outcome = CmRecordOutcome::Done;
  Bytes data;
  std::string text;
};

// A controller with one AR per plan, its DCP client and an optional station finder, on its own
// network of devices or the caller's.
class SimBench final : private PnSimWire {
 public:
  struct Ar {
    ArPlan* plan = nullptr;
    std::unique_ptr<CmClient> cm;
    bool cyclic = false;  // the cyclic engines run (from the Connect response on)
    std::unique_ptr<AlarmChannel> alarms;  // optional: opened and closed with the cyclic engines
  };

  SimBench() : net(own_net_), dcp(kControllerMac) {}
  // The devices of `network` (which must outlive the bench).
  explicit SimBench(PnSimNetwork& network) : net(network), dcp(kControllerMac) {}

  // An AR for `plan` (which must outlive the bench); start() sends its Connect.
  Ar& add_ar(ArPlan& plan) {
    ars.push_back({&plan, std::make_unique<CmClient>(plan.config, &replies), false, nullptr});
    return ars.back();
  }
  void start(Ar& ar) {
    ar.cm->start(now, out_);
    pump();
  }

  // Polls and delivers everything due now.
  void pump() {
    for (int guard = 0; guard < 100; ++guard) {
      bool any = false;
      std::array<std::uint8_t, kMaxFrameSize> buf{};
      while (const std::size_t n = finder ? finder->poll(now, buf) : dcp.poll(now, buf)) {
        any = true;
        to_devices(std::span<const std::uint8_t>(buf).first(n));
      }
      for (Ar& ar : ars) {
        ar.cm->poll(now, out_);
        drive_cyclic(ar);
        while (const std::size_t n = ar.plan->provider->poll(now, buf)) {
          any = true;
          to_devices(std::span<const std::uint8_t>(buf).first(n));
        }
        while (const std::size_t n = ar.alarms ? ar.alarms->poll(now, buf) : 0) {
          any = true;
          to_devices(std::span<const std::uint8_t>(buf).first(n));
        }
        ar.plan->consumer->poll(now);
      }
      any = flush_controller() || any;
      net.poll(now, *this);
      any = deliver_to_controller() || any;
      if (!any) return;
    }
  }
  // Advances the virtual time in `step`s, pumping at each.
  void run_for(core::Duration d, core::Duration step = 1ms) {
    for (core::Duration t{}; t < d; t += step) {
      now += step;
      pump();
    }
  }
  bool run_until(const std::function<bool()>& done, core::Duration limit = 30s, core::Duration step = 1ms) {
    for (core::Duration t{}; t < limit; t += step) {
      if (done()) return true;
      now += step;
      pump();
    }
    return done();
  }

  // Traffic from outside (another station, a fuzzer): to the devices now, their answers to the
  // controller side as usual.
  void inject_frame(std::span<const std::uint8_t> frame) { net.on_frame(frame, now); }
  void inject_datagram(std::span<const std::uint8_t> bytes, const UdpEndpoint& from, const UdpEndpoint& to) {
    (void)net.on_datagram(bytes, from, to, now, *this);
  }

 private:
  PnSimNetwork own_net_;  // the network when the caller names none (made before `net`, which refers to it)

 public:
  PnSimNetwork& net;
  DcpClient dcp;
  std::unique_ptr<StationFinder> finder;
  std::deque<Ar> ars;
  LastReply replies;
  core::TimePoint now{};
  // Frames from the controller to drop (true: lost), for loss tests.
  std::function<bool(std::span<const std::uint8_t>)> drop_to_devices;
  // Sees every frame and datagram the devices send (checks).
  std::function<void(std::span<const std::uint8_t>)> watch_frames;
  std::function<void(const UdpEndpoint& from, std::span<const std::uint8_t>)> watch_datagrams;

 private:
  void send_frame(std::span<const std::uint8_t> frame) noexcept override {
    if (watch_frames) watch_frames(frame);
    frames_.emplace_back(frame.begin(), frame.end());
  }
  void send_datagram(const UdpEndpoint& from, const UdpEndpoint& to, std::span<const std::uint8_t> bytes) noexcept override {
    if (watch_datagrams) watch_datagrams(from, bytes);
    datagrams_.push_back({from, to, Bytes(bytes.begin(), bytes.end())});
  }
  void to_devices(std::span<const std::uint8_t> frame) {
    if (drop_to_devices && drop_to_devices(frame)) return;
    net.on_frame(frame, now);
  }
  // The controller's datagrams to the network.
  bool flush_controller() {
    bool any = false;
    while (!out_.empty()) {
      any = true;
      const CmDatagram& d = out_.front();
      const UdpEndpoint from{kControllerIp, d.from == CmSocket::Server ? kRpcUdpPort : kControllerClientPort};
      const Bytes bytes(d.bytes.begin(), d.bytes.begin() + static_cast<std::ptrdiff_t>(d.size));
      const UdpEndpoint to = d.to;
      out_.pop();
      (void)net.on_datagram(bytes, from, to, now, *this);
    }
    return any;
  }
  bool deliver_to_controller() {
    bool any = !frames_.empty() || !datagrams_.empty();
    while (!frames_.empty()) {
      const Bytes f = std::move(frames_.front());
      frames_.pop_front();
      (void)dcp.on_frame(f, now);
      for (Ar& ar : ars) {
        (void)ar.plan->consumer->on_frame(f, now);
        if (ar.alarms) (void)ar.alarms->on_frame(f, now);
      }
    }
    while (!datagrams_.empty()) {
      const Datagram g = std::move(datagrams_.front());
      datagrams_.pop_front();
      if (g.to.ip != kControllerIp) continue;
      const CmSocket socket = g.to.port == kRpcUdpPort ? CmSocket::Server : CmSocket::Client;
      for (Ar& ar : ars) {
        if (ar.plan->config.device.ip == g.from.ip) ar.cm->on_datagram(g.bytes, g.from, socket, now, out_);
      }
    }
    any = flush_controller() || any;
    return any;
  }
  // The controller's cyclic engines start once the Connect is answered (the AR exists) and
  // stop when it ends.
  void drive_cyclic(Ar& ar) {
    const CmClientState s = ar.cm->state();
    const bool exists = s == CmClientState::Parameterising || s == CmClientState::PrmEnd ||
                        s == CmClientState::WaitApplicationReady || s == CmClientState::DataExchange;
    if (exists && !ar.cyclic) {
      ar.cyclic = true;
      // The controller's application is in RUN: every output good, every input consumed.
      for (std::size_t i = 0; i < ar.plan->provider->placements().size(); ++i) {
        (void)ar.plan->provider->set_iops(i, iox_status::kGood);
      }
      ar.plan->provider->start(now);
      ar.plan->consumer->arm(now);
      if (ar.alarms) ar.alarms->open();
    } else if (!exists && ar.cyclic) {
      ar.cyclic = false;
      ar.plan->provider->stop();
      ar.plan->consumer->disarm();
      if (ar.alarms) ar.alarms->close();
    }
  }

  struct Datagram {
    UdpEndpoint from, to;
    Bytes bytes;
  };
  CmOutbox out_;
  std::deque<Bytes> frames_;
  std::deque<Datagram> datagrams_;
};

}  // namespace drivegate::profinet::test
