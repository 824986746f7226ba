#include "adapters/profinet/profinet_bus.hpp"

#include <algorithm>
#include <cstdarg>
#include <random>
#include <stdexcept>
#include <thread>

#include "adapters/link/interface.hpp"
#include "adapters/link/raw_socket_link.hpp"
#include "adapters/link/udp_endpoint.hpp"
#include "adapters/profinet/link/profinet_link.hpp"
#include "adapters/profinet/sim_transport.hpp"
#include "adapters/profinet/wire/blocks_record.hpp"
#include "profiles/profidrive/master_settings.hpp"

namespace drivegate::profinet {

namespace {

using Phase = ProfinetBus::Phase;
using namespace std::chrono_literals;

// close(): how long the Releases may take in real time.
constexpr core::Duration kCloseBudget = 500ms;
// Reads of a parameter response the drive answers "not ready" to before the exchange fails.
constexpr int kMaxResponseReads = 20;
// The API of generic IO devices' submodules (the default API) [IEC 61158-6-10, API 0].
constexpr std::uint32_t kDefaultApi = 0;
// The first RT class 1 FrameIDs the controller proposes [IEC 61158-6-10 FrameID C000h-FBFFh];
// the device's IOCRBlockRes has the last word, and the CRs use its values.
constexpr std::uint16_t kFirstFrameId = 0xC000;

// A version 4 (random) UUID from the bus' seed and two numbers that make it unique per AR.
Uuid make_uuid(std::uint64_t seed, std::uint32_t a, std::uint32_t b) noexcept {
  Uuid u;
  u.time_low = static_cast<std::uint32_t>(seed) ^ a;
  u.time_mid = static_cast<std::uint16_t>(seed >> 32);
  u.time_hi_and_version = static_cast<std::uint16_t>(0x4000 | ((seed >> 48) & 0x0FFF));
  u.clock_seq_node = {static_cast<std::uint8_t>(0x80 | ((b >> 24) & 0x3F)), static_cast<std::uint8_t>(b >> 16),
                      static_cast<std::uint8_t>(b >> 8), static_cast<std::uint8_t>(b),
                      static_cast<std::uint8_t>(a >> 24), static_cast<std::uint8_t>(a >> 16),
                      static_cast<std::uint8_t>(a >> 8), static_cast<std::uint8_t>(a)};
  return u;
}

// A value of a fixed-size type is little-endian in a ParamRequest/ParamReply and big-endian in a
// record [IEC 61158-6-10: the fields of records are big-endian]: reversed on the way.
bool reversed_in_record(core::ParamType t, std::size_t size) noexcept {
  return (core::param_type_is_integer(t) || core::param_type_is_real(t)) && core::param_type_size(t) == size;
}

bool ar_exists(CmClientState s) noexcept {
  return s == CmClientState::Parameterising || s == CmClientState::PrmEnd || s == CmClientState::WaitApplicationReady ||
         s == CmClientState::DataExchange;
}

}  // namespace

// --- the record-47 channel -------------------------------------------------------------------------

profidrive::ParamTicket ProfinetBus::RecordChannel::submit(std::span<const std::uint8_t> request) noexcept {
  if (state_ != State::Idle || request.empty() || request.size() > request_.size() || !device_.cm ||
      device_.cm->state() != CmClientState::DataExchange)
    return profidrive::kNoTicket;
  std::copy(request.begin(), request.end(), request_.begin());
  request_size_ = request.size();
  record_ = device_.cm->submit_write(api_, slot_, subslot_, record_index::kAkdParameterAccess,
                                     std::span<const std::uint8_t>(request_).first(request_size_));
  if (record_ == 0) return profidrive::kNoTicket;
  state_ = State::Writing;
  reads_ = 0;
  ticket_ = ++last_ticket_;
  if (ticket_ == profidrive::kNoTicket) ticket_ = ++last_ticket_;
  return ticket_;
}

profidrive::ParamResult ProfinetBus::RecordChannel::poll(profidrive::ParamTicket ticket) noexcept {
  profidrive::ParamResult r;
  if (ticket == profidrive::kNoTicket || ticket != ticket_) return r;
  switch (state_) {
    case State::Done:
      r.state = profidrive::ParamState::Done;
      r.response = std::span<const std::uint8_t>(response_).first(response_size_);
      break;
    case State::Failed:
      r.state = profidrive::ParamState::Failed;
      r.error = error_.view();
      break;
    case State::Idle: return r;
    default: r.state = profidrive::ParamState::Pending; return r;
  }
  // Done and Failed are reported once; the channel is free again.
  state_ = State::Idle;
  ticket_ = profidrive::kNoTicket;
  return r;
}

void ProfinetBus::RecordChannel::cancel(profidrive::ParamTicket ticket) noexcept {
  if (ticket == profidrive::kNoTicket || ticket != ticket_) return;
  state_ = State::Idle;
  ticket_ = profidrive::kNoTicket;
  record_ = 0;  // its reply, should one come, is not ours any more
}

void ProfinetBus::RecordChannel::fail(std::string_view why) noexcept {
  error_.assign(why);
  state_ = State::Failed;
  record_ = 0;
}

bool ProfinetBus::RecordChannel::on_reply(const CmRecordReply& reply) noexcept {
  if (record_ == 0 || reply.id != record_) return false;
  record_ = 0;
  if (state_ == State::Writing) {
    if (reply.outcome == CmRecordOutcome::Done)
      state_ = State::ReadDue;
    else
      fail(reply.text);
    return true;
  }
  if (state_ != State::Reading) return true;
  if (reply.outcome == CmRecordOutcome::Done) {
    response_size_ = std::min(reply.data.size(), response_.size());
    std::copy_n(reply.data.begin(), response_size_, response_.begin());
    state_ = State::Done;
  } else if (reply.outcome == CmRecordOutcome::Refused && ++reads_ < kMaxResponseReads) {
    // The drive has no response ready yet (PROFIdrive: the read is refused until it has) [§5.1].
    state_ = State::ReadDue;
  } else {
    fail(reply.text);
  }
  return true;
}

void ProfinetBus::RecordChannel::step() noexcept {
  if (state_ != State::ReadDue || !device_.cm) return;
  record_ = device_.cm->submit_read(api_, slot_, subslot_, record_index::kAkdParameterAccess, response_.size());
  if (record_ == 0) {
    // The AR ended or its queue is full: the master's timeout ends the exchange, or the AR's end.
    if (device_.cm->state() != CmClientState::DataExchange) fail("the AR ended before the response was read");
    return;
  }
  state_ = State::Reading;
}

void ProfinetBus::RecordChannel::ar_ended() noexcept {
  if (state_ == State::Writing || state_ == State::ReadDue || state_ == State::Reading)
    fail("the AR ended before the parameter exchange completed");
}

// --- the telegram port -----------------------------------------------------------------------------

std::span<const std::uint8_t> ProfinetBus::Telegram::actual() const noexcept {
  if (!device_.exchanging()) return {};
  const RtConsumer& c = *device_.consumer;
  if (!iox_status::is_good(c.iops(submodule_)) || !c.provider_run()) return {};
  return c.data(submodule_);
}

bool ProfinetBus::Telegram::actual_fresh() const noexcept { return device_.fresh; }

std::span<std::uint8_t> ProfinetBus::Telegram::setpoint() noexcept {
  if (device_.provider && device_.provider->ok()) return device_.provider->data(submodule_);
  return std::span<std::uint8_t>(parked_).first(std::min(out_size_, parked_.size()));
}

void ProfinetBus::Telegram::control_lost(std::string_view why) noexcept {
  device_.lose_pending = true;
  device_.lose_reason.format("the drive does not follow the gateway (%.*s); releasing the AR",
                             static_cast<int>(why.size()), why.data());
}

// --- the device --------------------------------------------------------------------------------------

bool ProfinetBus::Device::exchanging() const noexcept {
  return phase == Phase::Running && consumer && consumer->state() == RtConsumerState::Running;
}

void ProfinetBus::Device::on_record_reply(const CmRecordReply& reply) noexcept {
  if (im0_read != 0 && reply.id == im0_read) {
    im0_read = 0;
    const Im0View v = reply.outcome == CmRecordOutcome::Done ? decode_im0(reply.data) : Im0View{WireError::Truncated, {}};
    if (v.error == WireError::None) {
      const Im0& m = v.im0;
      // The form core/device_identity.hpp reads back for clients (drivegatectl list).
      identity.format("I&M0 order %.*s serial %.*s hw %u sw %c%u.%u.%u", static_cast<int>(m.order_id.size()), m.order_id.data(),
                      static_cast<int>(m.serial_number.size()), m.serial_number.data(), m.hardware_revision,
                      m.software_prefix, m.software_functional, m.software_bugfix, m.software_internal);
    } else {
      const std::string_view why = reply.outcome == CmRecordOutcome::Done ? to_string(v.error) : reply.text;
      identity.format("I&M0 not read: %.*s", static_cast<int>(why.size()), why.data());
    }
    if (phase == Phase::Running) bus->set_detail(*this, "in data exchange (AR %u); %s", static_cast<unsigned>(ars), identity.c_str());
    return;
  }
  if (client_record != 0 && reply.id == client_record) {
    bus->client_record_done(*this, &reply, {});
    return;
  }
  for (const std::size_t a : axes)
    if (bus->axes_[a]->channel->on_reply(reply)) return;
}

void ProfinetBus::Device::on_alarm(const AlarmEvent& event) noexcept {
  core::Event e;
  e.kind = core::EventKind::Warning;
  if (axes.empty()) {
    e.text.format("bus %s: station %s: %.*s", bus->name_.c_str(), station.name.c_str(), static_cast<int>(event.text.size()),
                  event.text.data());
    bus->push_event(e);
    return;
  }
  for (const std::size_t a : axes) {
    e.axis = static_cast<core::AxisIndex>(a);
    e.text.format("%.*s", static_cast<int>(event.text.size()), event.text.data());
    bus->push_event(e);
  }
}

// --- construction ------------------------------------------------------------------------------------

ProfinetBus::ProfinetBus(const config::BusPlan& plan, ProfinetTransport transport)
    : name_(plan.name), options_(plan.section<config::ProfinetBusOptions>()), transport_(std::move(transport)) {
  const auto fail = [&](const std::string& what) { throw core::BusError("bus '" + name_ + "': " + what); };
  std::random_device random;
  uuid_seed_ = static_cast<std::uint64_t>(random()) << 32 | random();

  // The submodules of each device's AR, gathered from the axes and IO devices that use it.
  std::vector<std::vector<ArSubmodule>> subs;
  for (const auto& s : options_.stations) {
    auto d = std::make_unique<Device>();
    d->bus = this;
    d->index = devices_.size();
    d->station.name = s.name;
    d->station.ip.address = ipv4_octets(s.ip);
    d->station.ip.netmask = ipv4_octets(s.netmask);
    d->station.ip.gateway = ipv4_octets(s.gateway);
    d->station.vendor_id = s.vendor_id;
    d->station.device_id = s.device_id;
    devices_.push_back(std::move(d));
    subs.emplace_back();
  }
  const auto device_index = [&](const std::string& station) {
    for (std::size_t i = 0; i < devices_.size(); ++i)
      if (devices_[i]->station.name == station) return i;
    fail("station \"" + station + "\" is not in the bus' devices");
    return std::size_t{0};
  };
  // Slot 0: the device access point, once per device.
  const auto add_dap = [&](std::size_t dev, std::uint32_t module, std::uint32_t submodule) {
    for (const ArSubmodule& s : subs[dev])
      if (s.slot == 0) return;
    subs[dev].push_back({kDefaultApi, 0, 1, module, submodule, 0, 0});
  };
  for (const auto& a : plan.axes) {
    const auto& ax = a.section<config::ProfinetAxisSpec>();
    const auto& spec = a.device.section<config::ProfidriveDeviceSpec>();
    if (!spec.idents)
      fail("axis '" + a.spec.name + "': device profile \"" + a.device.name +
           "\" gives no module idents (profidrive.idents: the DAP's and the telegram modules', from the drive's GSDML); "
           "the Connect cannot name the drive's modules without them");
    const auto size = profidrive::telegram_size(ax.telegram);
    if (!size || !profidrive::standard_layout(ax.telegram))
      fail("axis '" + a.spec.name + "': telegram " + std::to_string(ax.telegram) +
           " has no fixed layout; the PROFINET runtime drives telegrams 1, 7, 9, 350, 351, 352 and 353");
    const std::size_t dev = device_index(ax.station);
    add_dap(dev, spec.idents->dap_module, spec.idents->dap_submodule);
    subs[dev].push_back({spec.idents->api, static_cast<std::uint16_t>(ax.slot), static_cast<std::uint16_t>(ax.subslot),
                         spec.idents->telegram_module(ax.telegram), spec.idents->telegram_submodule(ax.telegram),
                         static_cast<std::uint16_t>(size->actual_bytes), static_cast<std::uint16_t>(size->setpoint_bytes)});
  }
  for (const auto& io : options_.io) {
    const std::size_t dev = device_index(io.station);
    add_dap(dev, io.dap_ident, io.dap_submodule_ident);
    for (const auto& s : io.submodules)
      subs[dev].push_back({kDefaultApi, static_cast<std::uint16_t>(s.slot), static_cast<std::uint16_t>(s.subslot),
                           s.module_ident, s.submodule_ident, static_cast<std::uint16_t>(s.input_bytes),
                           static_cast<std::uint16_t>(s.output_bytes)});
    Device& d = *devices_[dev];
    for (const auto& r : io.records) {
      d.record_data.push_back(r.data);
    }
  }
  for (std::size_t i = 0; i < devices_.size(); ++i) {
    Device& d = *devices_[i];
    std::sort(subs[i].begin(), subs[i].end(), [](const ArSubmodule& x, const ArSubmodule& y) {
      return x.slot != y.slot ? x.slot < y.slot : x.subslot < y.subslot;
    });
    try {
      d.layout = std::make_unique<ArLayout>(std::move(subs[i]));
    } catch (const std::invalid_argument& e) {
      fail("station \"" + d.station.name + "\": " + e.what());
    }
  }
  // The IO devices' parameter records (record_data is final now: hand out views).
  for (const auto& io : options_.io) {
    Device& d = *devices_[device_index(io.station)];
    std::size_t k = d.parameters.size();
    for (const auto& r : io.records)
      d.parameters.push_back({kDefaultApi, static_cast<std::uint16_t>(r.slot), static_cast<std::uint16_t>(r.subslot), r.index,
                              d.record_data[k++]});
    IoDevice x;
    x.name = io.name;
    x.device = d.index;
    for (const auto& s : io.submodules) {
      x.submodules.push_back(d.layout->index(static_cast<std::uint16_t>(s.slot), static_cast<std::uint16_t>(s.subslot)));
      x.input_size += static_cast<std::size_t>(s.input_bytes);
      x.output_size += static_cast<std::size_t>(s.output_bytes);
    }
    if (x.input_size > core::kMaxIoBytes || x.output_size > core::kMaxIoBytes)
      fail("IO device '" + io.name + "': more than " + std::to_string(core::kMaxIoBytes) + " bytes in one direction");
    d.io = io_.size();
    io_.push_back(std::move(x));
  }
  for (std::size_t i = 0; i < plan.axes.size(); ++i) {
    const auto& a = plan.axes[i];
    const auto& ax = a.section<config::ProfinetAxisSpec>();
    const auto& spec = a.device.section<config::ProfidriveDeviceSpec>();
    Device& d = *devices_[device_index(ax.station)];
    auto x = std::make_unique<Axis>();
    x->device = d.index;
    for (const auto& [code, text] : a.device.fault_texts) x->faults.push_back({static_cast<std::uint16_t>(code), text});
    const std::size_t sub = d.layout->index(static_cast<std::uint16_t>(ax.slot), static_cast<std::uint16_t>(ax.subslot));
    const auto size = profidrive::telegram_size(ax.telegram);
    x->channel = std::make_unique<RecordChannel>(d, spec.idents->api, static_cast<std::uint16_t>(ax.slot),
                                                 static_cast<std::uint16_t>(ax.subslot));
    x->telegram = std::make_unique<Telegram>(d, sub, size->setpoint_bytes);
    x->master = std::make_unique<profidrive::ProfidriveMaster>(*x->telegram, *x->channel, *profidrive::standard_layout(ax.telegram),
                                                                profidrive::settings_from(a.spec));
    x->master->set_fault_table(x->faults);
    d.axes.push_back(axes_.size());
    axes_.push_back(std::move(x));
  }
}

ProfinetBus::~ProfinetBus() = default;

// --- life cycle --------------------------------------------------------------------------------------

void ProfinetBus::open(core::TimePoint now) {
  try {
    transport_.frames->open();
    transport_.client->open();
    transport_.server->open();
  } catch (const link::LinkError& e) {
    throw core::BusError("bus '" + name_ + "': " + e.what());
  }
  if (transport_.mac == MacAddress{}) {
    const link::InterfaceAddresses a = link::interface_addresses(transport_.interface);
    if (!a.has_mac) throw core::BusError("bus '" + name_ + "': cannot read the MAC address of '" + transport_.interface + "'");
    transport_.mac = a.mac;
  }
  for (auto& d : devices_) {
    // Each device's client has its own Xid range, so that the devices are searched for at once.
    d->dcp.emplace(transport_.mac, DcpClientTiming{}, static_cast<std::uint32_t>(d->index + 1) << 20);
    d->backoff = kRetryFirst;
  }
  open_ = true;
  last_now_ = now;
  link_seen_ = transport_.frames->poll_state(now);
  for (auto& d : devices_) {
    if (link_seen_ == link::LinkState::Up) {
      start_find(*d, now);
    } else {
      set_detail(*d, "waiting for the Ethernet link (%s)", link::to_string(link_seen_));
      enter(*d, Phase::Wait, now);
    }
  }
}

void ProfinetBus::close() noexcept {
  if (!open_) return;
  // Release every AR (the devices then stop at once instead of after their watchdog), bounded.
  const core::SteadyClock clock;
  const auto start = clock.now();
  core::TimePoint now = last_now_;
  for (auto& d : devices_)
    if (d->cm && d->cm->state() != CmClientState::Idle) d->cm->release(now, out_);
  flush_datagrams();

  const auto pending = [&] {
    for (const auto& d : devices_)
      if (d->cm && d->cm->state() == CmClientState::Releasing) return true;
    return false;
  };
  while (pending() && clock.now() - start < kCloseBudget) {
    while (transport_.client->receive_from(datagram_)) dispatch_datagram(datagram_, CmSocket::Client, now);
    while (transport_.server->receive_from(datagram_)) dispatch_datagram(datagram_, CmSocket::Server, now);
    if (transport_.peer) transport_.peer->step(now);
    for (auto& d : devices_)
      if (d->cm) d->cm->poll(now, out_);
    flush_datagrams();
    std::this_thread::sleep_for(1ms);
    now = last_now_ + (clock.now() - start);
  }
  for (auto& d : devices_) {
    stop_cyclic(*d);
    enter(*d, Phase::Idle, now);
  }
  transport_.frames->close();
  transport_.client->close();
  transport_.server->close();
  open_ = false;
}

void ProfinetBus::set_detail(Device& d, const char* fmt, ...) noexcept {
  char what[320];
  va_list args;
  va_start(args, fmt);
  std::vsnprintf(what, sizeof what, fmt, args);
  va_end(args);
  if (d.ip != 0) {
    const auto mac = mac_text(d.mac);
    const auto ip = ipv4_octets(d.ip);
    d.detail.format("station \"%s\" (%s at %u.%u.%u.%u): %s", d.station.name.c_str(), mac.data(), ip[0], ip[1], ip[2], ip[3],
                    what);
  } else {
    d.detail.format("station \"%s\": %s", d.station.name.c_str(), what);
  }
}

void ProfinetBus::enter(Device& d, Phase p, core::TimePoint now) noexcept {
  d.phase = p;
  d.since = now;
  core::LinkState link = core::LinkState::Offline;
  switch (p) {
    case Phase::Idle: link = core::LinkState::Offline; break;
    case Phase::Find: link = d.had_op ? core::LinkState::Lost : core::LinkState::Booting; break;
    case Phase::Connect: link = d.had_op ? core::LinkState::Lost : core::LinkState::Configuring; break;
    case Phase::Running: link = core::LinkState::Operational; break;
    case Phase::Wait: link = d.had_op ? core::LinkState::Lost : core::LinkState::Offline; break;
  }
  if (p == Phase::Running) d.had_op = true;
  d.link.store(link, std::memory_order_relaxed);
}

void ProfinetBus::start_find(Device& d, core::TimePoint now) {
  StationFinderOptions o;
  o.ip_qualifier =
      options_.ip_assignment == config::ProfinetIpAssignment::Permanent ? DcpQualifier::Permanent : DcpQualifier::Temporary;
  d.finder = std::make_unique<StationFinder>(*d.dcp, std::vector<StationConfig>{d.station}, o);
  if (d.phase != Phase::Find) {
    set_detail(d, "searching (DCP identify by name)");
    enter(d, Phase::Find, now);
  }
}

void ProfinetBus::found(Device& d, core::TimePoint now) noexcept {
  const StationReport& r = d.finder->reports().front();
  if (!r.ok()) {
    // A station that does not answer yet (booting) is asked again until dcp_timeout passed.
    if (r.outcome == StationOutcome::Missing && now - d.since < options_.dcp_timeout) {
      start_find(d, now);
      return;
    }
    d.detail.assign(r.text);
    d.finder.reset();
    d.backoff = std::min(d.backoff * 2, kRetryMax);
    ++errors_;
    enter(d, Phase::Wait, now);
    return;
  }
  d.mac = r.mac;
  d.ip = ipv4_host(r.ip.address);
  d.vendor_id = r.vendor_id;
  d.device_id = r.device_id;
  d.finder.reset();
  connect(d, now);
}

void ProfinetBus::connect(Device& d, core::TimePoint now) noexcept {
  ++d.ars;
  const auto ar = static_cast<std::uint32_t>(d.ars);
  const auto factor = static_cast<std::uint16_t>(options_.send_clock / config::kProfinetClockBase);
  CmClientConfig& c = d.cm_config;
  c.device = {d.ip, kRpcUdpPort};
  c.device_object = {1, d.device_id, d.vendor_id};
  c.activity = make_uuid(~uuid_seed_, static_cast<std::uint32_t>(d.index), ar);
  c.order = ByteOrder::Little;
  ConnectRequest& q = c.connect;
  q.ar.ar_uuid = make_uuid(uuid_seed_, static_cast<std::uint32_t>(d.index), ar);
  q.ar.session_key = static_cast<std::uint16_t>(ar == 0 ? 1 : ar);
  q.ar.initiator_mac = transport_.mac;
  q.ar.initiator_object_uuid = make_pnio_object_uuid({1, 0, 0});
  q.ar.station_name = options_.controller_station;
  const auto iocr = [&](IocrParams& p, std::uint16_t type, std::uint16_t reference, std::uint16_t length) {
    p = IocrParams{};
    p.type = type;
    p.reference = reference;
    p.data_length = length;
    p.frame_id = static_cast<std::uint16_t>(kFirstFrameId + 2 * d.index + reference);
    p.send_clock_factor = factor;
    p.reduction_ratio = static_cast<std::uint16_t>(options_.reduction_ratio);
    p.phase = static_cast<std::uint16_t>(1 + d.index % static_cast<std::size_t>(options_.reduction_ratio));
    p.watchdog_factor = static_cast<std::uint16_t>(options_.data_hold_factor);
    p.data_hold_factor = static_cast<std::uint16_t>(options_.data_hold_factor);
  };
  iocr(q.input, iocr_type::kInput, 1, d.layout->input_length());
  iocr(q.output, iocr_type::kOutput, 2, d.layout->output_length());
  q.input_apis = d.layout->input_apis();
  q.output_apis = d.layout->output_apis();
  q.alarm = AlarmCrBlockReq{};
  q.expected = d.layout->expected();
  c.parameters = d.parameters;
  d.im0_read = 0;
  d.cm.emplace(c, &d);
  d.cm->start(now, out_);
  set_detail(d, "connecting (AR %u)", ar);
  enter(d, Phase::Connect, now);
}

void ProfinetBus::start_cyclic(Device& d, core::TimePoint now) noexcept {
  const IocrParams& out = d.cm_config.connect.output;
  RtIocrConfig rt;
  rt.controller_mac = transport_.mac;
  rt.device_mac = d.mac;
  rt.send_clock_factor = out.send_clock_factor;
  rt.reduction_ratio = out.reduction_ratio;
  rt.phase = out.phase;
  rt.data_hold_factor = out.data_hold_factor;
  rt.submodules = d.layout->io();
  rt.frame_id = d.cm->output_frame_id();
  d.provider.emplace(rt);
  rt.frame_id = d.cm->input_frame_id();
  d.consumer.emplace(rt);
  if (!d.provider->ok() || !d.consumer->ok()) {
    const RtConfigError e = d.provider->ok() ? d.consumer->error() : d.provider->error();
    core::Text why;
    why.format("the device's frame IDs cannot be used (output 0x%04X, input 0x%04X): %.*s", d.cm->output_frame_id(),
               d.cm->input_frame_id(), static_cast<int>(to_string(e).size()), to_string(e).data());
    lose(d, why.view(), now);
    return;
  }
  // The controller's application runs: every output good, every input consumed.
  for (std::size_t i = 0; i < d.layout->io().size(); ++i) {
    (void)d.provider->set_iops(i, iox_status::kGood);
    (void)d.provider->set_iocs(i, iox_status::kGood);
  }
  d.provider->start(now);
  d.consumer->arm(now);
  AlarmChannelConfig ac;
  ac.controller_mac = transport_.mac;
  ac.device_mac = d.mac;
  ac.alarm_cr = d.cm_config.connect.alarm;
  ac.device_reference = d.cm->alarm_cr_response().local_alarm_reference;
  d.alarms.emplace(ac, &d);
  d.alarms->open();
  d.cyclic = true;
  d.frames_seen = 0;
  d.fresh = false;
}

void ProfinetBus::stop_cyclic(Device& d) noexcept {
  if (d.provider) d.provider->stop();
  if (d.consumer) d.consumer->disarm();
  if (d.alarms) d.alarms->close();
  d.cyclic = false;
  d.fresh = false;
}

void ProfinetBus::lose(Device& d, std::string_view why, core::TimePoint now) noexcept {
  const bool was_running = d.phase == Phase::Running;
  stop_cyclic(d);
  for (const std::size_t a : d.axes) axes_[a]->channel->ar_ended();
  if (d.client_record != 0) client_record_done(d, nullptr, "the AR ended before the record's reply came");
  if (d.io) io_[*d.io].outputs.fill(0);
  // Release the AR where the device may still hold it (a silent device's Release just times out).
  if (d.cm && d.cm->state() != CmClientState::Failed && d.cm->state() != CmClientState::Released) d.cm->release(now, out_);
  set_detail(d, "%s: %.*s", was_running ? "lost" : "failed", static_cast<int>(why.size()), why.data());
  d.backoff = was_running ? kRetryFirst : std::min(d.backoff * 2, kRetryMax);
  ++errors_;
  enter(d, Phase::Wait, now);
}

void ProfinetBus::step(Device& d, core::TimePoint now) noexcept {
  if (d.lose_pending) {
    d.lose_pending = false;
    if (d.phase == Phase::Connect || d.phase == Phase::Running) lose(d, d.lose_reason.view(), now);
  }
  switch (d.phase) {
    case Phase::Idle: break;
    case Phase::Find:
      if (d.finder && d.finder->done()) found(d, now);
      break;
    case Phase::Connect:
    case Phase::Running: {
      const CmClientState s = d.cm->state();
      if (s == CmClientState::Failed || s == CmClientState::Released) {
        lose(d, s == CmClientState::Failed ? d.cm->reason() : std::string_view{"the AR was released"}, now);
        break;
      }
      if (ar_exists(s) && !d.cyclic) start_cyclic(d, now);
      if (!d.cyclic) break;
      d.consumer->poll(now);
      if (d.consumer->state() == RtConsumerState::Timeout) {
        lost_.fetch_add(1, std::memory_order_relaxed);
        lose(d, d.consumer->reason(), now);
        break;
      }
      if (d.alarms->state() == AlarmChannelState::Aborted) {
        lose(d, d.alarms->reason(), now);
        break;
      }
      const std::uint64_t frames = d.consumer->counters().frames;
      d.fresh = frames != d.frames_seen;
      d.frames_seen = frames;
      if (d.phase == Phase::Connect && s == CmClientState::DataExchange &&
          d.consumer->state() == RtConsumerState::Running) {
        set_detail(d, "in data exchange (AR %u)", static_cast<unsigned>(d.ars));
        d.backoff = kRetryFirst;
        enter(d, Phase::Running, now);
        // The device's identity for the link detail: I&M0 of the DAP [IEC 61158-6-10 I&M0, AFF0h].
        d.im0_read = d.cm->submit_read(kDefaultApi, 0, 1, record_index::kIm0, kIm0Size);
      }
      for (const std::size_t a : d.axes) axes_[a]->channel->step();
      break;
    }
    case Phase::Wait:
      if (link_seen_ == link::LinkState::Up && now - d.since >= d.backoff) start_find(d, now);
      break;
  }
}

// --- client records ----------------------------------------------------------------------------------

core::Admission ProfinetBus::record(const core::ParamRequest& req, core::TimePoint /*now*/) noexcept {
  const core::RecordAddress& a = req.record;
  core::Admission no;
  no.accepted = false;
  Device* dp = nullptr;
  if (a.io != core::kNoIo && a.io < io_.size())
    dp = devices_[io_[a.io].device].get();
  else if (a.io == core::kNoIo && req.axis < axes_.size())
    dp = devices_[axes_[req.axis]->device].get();
  if (dp == nullptr) return core::Admission::reject("no such axis or IO device on this bus");
  Device& d = *dp;
  for (const std::size_t x : d.axes)
    if (a.index == record_index::kAkdParameterAccess && axes_[x]->channel->carries(a.slot, a.subslot)) {
      no.reason.format("record 47 of slot %u subslot %u is the PROFIdrive parameter channel of the device's axis, run "
                       "by the gateway: give a PNU (p930) instead",
                       unsigned{a.slot}, unsigned{a.subslot});
      return no;
    }
  if (req.write && (req.size == 0 || req.size > CmClient::kMaxRecordData)) {
    no.reason.format("a record write carries 1 to %zu bytes here (one RPC datagram), not %u", CmClient::kMaxRecordData,
                     unsigned{req.size});
    return no;
  }
  if (!d.cm || d.cm->state() != CmClientState::DataExchange) {
    no.reason.format("station \"%s\" is not in data exchange: no record access now (%s)", d.station.name.c_str(),
                     d.detail.c_str());
    return no;
  }
  if (d.client_record != 0 || records_in_flight_ + record_count_ >= record_replies_.size()) {
    no.reason.assign("the record requests of this bus are all in flight: try again later");
    no.busy = true;
    return no;
  }
  std::uint32_t api = a.api;
  if (!a.api_given) {
    // The API the configuration puts the submodule in (the AKD's telegram: 3A00h), else API 0.
    const std::size_t i = d.layout->index(a.slot, a.subslot);
    api = i < d.layout->submodules().size() ? d.layout->submodules()[i].api : kDefaultApi;
  }
  core::ParamReply& r = d.client_reply;
  r = core::ParamReply{};
  r.id = req.id;
  r.axis = req.axis;
  r.type = req.type == core::ParamType::Unknown ? core::ParamType::OctetString : req.type;
  if (req.write) {
    const auto bytes = req.bytes();
    if (reversed_in_record(req.type, bytes.size()))
      std::reverse_copy(bytes.begin(), bytes.end(), record_scratch_.begin());
    else
      std::copy(bytes.begin(), bytes.end(), record_scratch_.begin());
    r.size = req.size;
    std::copy(bytes.begin(), bytes.end(), r.data.begin());
    d.client_record = d.cm->submit_write(api, a.slot, a.subslot, a.index,
                                         std::span<const std::uint8_t>(record_scratch_).first(bytes.size()));
  } else {
    d.client_record = d.cm->submit_read(api, a.slot, a.subslot, a.index, std::min(CmClient::kMaxRecordData, r.data.size()));
  }
  if (d.client_record == 0) return core::Admission::reject("the IO controller's record queue of the station is full");
  ++records_in_flight_;
  return core::Admission::accept();
}

void ProfinetBus::client_record_done(Device& d, const CmRecordReply* reply, std::string_view why) noexcept {
  d.client_record = 0;
  if (records_in_flight_ > 0) --records_in_flight_;
  core::ParamReply& r = d.client_reply;
  if (reply != nullptr && reply->outcome == CmRecordOutcome::Done) {
    r.ok = true;
    if (!reply->write) {
      const std::size_t n = std::min(reply->data.size(), r.data.size());
      if (reversed_in_record(r.type, n))
        std::reverse_copy(reply->data.begin(), reply->data.begin() + static_cast<std::ptrdiff_t>(n), r.data.begin());
      else
        std::copy_n(reply->data.begin(), n, r.data.begin());
      r.size = static_cast<std::uint16_t>(n);
    }
  } else {
    r.ok = false;
    r.size = 0;
    if (reply != nullptr) {
      const PnioStatus& s = reply->status;
      r.error_code = std::uint32_t{s.code} << 24 | std::uint32_t{s.decode} << 16 | std::uint32_t{s.code1} << 8 |
                     std::uint32_t{s.code2};
      why = reply->text;
    }
    r.error.format("station \"%s\": %.*s", d.station.name.c_str(), static_cast<int>(why.size()), why.data());
  }
  // record() took it only with room in the ring.
  record_replies_[(record_head_ + record_count_) % record_replies_.size()] = r;
  ++record_count_;
}

bool ProfinetBus::next_record_reply(core::ParamReply& out) noexcept {
  if (record_count_ == 0) return false;
  out = record_replies_[record_head_];
  record_head_ = (record_head_ + 1) % record_replies_.size();
  --record_count_;
  return true;
}

// --- the cyclic path ---------------------------------------------------------------------------------

void ProfinetBus::handle_link(core::TimePoint now) noexcept {
  const link::LinkState s = transport_.frames->poll_state(now);
  if (s == link_seen_) return;
  link_seen_ = s;
  if (s == link::LinkState::Up) return;  // the devices waiting search again after their back-off
  core::Text why;
  why.format("the Ethernet link is down (%s)", link::to_string(s));
  for (auto& d : devices_) {
    if (d->phase == Phase::Connect || d->phase == Phase::Running) {
      lose(*d, why.view(), now);
    } else if (d->phase == Phase::Find) {
      d->finder.reset();
      set_detail(*d, "%s", why.c_str());
      enter(*d, Phase::Wait, now);
    }
  }
}

void ProfinetBus::receive(core::TimePoint now) noexcept {
  if (!open_) return;
  last_now_ = now;
  if (transport_.peer) transport_.peer->step(now);
  handle_link(now);
  for (;;) {
    const std::size_t n = transport_.frames->receive(rx_);
    for (std::size_t i = 0; i < n; ++i) dispatch_frame(rx_[i].view(), now);
    if (n < rx_.size()) break;
  }
  while (transport_.client->receive_from(datagram_)) dispatch_datagram(datagram_, CmSocket::Client, now);
  while (transport_.server->receive_from(datagram_)) dispatch_datagram(datagram_, CmSocket::Server, now);
  for (auto& d : devices_) {
    step(*d, now);
    flush_datagrams();
  }
}

void ProfinetBus::transmit(core::TimePoint now) noexcept {
  if (!open_) return;
  for (auto& dp : devices_) {
    Device& d = *dp;
    if (d.finder) {
      while (const std::size_t n = d.finder->poll(now, tx_)) send_frame(std::span<const std::uint8_t>(tx_).first(n));
    } else if (d.dcp) {
      while (const std::size_t n = d.dcp->poll(now, tx_)) send_frame(std::span<const std::uint8_t>(tx_).first(n));
    }
    if (d.cm) d.cm->poll(now, out_);
    if (d.cyclic) {
      if (d.io) {
        const IoDevice& io = io_[*d.io];
        std::size_t at = 0;
        for (const std::size_t sub : io.submodules) {
          const auto out = d.provider->data(sub);
          std::copy_n(io.outputs.begin() + static_cast<std::ptrdiff_t>(at), out.size(), out.begin());
          at += out.size();
        }
      }
      while (const std::size_t n = d.provider->poll(now, tx_)) send_frame(std::span<const std::uint8_t>(tx_).first(n));
      while (const std::size_t n = d.alarms->poll(now, tx_)) send_frame(std::span<const std::uint8_t>(tx_).first(n));
    }
    flush_datagrams();
  }
}

void ProfinetBus::send_frame(std::span<const std::uint8_t> frame) noexcept {
  const link::SendResult r = transport_.frames->send(frame);
  if (r.sent == 1)
    sent_.fetch_add(1, std::memory_order_relaxed);
  else
    errors_.fetch_add(1, std::memory_order_relaxed);
}

void ProfinetBus::dispatch_frame(std::span<const std::uint8_t> frame, core::TimePoint now) noexcept {
  received_.fetch_add(1, std::memory_order_relaxed);
  const EthernetView v = decode_ethernet(frame);
  if (!v.ok()) {
    dropped_.fetch_add(1, std::memory_order_relaxed);
    return;
  }
  if (is_dcp(v.frame_class)) {
    bool taken = false;
    for (auto& d : devices_)
      if (d->finder) taken = d->dcp->on_frame(frame, now) || taken;
    if (!taken) dropped_.fetch_add(1, std::memory_order_relaxed);
    return;
  }
  for (auto& d : devices_) {
    if (!d->cyclic || d->mac != v.header.src) continue;
    bool taken = false;
    if (v.frame_class == FrameClass::RtCyclic)
      taken = d->consumer->on_frame(frame, now);
    else if (v.frame_class == FrameClass::AlarmHigh || v.frame_class == FrameClass::AlarmLow)
      taken = d->alarms->on_frame(frame, now);
    if (!taken) dropped_.fetch_add(1, std::memory_order_relaxed);
    return;
  }
  dropped_.fetch_add(1, std::memory_order_relaxed);
}

void ProfinetBus::dispatch_datagram(const link::Datagram& g, CmSocket socket, core::TimePoint now) noexcept {
  const std::uint32_t ip = ipv4_host(g.from.address);
  for (auto& d : devices_) {
    if (!d->cm || d->ip != ip) continue;
    d->cm->on_datagram(g.view(), UdpEndpoint{ip, g.from.port}, socket, now, out_);
    flush_datagrams();  // the outbox holds 8: a burst of answers (every device's Connect) must not fill it
    return;
  }
  dropped_.fetch_add(1, std::memory_order_relaxed);
}

void ProfinetBus::flush_datagrams() noexcept {
  while (!out_.empty()) {
    const CmDatagram& g = out_.front();
    link::DatagramPort& port = g.from == CmSocket::Server ? *transport_.server : *transport_.client;
    const link::DatagramStatus s = port.send_to(link::Ipv4Endpoint{ipv4_octets(g.to.ip), g.to.port},
                                                std::span<const std::uint8_t>(g.bytes).first(g.size));
    if (s != link::DatagramStatus::Sent) errors_.fetch_add(1, std::memory_order_relaxed);
    out_.pop();
  }
}

// --- what the runner reads ----------------------------------------------------------------------------

core::LinkState ProfinetBus::link_state(std::size_t axis) const noexcept {
  return devices_[axes_[axis]->device]->link.load(std::memory_order_relaxed);
}

std::string_view ProfinetBus::link_detail(std::size_t axis) const noexcept {
  return devices_[axes_[axis]->device]->detail.view();
}

void ProfinetBus::push_event(const core::Event& e) noexcept { (void)events_.push(e); }

bool ProfinetBus::next_event(core::Event& out) noexcept { return events_.pop(out); }

core::BusCounters ProfinetBus::counters() const noexcept {
  core::BusCounters c;
  c.frames_sent = sent_.load(std::memory_order_relaxed);
  c.frames_received = received_.load(std::memory_order_relaxed);
  c.frames_lost = lost_.load(std::memory_order_relaxed);
  c.frames_dropped = dropped_.load(std::memory_order_relaxed);
  c.errors = errors_.load(std::memory_order_relaxed);
  return c;
}

core::IoInfo ProfinetBus::io_info(std::size_t k) const noexcept {
  core::IoInfo out;
  if (k >= io_.size()) return out;
  out.name = io_[k].name;
  out.address = static_cast<std::uint32_t>(k + 1);
  out.input_size = io_[k].input_size;
  out.output_size = io_[k].output_size;
  out.sized = true;
  return out;
}

void ProfinetBus::io_read(std::size_t k, core::IoSnapshot& out) noexcept {
  out.valid = false;
  out.input_size = 0;
  out.output_size = 0;
  if (k >= io_.size()) return;
  const IoDevice& io = io_[k];
  const Device& d = *devices_[io.device];
  bool good = d.exchanging();
  std::size_t at = 0;
  if (d.consumer) {
    for (const std::size_t sub : io.submodules) {
      const auto in = d.consumer->data(sub);
      std::copy(in.begin(), in.end(), out.inputs.begin() + static_cast<std::ptrdiff_t>(at));
      at += in.size();
      if (!in.empty() && !iox_status::is_good(d.consumer->iops(sub))) good = false;
    }
  }
  out.input_size = static_cast<std::uint16_t>(at);
  std::copy_n(io.outputs.begin(), io.output_size, out.outputs.begin());
  out.output_size = static_cast<std::uint16_t>(io.output_size);
  out.valid = good;
}

core::IoWriteStatus ProfinetBus::io_write(std::size_t k, std::size_t offset, std::span<const std::uint8_t> bytes) noexcept {
  if (k >= io_.size()) return core::IoWriteStatus::UnknownSlave;
  IoDevice& io = io_[k];
  if (!devices_[io.device]->exchanging()) return core::IoWriteStatus::SlaveLost;
  if (bytes.empty() || offset > io.output_size || bytes.size() > io.output_size - offset) return core::IoWriteStatus::OutOfRange;
  std::copy(bytes.begin(), bytes.end(), io.outputs.begin() + static_cast<std::ptrdiff_t>(offset));
  return core::IoWriteStatus::Ok;
}

// --- the factory -----------------------------------------------------------------------------------------

std::unique_ptr<ProfinetBus> make_profinet_bus(const config::BusPlan& plan) {
  const auto& o = plan.section<config::ProfinetBusOptions>();
  if (o.simulated) return make_simulated_profinet_bus(plan);
  ProfinetTransport t;
  link::RawSocketOptions raw;
  raw.interface = o.interface;
  t.frames = std::make_unique<link::RawSocketLink>(kFrameRules, raw);
  t.client = std::make_unique<link::UdpEndpoint>(rpc_udp_options(o.interface));
  t.server = std::make_unique<link::UdpEndpoint>(rpc_udp_options(o.interface, kRpcUdpPort));
  t.interface = o.interface;
  return std::make_unique<ProfinetBus>(plan, std::move(t));
}

}  // namespace drivegate::profinet
