#include "adapters/ethercat/ethercat_bus.hpp"
#include "adapters/ethercat/sim_transport.hpp"

#include <algorithm>
#include <ctime>
#include <map>
#include <thread>

#include "adapters/ethercat/link/ethercat_link.hpp"
#include "adapters/ethercat/wire/al_status.hpp"
#include "core/bytes.hpp"
#include "profiles/cia402/master_settings.hpp"
#include "profiles/cia402/sdo_abort.hpp"
#include "profiles/cia402/statusword.hpp"

namespace drivegate::ethercat {

namespace {

using Phase = EthercatBus::Phase;
using namespace std::chrono_literals;

constexpr std::uint16_t kFirstStation = 0x1001;  // LineBootConfig's default: 1000h + position
// The AL status register block read when a slave left OP: 0130h status, 0132h reserved, 0134h AL
// status code [ETG.1000.4 Table 31].
constexpr std::uint16_t kAlBlock = 6;
// How long the AL status code read of a slave that left OP may take before it is lost anyway.
constexpr core::Duration kLeftOpReadBudget = 100ms;
// After the disable-voltage controlword of a safe stop: cycles of it before SAFE-OP is asked.
constexpr core::Duration kDisableHold = 20ms;
// close(): SAFE-OP, then INIT, each bounded by this much real time.
constexpr core::Duration kCloseBudget = 500ms;
// CiA 402 device profile number in 1000h's low word [CiA 402-2 §6.2; digest "generic profile"].
constexpr std::uint32_t kCia402Profile = 0x0192;

bool claims_emergency(const SlaveAccess& io, std::uint16_t code) noexcept {
  const cia402::ObjectId error_code = cia402::obj::kErrorCode.id;
  return io.mapped(error_code) && static_cast<std::uint16_t>(io.read(error_code)) == code;
}

std::string drive_name(const config::AxisPlan& a) {
  const auto& dev = a.device.section<config::EthercatDeviceSpec>();
  if (!dev.identities.empty() && !dev.identities.front().name.empty()) return dev.identities.front().name;
  return a.device.name;
}

}  // namespace

std::vector<PlannedSlave> planned_slaves(const config::BusPlan& plan) {
  std::map<int, PlannedSlave> at;
  for (const auto& a : plan.axes) {
    if (at.count(a.address) != 0) continue;  // a second axis of a multi-axis slave
    PlannedSlave p;
    p.position = static_cast<std::uint16_t>(a.address - 1);
    p.name = drive_name(a);
    p.axis = &a;
    const auto& dev = a.device.section<config::EthercatDeviceSpec>();
    for (const auto& pdo : dev.rxpdos) p.output_bits += static_cast<std::uint32_t>(pdo.bits());
    for (const auto& pdo : dev.txpdos) p.input_bits += static_cast<std::uint32_t>(pdo.bits());
    at.emplace(a.address, std::move(p));
  }
  for (const auto& io : plan.section<config::EthercatBusOptions>().io) {
    if (at.count(io.position) != 0) continue;  // refused by the configuration check
    PlannedSlave p;
    p.position = static_cast<std::uint16_t>(io.position - 1);
    p.name = io.name;
    p.io = &io;
    p.output_bits = static_cast<std::uint32_t>(io.output_bytes.value_or(0)) * 8U;
    p.input_bits = static_cast<std::uint32_t>(io.input_bytes.value_or(0)) * 8U;
    at.emplace(io.position, std::move(p));
  }
  std::vector<PlannedSlave> out;
  int expect = 1;
  for (auto& [position, p] : at) {
    if (position != expect)
      throw core::BusError("bus '" + plan.name + "': position " + std::to_string(expect) +
                           " has neither an axis nor an io: entry; list every slave up to the last configured one (the "
                           "frame passes them all, and each must be known to be started)");
    ++expect;
    out.push_back(std::move(p));
  }
  if (out.size() > LineBoot::kMaxSlaves)
    throw core::BusError("bus '" + plan.name + "': " + std::to_string(out.size()) + " slaves, at most " +
                         std::to_string(LineBoot::kMaxSlaves) + " are supported");
  return out;
}

ImageSlave planned_image_slave(const PlannedSlave& s) {
  ImageSlave i;
  i.station = static_cast<std::uint16_t>(kFirstStation + s.position);
  i.output_bytes = bytes_of_bits(s.output_bits);
  i.input_bytes = bytes_of_bits(s.input_bits);
  // No SII known: SM2 at the start of the process RAM, SM3 after SM2's three buffers (the
  // defaults image_slave_from_sii() takes for a slave without a mailbox) [ETG.1000.4 §6 buffered
  // SyncManager].
  i.sm3.start = static_cast<std::uint16_t>(i.sm2.start + 3U * i.output_bytes);
  return i;
}

ImageOptions bus_image_options() {
  ImageOptions o;
  // One datagram per slave: each has its own working counter, and a missing slave leaves the
  // others' inputs coming (a whole-image LRW would be short for everyone).
  o.datagrams = CyclicDatagrams::PerSlave;
  // Besides: CyclicExchange's AL status check (2 bytes) and the slot DC's FRMW of the system time
  // (8 bytes) takes first in the frame (master/dc.hpp).
  o.extra_datagrams = 2;
  o.extra_data_bytes = 2 + 8;
  return o;
}

EthercatBus::EthercatBus(const config::BusPlan& plan, std::unique_ptr<Link> link, std::unique_ptr<CyclePeer> peer)
    : name_(plan.name),
      options_(plan.section<config::EthercatBusOptions>()),
      cycle_time_(plan.cycle_time),
      link_(std::move(link)),
      peer_(std::move(peer)) {
  for (auto& p : planned_slaves(plan)) {
    auto s = std::make_unique<Slave>();
    s->plan = std::move(p);
    s->station = static_cast<std::uint16_t>(kFirstStation + s->plan.position);
    if (const config::AxisPlan* a = s->plan.axis) {
      const auto& dev = a->device.section<config::EthercatDeviceSpec>();
      for (const auto& id : dev.identities)
        s->identities.push_back(SiiIdentity{id.vendor_id, id.product_code, id.revision.value_or(0), 0});
      s->any_identity = dev.identities.empty();
      std::size_t n = 0;
      for (const auto& pdo : dev.rxpdos) n += pdo.entries.size();
      for (const auto& pdo : dev.txpdos) n += pdo.entries.size();
      s->entries.reserve(n);  // the PdoConfig spans point into it
      const auto add = [&](const std::vector<config::EthercatPdoSpec>& pdos, std::vector<PdoConfig>& out) {
        for (const auto& pdo : pdos) {
          const std::size_t first = s->entries.size();
          for (const auto& e : pdo.entries) s->entries.push_back(PdoEntryConfig{e.object.index, e.object.sub, e.bits});
          out.push_back(PdoConfig{pdo.index, std::span<const PdoEntryConfig>(s->entries.data() + first, pdo.entries.size())});
        }
      };
      add(dev.rxpdos, s->rx);
      add(dev.txpdos, s->tx);
      for (const auto& w : dev.startup_writes)
        s->startup.push_back(CoeStartupWrite{w.def.id.index, w.def.id.sub, static_cast<std::uint32_t>(w.value & 0xFFFFFFFF),
                                             cia402::size_of(w.def.type)});
      for (const auto& o : dev.ignored_writes) s->ignored.push_back(CoeObjectId{o.index, o.sub});
      s->dict = std::make_unique<SlaveDictionary>(static_cast<std::uint16_t>(s->plan.position + 1));
    } else if (const config::EthercatIoSlave* io = s->plan.io) {
      if (io->vendor_id && io->product_code)
        s->identities.push_back(SiiIdentity{*io->vendor_id, *io->product_code, 0, 0});
      s->any_identity = s->identities.empty();
    }
    const SiiIdentity first = s->identities.empty() ? SiiIdentity{} : s->identities.front();
    expected_.push_back(ExpectedSlave{first.vendor_id, first.product_code, first.revision, s->plan.name});
    if (s->plan.io != nullptr) io_.add(slaves_.size(), s->plan);
    slaves_.push_back(std::move(s));
  }
  LineBootConfig lb;
  lb.first_station = kFirstStation;
  lb.preop_to_safeop = options_.transition_timeout;
  lb.safeop_to_op = options_.transition_timeout;
  boot_ = std::make_unique<LineBoot>(expected_, lb);
  {
    // Distributed clocks: the drives whose profile asks for them, on a bus that runs them.
    std::array<std::uint16_t, LineBoot::kMaxSlaves> stations{};
    std::array<bool, LineBoot::kMaxSlaves> wanted{};
    const std::size_t n = std::min(slaves_.size(), stations.size());
    for (std::size_t k = 0; k < n; ++k) {
      stations[k] = slaves_[k]->station;
      const config::AxisPlan* a = slaves_[k]->plan.axis;
      wanted[k] = a != nullptr && a->device.section<config::EthercatDeviceSpec>().distributed_clocks;
    }
    BusDcConfig dc;
    dc.enabled = options_.distributed_clocks;
    dc.cycle_ns = static_cast<std::uint32_t>(std::chrono::duration_cast<std::chrono::nanoseconds>(cycle_time_).count());
    dc.shift_ns = static_cast<std::int32_t>(std::chrono::duration_cast<std::chrono::nanoseconds>(options_.sync0_shift).count());
    // A 092Ch round about once a second.
    dc.difference_every = static_cast<std::uint32_t>(std::max<std::int64_t>(1, std::chrono::seconds(1) / cycle_time_));
    dc_ = std::make_unique<BusDc>(tx_, std::span<const std::uint16_t>(stations.data(), n),
                                  std::span<const bool>(wanted.data(), n), dc);
  }
  for (std::size_t k = 0; k < slaves_.size(); ++k) {
    const auto& ids = slaves_[k]->identities;
    boot_->accept_identities(k, ids.empty() ? std::span<const SiiIdentity>{} : std::span<const SiiIdentity>(ids).subspan(1),
                             slaves_[k]->any_identity);
  }
  for (const auto& a : plan.axes) {
    const std::size_t k = static_cast<std::size_t>(a.address - 1);
    Slave& s = *slaves_[k];
    const auto& dev = a.device.section<config::EthercatDeviceSpec>();
    Axis x;
    x.slave = k;
    x.names = DictionaryAxis{a.section<config::EthercatAxisSpec>().slave_axis, dev.axes, dev.axis_offset};
    for (const auto& [code, text] : a.device.fault_texts) x.faults.push_back({static_cast<std::uint16_t>(code), text});
    std::vector<MappedObject> objects;
    std::uint32_t bits = 0;
    for (const auto& pdo : dev.rxpdos)
      for (const auto& e : pdo.entries) {
        if (e.object.index != 0) objects.push_back(MappedObject{e.object, e.type, true, static_cast<std::uint16_t>(bits / 8)});
        bits += e.bits;
      }
    bits = 0;
    for (const auto& pdo : dev.txpdos)
      for (const auto& e : pdo.entries) {
        if (e.object.index != 0) objects.push_back(MappedObject{e.object, e.type, false, static_cast<std::uint16_t>(bits / 8)});
        bits += e.bits;
      }
    std::vector<EcatOwnedObject> owned;
    for (const auto& w : dev.startup_writes)
      owned.push_back({w.def.id, "set by the EtherCAT bus at every start (start-up write: " + w.why + ")"});
    const int slave_axis = a.section<config::EthercatAxisSpec>().slave_axis;
    x.io = std::make_unique<SlaveAccess>(k, std::move(objects), slave_axis, dev.axis_offset, nullptr, std::move(owned),
                                         std::span<const cia402::FaultText>{});
    s.axes.push_back(axes_.size());
    axes_.push_back(std::move(x));
  }
  // The fault tables are final now (axes_ does not grow any more): hand out their views.
  for (std::size_t i = 0; i < axes_.size(); ++i) {
    Axis& x = axes_[i];
    x.io->set_faults(x.faults);
    cia402::MasterSettings settings = cia402::settings_from(plan.axes[i].spec);
    settings.pp_bit6_absolute = plan.axes[i].device.quirk("pp_bit6_absolute");
    x.master = std::make_unique<cia402::Cia402Master>(*x.io, settings);
    x.master->set_fault_table(x.faults);
  }
}

EthercatBus::~EthercatBus() {
  for (auto& s : slaves_) {
    tx_.forget(&s->setup);
    if (s->coe) tx_.forget(&*s->coe);
  }
  if (boot_) tx_.forget(boot_.get());
  if (cx_) tx_.forget(&*cx_);
  if (dc_) dc_->forget_all();
}

void EthercatBus::open(core::TimePoint now) {
  try {
    link_->open();
  } catch (const LinkError& e) {
    throw core::BusError("bus '" + name_ + "': " + e.what());
  }
  open_ = true;
  last_now_ = now;
  // The DC system time base: CLOCK_REALTIME read once here against the bus' `now` (the daemon's
  // cycle clock is steady_clock, CLOCK_MONOTONIC): master_system_time(now) is then ns since 2000
  // [ETG.1000.4 §6 DC system time]. The engines read no clock.
  timespec rt{};
  ::clock_gettime(CLOCK_REALTIME, &rt);
  dc_->set_base(system_time_base(static_cast<std::int64_t>(rt.tv_sec) * 1'000'000'000 + rt.tv_nsec, core::to_ns(now)));
  link_seen_ = link_->poll_state(now);
  for (auto& s : slaves_) {
    set_detail(*s, "booting");
    enter(*s, Phase::Boot, now);
  }
  start_boot(now);
}

void EthercatBus::start_boot(core::TimePoint now) noexcept {
  for (auto& s : slaves_) {
    if (s->coe) s->coe->reset();
    if (s->dict) s->dict->stop(s->coe ? &*s->coe : nullptr);
    for (std::size_t a : s->axes) axes_[a].io->forget_requests();
    enter(*s, Phase::Boot, now);
  }
  dc_->restart_line();
  boot_->start(now);
  line_booting_ = true;
  line_backoff_ = false;
}

void EthercatBus::set_detail(Slave& s, const char* what) noexcept {
  s.detail.format("slave %u (0x%04X, %s): %s", s.plan.position + 1U, s.station, s.plan.name.c_str(), what);
}

void EthercatBus::enter(Slave& s, Phase p, core::TimePoint now) noexcept {
  s.phase = p;
  s.since = now;
  // A slave that restarts (or is lost: it may come back from a power cycle with its DC registers
  // zero) gets its distributed clocks again.
  if (p == Phase::Restart || p == Phase::Lost) dc_->forget(s.plan.position);
  core::LinkState link = core::LinkState::Offline;
  switch (p) {
    case Phase::Boot: link = core::LinkState::Booting; break;
    case Phase::Restart: link = s.had_op ? core::LinkState::Lost : core::LinkState::Booting; break;
    case Phase::DeviceType:
    case Phase::Configure:
    case Phase::Sync:
    case Phase::SafeOp:
    case Phase::ToOp: link = core::LinkState::Configuring; break;
    // LeftOp: the cycle its AL status code is read in; the link goes Lost with the sentence after.
    case Phase::Op:
    case Phase::LeftOp: link = core::LinkState::Operational; break;
    case Phase::Lost: link = s.had_op ? core::LinkState::Lost : core::LinkState::Offline; break;
    case Phase::SafeStop: link = core::LinkState::Degraded; break;
  }
  s.link.store(link, std::memory_order_relaxed);
}

core::LinkState EthercatBus::link_state(std::size_t axis) const noexcept {
  return slaves_[axes_[axis].slave]->link.load(std::memory_order_relaxed);
}

std::string_view EthercatBus::link_detail(std::size_t axis) const noexcept {
  return slaves_[axes_[axis].slave]->detail.view();
}

void EthercatBus::push_event(const core::Event& e) noexcept { (void)events_.push(e); }

void EthercatBus::bus_event(core::EventKind kind, std::string_view text) noexcept {
  core::Event e;
  e.kind = kind;
  e.text.format("bus %s: %.*s", name_.c_str(), static_cast<int>(text.size()), text.data());
  push_event(e);
}

bool EthercatBus::next_event(core::Event& out) noexcept { return events_.pop(out); }

void EthercatBus::on_emergency(std::uint16_t station, const CoeEmergency& e) noexcept {
  if (station < kFirstStation || static_cast<std::size_t>(station - kFirstStation) >= slaves_.size()) return;
  Slave& s = *slaves_[station - kFirstStation];
  // A CoE emergency names no axis [ETG.1000.6 §5.6.4: error code, register, 5 bytes]. On a
  // multi-axis slave it goes to the axes whose error code (603Fh + n x axis_offset, in the inputs
  // the same cycle the drive raised it) says it; to every axis when none does (603Fh not mapped).
  bool claimed = false;
  if (s.axes.size() > 1)
    for (std::size_t a : s.axes) claimed = claimed || claims_emergency(*axes_[a].io, e.error_code);
  for (std::size_t a : s.axes) {
    if (claimed && !claims_emergency(*axes_[a].io, e.error_code)) continue;
    axes_[a].io->on_emergency(e);
    core::Event ev;
    ev.axis = static_cast<core::AxisIndex>(a);
    ev.kind = core::EventKind::Emcy;
    ev.code = e.error_code;
    const std::string_view text = cia402::error_code_text(e.error_code, axes_[a].faults);
    ev.text.format("EMCY 0x%04X (error register 0x%02X, data %02X %02X %02X %02X %02X): %.*s", e.error_code,
                   e.error_register, e.data[0], e.data[1], e.data[2], e.data[3], e.data[4],
                   static_cast<int>(text.size()), text.data());
    push_event(ev);
  }
}

// --- Cyclic path --------------------------------------------------------------------------------

void EthercatBus::receive(core::TimePoint now) noexcept {
  if (!open_) return;
  last_now_ = now;
  if (peer_) peer_->step(now);
  for (;;) {
    const std::size_t got = link_->receive(rx_);
    for (std::size_t i = 0; i < got; ++i) tx_.on_frame(rx_[i].view());
    if (got < rx_.size()) break;
  }
  tx_.expire(now);
  handle_link(now);
  if (line_booting_ && boot_->status() != LineStatus::Running) {
    boot_done(now);
  } else if (line_backoff_ && now - line_since_ >= line_wait_ && link_seen_ == LinkState::Up) {
    start_boot(now);
  }
  dc_step(now);
  for (std::size_t k = 0; k < slaves_.size(); ++k) advance(k, now);
  const std::uint64_t completed = cx_ ? cx_->last_completed_cycle() : 0;
  for (auto& x : axes_) {
    const bool op = slaves_[x.slave]->phase == Phase::Op;
    x.io->begin_cycle(op, op && completed != 0 && cx_->inputs_cycle(x.slave) == completed);
  }
}

void EthercatBus::transmit(core::TimePoint now) noexcept {
  if (!open_) return;
  // The frame: DC's datagram first (its slot), the process data, then the acyclic traffic.
  queue_dc(now);
  if (cx_ && image_.ok()) cx_->queue(tx_);
  boot_->poll(now, tx_);
  for (auto& s : slaves_) {
    if (s->coe) s->coe->poll(now, tx_);
    if (s->phase == Phase::Configure) s->setup.poll(now, tx_);
  }
  dc_->poll(now, tx_);  // the DC set-up's datagrams, after the process data
  const auto frames = tx_.take_frames(now + cycle_time_);
  if (!frames.empty()) {
    const SendResult r = link_->send(frames);
    tx_unsent_ += r.unsent + r.invalid;
  }
  publish_counters();
}

void EthercatBus::queue_dc(core::TimePoint now) noexcept {
  // DcCyclic's FRMW of the reference clock's system time, first in the cycle's frame (its slot in
  // bus_image_options()) [ETG.1000.4 §5.4 FRMW, master/dc.hpp].
  dc_->poll_cyclic(now, tx_);
}

void EthercatBus::dc_step(core::TimePoint now) noexcept {
  std::array<BusDcView, LineBoot::kMaxSlaves> views{};
  const std::size_t n = std::min(slaves_.size(), views.size());
  for (std::size_t k = 0; k < n; ++k) {
    const Phase p = slaves_[k]->phase;
    BusDcView& v = views[k];
    v.present = !line_booting_ && k < boot_->slave_count() && p != Phase::Lost && p != Phase::Restart && p != Phase::Boot;
    v.at_sync = p == Phase::Sync;
    v.configuring = p == Phase::Boot || p == Phase::Restart || p == Phase::DeviceType || p == Phase::Configure;
    v.running = p == Phase::SafeOp || p == Phase::ToOp || p == Phase::Op || p == Phase::LeftOp || p == Phase::SafeStop;
  }
  dc_->step(now, std::span<const BusDcView>(views.data(), n));
  core::FixedString<240> text;
  bool warning = false;
  while (dc_->take_event(text, warning)) bus_event(warning ? core::EventKind::Warning : core::EventKind::Info, text.view());
  const DcCyclic& c = dc_->cyclic();
  // A line whose only DC slave is the reference clock has no 092Ch to read: nothing differs (0)
  // once the reference's time comes back.
  std::int64_t difference = -1;
  if (c.configured() && c.difference_valid()) {
    difference = static_cast<std::int64_t>(c.max_abs_difference_ns());
  } else if (c.configured() && c.station_count() == 0 && c.has_reference_time()) {
    difference = 0;
  }
  dc_difference_.store(difference, std::memory_order_relaxed);
  dc_master_offset_.store(c.configured() && c.has_reference_time() ? c.master_minus_reference_ns() : 0,
                          std::memory_order_relaxed);
}

bool EthercatBus::dc_ready(std::size_t k, core::TimePoint now) noexcept {
  Slave& s = *slaves_[k];
  if (!dc_->wanted(k)) return true;
  switch (dc_->verdict(k)) {
    case BusDc::Verdict::Wait: return false;
    case BusDc::Verdict::Free: return true;
    case BusDc::Verdict::Failed:
      s.detail.assign(dc_->text(k));
      fail(k, now);
      return false;
    case BusDc::Verdict::Sync0: break;
  }
  if (s.sync_mode_done || !s.coe) return true;
  // SYNC0 runs: the drive's SM2 synchronisation to DC SYNC0, 1C32h:01 = 2, in PRE-OP (a drive
  // checks it at SAFE-OP -> OP: AL status code 0030h otherwise) [ETG.1020 synchronisation; the
  // generic-cia402 persona's 1C32h]. A drive without 1C32h takes SYNC0 as it is.
  constexpr std::uint32_t kSyncDc0 = 2;
  if (s.sync_mode_sdo == 0) {
    s.sync_mode_sdo = s.coe->download_value(0x1C32, 1, kSyncDc0, 2);
    if (s.sync_mode_sdo != 0) set_detail(s, "SYNC0 running: 1C32h:01 = 2 (DC SYNC0)");
    return false;
  }
  const CoeSdoResult r = s.coe->result(s.sync_mode_sdo);
  if (r.status == CoeSdoStatus::Queued || r.status == CoeSdoStatus::InFlight) return false;
  if (r.status != CoeSdoStatus::Unknown) s.coe->take(s.sync_mode_sdo);
  s.sync_mode_sdo = 0;
  if (r.status == CoeSdoStatus::Done || r.abort_code == cia402::sdo_abort_code::kNoObject ||
      r.abort_code == cia402::sdo_abort_code::kNoSubIndex) {
    s.sync_mode_done = true;
    return true;
  }
  core::FixedString<160> why;
  why.format("1C32h:01 = 2 (DC SYNC0) refused: %s", cia402::sdo_abort_text(r.abort_code).data());
  set_detail(s, why.c_str());
  fail(k, now);
  return false;
}

void EthercatBus::handle_link(core::TimePoint now) noexcept {
  const LinkState ls = link_->poll_state(now);
  if (ls == link_seen_) return;
  const bool was_up = link_seen_ == LinkState::Up;
  link_seen_ = ls;
  if (ls != LinkState::Up && was_up) {
    for (std::size_t k = 0; k < slaves_.size(); ++k) {
      Slave& s = *slaves_[k];
      s.detail.format("the Ethernet link is down (%s)", to_string(ls));
      if (s.phase != Phase::Lost) lose(k, now);
    }
    return;
  }
  if (ls == LinkState::Up) {
    // Back: every slave is probed and configured again (its back-off starts over).
    for (auto& s : slaves_) {
      s->detail.assign("the Ethernet link is up again: checking the slave");
      s->backoff = core::Duration::zero();
    }
  }
}

bool EthercatBus::all_op() const noexcept {
  return std::all_of(slaves_.begin(), slaves_.end(), [](const auto& s) { return s->phase == Phase::Op; });
}

void EthercatBus::publish_counters() noexcept {
  const TransactionCounters& t = tx_.counters();
  sent_.store(t.frames_sent, std::memory_order_relaxed);
  received_.store(t.frames_returned, std::memory_order_relaxed);
  lost_.store(t.frames_lost, std::memory_order_relaxed);
  dropped_.store(t.foreign + t.malformed + t.mismatched + tx_unsent_, std::memory_order_relaxed);
  if (cx_) {
    // Working counter errors once the line was up: before, every configuring slave would count.
    const std::uint64_t w = cx_->counters().wkc_errors;
    if (counting_errors_ || all_op()) {
      counting_errors_ = true;
      wkc_errors_ += w - wkc_seen_;
    }
    wkc_seen_ = w;
  }
  errors_.store(wkc_errors_, std::memory_order_relaxed);
}

core::BusCounters EthercatBus::counters() const noexcept {
  core::BusCounters c;
  c.frames_sent = sent_.load(std::memory_order_relaxed);
  c.frames_received = received_.load(std::memory_order_relaxed);
  c.frames_lost = lost_.load(std::memory_order_relaxed);
  c.frames_dropped = dropped_.load(std::memory_order_relaxed);
  c.errors = errors_.load(std::memory_order_relaxed);
  return c;
}

// --- Life cycle ---------------------------------------------------------------------------------

void EthercatBus::boot_done(core::TimePoint now) noexcept {
  line_booting_ = false;
  if (boot_->status() == LineStatus::Failed) {
    const std::string_view why = boot_->line_text();
    for (auto& s : slaves_) {
      s->detail.format("line start-up failed: %.*s", static_cast<int>(why.size()), why.data());
      enter(*s, Phase::Lost, now);
    }
    bus_event(core::EventKind::Warning, slaves_.empty() ? why : slaves_.front()->detail.view());
    line_wait_ = line_wait_ == core::Duration::zero() ? options_.boot_retry
                                                      : std::min(line_wait_ * 2, options_.boot_retry_max);
    line_backoff_ = true;
    line_since_ = now;
    return;
  }
  line_wait_ = core::Duration::zero();
  for (std::size_t k = slaves_.size(); k < boot_->slave_count(); ++k)
    bus_event(core::EventKind::Warning, boot_->slave(k).text.view());
  if (boot_->missing() > 0) bus_event(core::EventKind::Warning, boot_->line_text());
  // The image, once for every configured slave: from the SII where the boot read it, else the
  // defaults (its SM entries are corrected when the slave turns up; the offsets do not move).
  for (std::size_t k = 0; k < slaves_.size(); ++k) {
    Slave& s = *slaves_[k];
    const bool known = k < boot_->slave_count() && boot_->slave(k).status == SlaveStatus::Ready;
    if (known && s.plan.io != nullptr && !image_.ok()) {
      // An I/O slave whose sizes the plan leaves open: its SII's process data SMs say them
      // [ETG.1000.6 §5.4 SyncM category]. Only at the first layout: the offsets never move.
      const SiiInfo& sii = boot_->sii(k);
      for (std::size_t i = 0; i < sii.sync_manager_count; ++i) {
        const SiiSyncManager& sm = sii.sync_managers[i];
        if (sm.type == sii_sm_type::kOutputs && !s.plan.io->output_bytes) s.plan.output_bits = sm.length * 8U;
        if (sm.type == sii_sm_type::kInputs && !s.plan.io->input_bytes) s.plan.input_bits = sm.length * 8U;
      }
    }
    image_slaves_[k] = known ? image_slave_from_sii(boot_->sii(k), s.station, s.plan.output_bits, s.plan.input_bits)
                             : planned_image_slave(s.plan);
    s.image_from_sii = known;
  }
  if (!image_.build(std::span<const ImageSlave>(image_slaves_.data(), slaves_.size()), bus_image_options())) {
    for (auto& s : slaves_) {
      s->detail.format("process image refused: %.*s", static_cast<int>(image_.text().size()), image_.text().data());
      enter(*s, Phase::Lost, now);
      s->backoff = options_.boot_retry_max;
    }
    bus_event(core::EventKind::Warning, slaves_.front()->detail.view());
    return;
  }
  if (!cx_) {
    cx_.emplace(image_, CyclicOptions{true});
    for (auto& x : axes_) x.io->attach(&*cx_);
  }
  for (std::size_t k = 0; k < slaves_.size(); ++k) {
    Slave& s = *slaves_[k];
    if (k < boot_->slave_count()) {
      const SlaveReport& r = boot_->slave(k);
      if (r.status == SlaveStatus::Ready) {
        configure(k, now);
        continue;
      }
      s.detail.assign(r.text.view());
      if (r.identity_mismatch()) bus_event(core::EventKind::Warning, r.text.view());
    } else {
      set_detail(s, "not found on the line");
    }
    fail(k, now);
  }
}

void EthercatBus::configure(std::size_t k, core::TimePoint now) noexcept {
  Slave& s = *slaves_[k];
  if (!s.image_from_sii) {
    // The slave was missing when the image was laid out: its SMs as its SII gives them.
    image_slaves_[k] = image_slave_from_sii(boot_->sii(k), s.station, s.plan.output_bits, s.plan.input_bits);
    if (!image_.build(std::span<const ImageSlave>(image_slaves_.data(), slaves_.size()), bus_image_options())) {
      s.detail.format("process image refused: %.*s", static_cast<int>(image_.text().size()), image_.text().data());
      fail(k, now);
      return;
    }
    s.image_from_sii = true;
  }
  const SiiMailbox& mb = boot_->sii(k).header.standard_mailbox;
  if (mb.present()) {
    if (s.coe) {
      s.coe->reset();
    } else {
      EmergencySink* sink = this;
      s.coe.emplace(s.station, mb, CoeSdoTiming{options_.sdo_timeout, std::chrono::milliseconds(1)}, sink);
    }
  }
  if (s.dict) s.dict->stop(s.coe ? &*s.coe : nullptr);
  for (std::size_t a : s.axes) {
    axes_[a].io->set_coe(s.coe ? &*s.coe : nullptr);
    axes_[a].io->forget_requests();
    axes_[a].io->override_controlword(false);
  }
  // SAFE-OP comes with the cyclic frame running: outputs zero (controlword 0: the drive stays
  // disabled) until the profile writes them in OP [digest step 7].
  if (cx_) std::fill(cx_->outputs(k).begin(), cx_->outputs(k).end(), std::uint8_t{0});
  if (s.any_identity && s.plan.axis != nullptr && s.coe) {
    s.probe = s.coe->upload_value(0x1000, 0);
    enter(s, Phase::DeviceType, now);
    return;
  }
  start_setup(k, now);
}

void EthercatBus::start_setup(std::size_t k, core::TimePoint now) noexcept {
  Slave& s = *slaves_[k];
  PdoSetupConfig cfg;
  cfg.position = s.plan.position;
  cfg.startup_writes = s.startup;
  cfg.ignored_writes = s.ignored;
  cfg.map_pdos = s.plan.axis != nullptr && s.coe.has_value();
  cfg.rx_pdos = s.rx;
  cfg.tx_pdos = s.tx;
  cfg.sm_watchdog = options_.sm_watchdog;
  if (!s.setup.start(s.coe ? &*s.coe : nullptr, cfg, image_.slave(k), now)) {
    s.detail.assign(s.setup.text());
    fail(k, now);
    return;
  }
  set_detail(s, "configuring it (PDO mapping, SyncManagers, FMMUs)");
  enter(s, Phase::Configure, now);
}

void EthercatBus::lose(std::size_t k, core::TimePoint now) noexcept {
  Slave& s = *slaves_[k];
  for (std::size_t a : s.axes) {
    axes_[a].io->forget_requests();
    axes_[a].io->override_controlword(false);
  }
  if (s.coe) s.coe->reset();
  if (s.dict) s.dict->stop(s.coe ? &*s.coe : nullptr);
  s.missing = 0;
  s.left_op_waiting = false;
  enter(s, Phase::Lost, now);
}

void EthercatBus::fail(std::size_t k, core::TimePoint now) noexcept {
  Slave& s = *slaves_[k];
  s.backoff = s.backoff == core::Duration::zero() ? options_.boot_retry : std::min(s.backoff * 2, options_.boot_retry_max);
  lose(k, now);
}

void EthercatBus::advance(std::size_t k, core::TimePoint now) noexcept {
  Slave& s = *slaves_[k];
  switch (s.phase) {
    case Phase::Boot: break;  // boot_done() moves it on
    case Phase::Restart: {
      const SlaveReport& r = boot_->slave(k);
      if (r.status == SlaveStatus::Busy) break;
      if (r.status == SlaveStatus::Ready && r.state == AlState::PreOp) {
        ++s.restarts;
        set_detail(s, "answered again, identity checked: configuring it");
        configure(k, now);
        break;
      }
      s.detail.assign(r.text.view());
      if (r.identity_mismatch()) bus_event(core::EventKind::Warning, r.text.view());
      fail(k, now);
      break;
    }
    case Phase::DeviceType: {
      const CoeSdoResult r = s.coe->result(s.probe);
      if (r.status == CoeSdoStatus::Queued || r.status == CoeSdoStatus::InFlight) break;
      if (r.status != CoeSdoStatus::Unknown) s.coe->take(s.probe);
      s.probe = 0;
      if (r.status != CoeSdoStatus::Done) {
        core::FixedString<120> why;
        why.format("1000h (device type) read failed: %s", cia402::sdo_abort_text(r.abort_code).data());
        set_detail(s, why.c_str());
        fail(k, now);
      } else if ((r.value & 0xFFFF) != kCia402Profile) {
        core::FixedString<120> why;
        why.format("1000h reads 0x%08X: not a CiA 402 drive (profile 0192h), refused by a profile without identities",
                   r.value);
        set_detail(s, why.c_str());
        bus_event(core::EventKind::Warning, s.detail.view());
        fail(k, now);
      } else {
        start_setup(k, now);
      }
      break;
    }
    case Phase::Configure:
      switch (s.setup.status()) {
        case PdoSetupStatus::Done:
          for (std::size_t i = 0; i < s.setup.warning_count(); ++i)
            bus_event(core::EventKind::Warning, s.setup.warning(i));
          s.sync_mode_sdo = 0;
          s.sync_mode_done = false;
          if (dc_->wanted(k)) set_detail(s, "setting up distributed clocks (SYNC0)");
          enter(s, Phase::Sync, now);
          break;
        case PdoSetupStatus::Failed:
          s.detail.assign(s.setup.text());
          fail(k, now);
          break;
        default: break;
      }
      break;
    case Phase::Sync:
      if (!dc_ready(k, now)) break;
      if (boot_->request_state(k, AlState::SafeOp, now)) {
        set_detail(s, "PRE-OP -> SAFE-OP");
        enter(s, Phase::SafeOp, now);
      } else {
        set_detail(s, "SAFE-OP could not be requested");
        fail(k, now);
      }
      break;
    case Phase::SafeOp:
    case Phase::ToOp: {
      const SlaveReport& r = boot_->slave(k);
      if (r.status == SlaveStatus::Busy) break;
      const AlState want = s.phase == Phase::SafeOp ? AlState::SafeOp : AlState::Op;
      if (r.status != SlaveStatus::Ready || r.state != want) {
        s.detail.assign(r.text.view());
        if (s.detail.view().empty()) set_detail(s, "did not reach the state asked for");
        fail(k, now);
        break;
      }
      if (want == AlState::SafeOp) {
        if (boot_->request_state(k, AlState::Op, now)) {
          set_detail(s, "SAFE-OP -> OP");
          enter(s, Phase::ToOp, now);
        } else {
          set_detail(s, "OP could not be requested");
          fail(k, now);
        }
        break;
      }
      s.had_op = true;
      s.missing = 0;
      s.backoff = core::Duration::zero();
      s.op_cycle = cx_ ? cx_->counters().cycles : 0;
      s.dict_due = s.dict != nullptr;
      set_detail(s, "in OP");
      enter(s, Phase::Op, now);
      break;
    }
    case Phase::Op: {
      for (std::size_t a : s.axes) {
        if (core::FixedString<200> why; axes_[a].io->take_control_lost(why)) {
          s.detail = why;
          s.safe_step = 0;
          enter(s, Phase::SafeStop, now);
          run_safe_stop(k, now);
          return;
        }
      }
      read_names(k);
      if (!cx_) break;
      switch (cx_->answered(k)) {
        case SlaveAnswer::Missing:
          if (++s.missing >= options_.lost_cycles) {
            core::FixedString<60> why;
            why.format("no answer for %d cycles", s.missing);
            set_detail(s, why.c_str());
            lose(k, now);
            return;
          }
          break;
        case SlaveAnswer::Answered: s.missing = 0; break;
        case SlaveAnswer::Unknown: break;
      }
      // Its AL status (CyclicExchange's round-robin check) left OP: an SM watchdog, a local
      // error, another master. Read the AL status code for the sentence [ETG.1000.6 §5.3.2].
      const SlaveAlCheck& c = cx_->al_check(k);
      const AlStatus st = c.status();
      if (c.cycle > s.op_cycle && c.answered && (st.error || st.state() != AlState::Op)) {
        s.left_op_seq = static_cast<std::uint16_t>(s.left_op_seq + 1);
        s.left_op_waiting = tx_.queue(this, (static_cast<std::uint32_t>(k) << 16) | s.left_op_seq, Command::FPRD,
                                      physical_address(s.station, reg::kAlStatus), kAlBlock);
        enter(s, Phase::LeftOp, now);
        if (!s.left_op_waiting) {
          set_detail(s, "left OP");
          lose(k, now);
        }
      }
      break;
    }
    case Phase::LeftOp:
      if (now - s.since >= kLeftOpReadBudget) {
        set_detail(s, "left OP (its AL status code could not be read)");
        lose(k, now);
      }
      break;
    case Phase::Lost: {
      const core::Duration wait = s.backoff == core::Duration::zero() ? options_.boot_retry : s.backoff;
      if (line_booting_ || line_backoff_ || link_seen_ != LinkState::Up || now - s.since < wait) break;
      for (std::size_t a : s.axes) axes_[a].io->forget_requests();
      if (s.coe) s.coe->reset();
      if (boot_->restart_slave(k, now)) {
        core::FixedString<60> why;
        why.format("restarting it (after %lld ms)",
                   static_cast<long long>(std::chrono::duration_cast<std::chrono::milliseconds>(wait).count()));
        set_detail(s, why.c_str());
        enter(s, Phase::Restart, now);
      }
      break;
    }
    case Phase::SafeStop: run_safe_stop(k, now); break;
  }
}

void EthercatBus::read_names(std::size_t k) noexcept {
  Slave& s = *slaves_[k];
  if (!s.dict) return;
  if (s.dict_due) {
    // SDO Information only where the SII offers it: a slave without it may not answer at all
    // [ETG.1000.6 Table 21, CoE details bit 1].
    const SiiInfo& sii = boot_->sii(k);
    const bool sdo_info = s.coe && s.coe->valid() && sii.has_general && (sii.general.coe_details & coe_details::kSdoInfo) != 0;
    if (!s.dict->start(sdo_info)) return;
    s.dict_due = false;
  }
  if (s.coe) s.dict->step(*s.coe);
}

core::NamedObject EthercatBus::find_object(std::size_t axis, std::string_view name) const {
  core::NamedObject out;
  if (axis >= axes_.size()) return out;
  const Axis& x = axes_[axis];
  const SlaveDictionary* dict = slaves_[x.slave]->dict.get();
  if (dict == nullptr) return out;
  DictionaryMatch m = dict->find(name, x.names);
  out.found = m.found;
  out.index = m.index;
  out.sub = m.sub;
  out.type = m.type;
  out.source = "the object dictionary of slave " + std::to_string(x.slave + 1) + " (SDO Information)";
  out.error = std::move(m.error);
  return out;
}

void EthercatBus::on_result(std::uint32_t tag, const DatagramAnswer& a) noexcept {
  const std::size_t k = tag >> 16;
  if (k >= slaves_.size()) return;
  Slave& s = *slaves_[k];
  if (s.phase != Phase::LeftOp || !s.left_op_waiting || (tag & 0xFFFF) != s.left_op_seq) return;
  s.left_op_waiting = false;
  if (a.outcome != DatagramOutcome::Answered || a.wkc != 1 || a.data.size() < kAlBlock) {
    set_detail(s, "left OP (no answer to the AL status read)");
  } else {
    const AlStatus st = decode_al_status(core::get_u16(a.data, 0));
    const std::uint16_t code = core::get_u16(a.data, 4);
    const std::string_view state = to_string(st.state());
    const std::string_view text = al_status_text(code);
    core::FixedString<140> why;
    if (st.error)
      why.format("left OP: %.*s + error 0x%04X %.*s", static_cast<int>(state.size()), state.data(), code,
                 static_cast<int>(text.size()), text.data());
    else
      why.format("left OP: now %.*s", static_cast<int>(state.size()), state.data());
    set_detail(s, why.c_str());
  }
  lose(k, last_now_);
}

// The drive does not follow the controlword (DESIGN.md §4): quick stop through the process data,
// then disable voltage, then the slave to SAFE-OP (its outputs no longer applied) and a fresh
// configuration, as after a loss.
void EthercatBus::run_safe_stop(std::size_t k, core::TimePoint now) noexcept {
  Slave& s = *slaves_[k];
  switch (s.safe_step) {
    case 0:
      for (std::size_t a : s.axes) axes_[a].io->override_controlword(true, 0x0002);
      s.safe_step = 1;
      break;
    case 1: {
      bool braking = false;
      for (std::size_t a : s.axes) {
        const auto st = cia402::decode_state(axes_[a].io->statusword());
        braking = braking || st == core::AxisState::OperationEnabled || st == core::AxisState::QuickStopActive;
      }
      if (braking && now - s.since < kSafeStopBudget) break;
      for (std::size_t a : s.axes) axes_[a].io->override_controlword(true, 0x0000);
      s.safe_step = 2;
      s.since = now;
      break;
    }
    case 2:
      if (now - s.since < kDisableHold) break;
      if (boot_->request_state(k, AlState::SafeOp, now)) {
        s.safe_step = 3;
      } else {
        s.safe_step = 4;
      }
      break;
    case 3:
      if (boot_->slave(k).status == SlaveStatus::Busy) break;
      s.safe_step = 4;
      break;
    default:
      set_detail(s, "stopped after it stopped following its controlword: configuring it again");
      for (std::size_t a : s.axes) axes_[a].io->forget_requests();
      if (s.coe) s.coe->reset();
      if (boot_->restart_slave(k, now)) {
        enter(s, Phase::Restart, now);
      } else {
        lose(k, now);
      }
      for (std::size_t a : s.axes) axes_[a].io->override_controlword(false);
      break;
  }
}

void EthercatBus::close() noexcept {
  if (!open_) return;
  // Best effort and bounded: every slave to SAFE-OP (outputs no longer applied), then INIT
  // [ETG.1000.6 §5.3: the master takes the slaves down before it stops sending].
  const core::SteadyClock clock;
  const auto run = [&](AlState target) {
    for (std::size_t k = 0; k < slaves_.size() && k < boot_->slave_count(); ++k)
      if (boot_->slave(k).state > target) boot_->request_state(k, target, last_now_);
    const auto start = clock.now();
    while (clock.now() - start < kCloseBudget) {
      bool busy = false;
      for (std::size_t k = 0; k < boot_->slave_count(); ++k) busy = busy || boot_->slave(k).status == SlaveStatus::Busy;
      if (!busy) break;
      const core::TimePoint now = last_now_ + (clock.now() - start);
      if (peer_) peer_->step(now);
      const std::size_t got = link_->receive(rx_);
      for (std::size_t i = 0; i < got; ++i) tx_.on_frame(rx_[i].view());
      tx_.expire(now);
      if (cx_ && image_.ok()) cx_->queue(tx_);
      boot_->poll(now, tx_);
      const auto frames = tx_.take_frames(now + cycle_time_);
      if (!frames.empty()) link_->send(frames);
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
  };
  if (!line_booting_) {
    run(AlState::SafeOp);
    run(AlState::Init);
  }
  link_->close();
  open_ = false;
  for (auto& s : slaves_) s->link.store(core::LinkState::Offline, std::memory_order_relaxed);
}

std::unique_ptr<EthercatBus> make_ethercat_bus(const config::BusPlan& plan) {
  const auto& o = plan.section<config::EthercatBusOptions>();
  if (o.transport == config::EthercatTransportKind::Simulated) return make_simulated_ethercat_bus(plan);
  RawSocketOptions r;
  r.interface = o.interface;
  return std::make_unique<EthercatBus>(plan, std::make_unique<RawSocketLink>(std::move(r)));
}

}  // namespace drivegate::ethercat
