#include "adapters/canopen/boot_plan.hpp"

#include <chrono>

#include "adapters/canopen/wire/cob_id.hpp"
#include "adapters/canopen/wire/pdo_mapping.hpp"

namespace drivegate::canopen {
namespace {

using cia402::DataType;
using cia402::ObjectDef;

ObjectDef u8(std::uint16_t index, std::uint8_t sub) { return {{index, sub}, DataType::U8}; }
ObjectDef i8(std::uint16_t index, std::uint8_t sub) { return {{index, sub}, DataType::I8}; }
ObjectDef u16(std::uint16_t index, std::uint8_t sub) { return {{index, sub}, DataType::U16}; }
ObjectDef u32(std::uint16_t index, std::uint8_t sub) { return {{index, sub}, DataType::U32}; }

long long ms(core::Duration d) { return std::chrono::duration_cast<std::chrono::milliseconds>(d).count(); }

struct Steps {
  std::vector<BootStep> list;
  void write(std::string stage, ObjectDef def, std::int64_t value, bool optional = false, std::string why = {}) {
    list.push_back({BootStep::Kind::Write, def, value, 0xFFFFFFFF, optional, std::move(stage), std::move(why), 0, 0, 0, 0});
  }
  void seed(ObjectDef def) {
    list.push_back({BootStep::Kind::Seed, def, 0, 0xFFFFFFFF, true, "process image", {}, 0, 0, 0, 0});
  }
  void expect(std::string stage, ObjectDef def, std::int64_t value, std::uint32_t mask = 0xFFFFFFFF,
              std::string why = {}) {
    list.push_back({BootStep::Kind::Expect, def, value, mask, false, std::move(stage), std::move(why), 0, 0, 0, 0});
  }
  void probe(std::string stage, ObjectDef def, std::uint8_t sets) {
    list.push_back({BootStep::Kind::Probe, def, 0, 0xFFFFFFFF, true, std::move(stage), {}, sets, 0, 0, 0});
  }
  void fail(std::string stage, std::string why) {
    list.push_back({BootStep::Kind::Fail, {}, 0, 0xFFFFFFFF, false, std::move(stage), std::move(why), 0, 0, 0, 0});
  }
};

const config::PdoSpec* find_pdo(const std::vector<config::PdoSpec>& pdos, int number) {
  for (const auto& p : pdos)
    if (p.number == number) return &p;
  return nullptr;
}

// One direction's PDOs. CiA 301 §7.5.2.35/36 and AKD part 1 §12.6: invalidate (bit 31), clear
// the count, write the entries, set the count, set the communication parameters, validate.
void pdo_steps(Steps& s, const config::CanopenDeviceSpec& dev, bool transmit, NodeId node) {
  const auto& pdos = transmit ? dev.tpdos : dev.rpdos;
  for (int n = 0; n < 4; ++n) {
    const std::uint16_t comm = transmit ? tpdo_comm_index(n) : rpdo_comm_index(n);
    const std::uint16_t map = transmit ? tpdo_map_index(n) : rpdo_map_index(n);
    // TPDOs: no RTR (bit 30), as the AKD's own procedure writes them (AKD part 1 §14 vectors 3, 8).
    const std::uint32_t cob = (transmit ? cob::tpdo(n, node) : cob::rpdo(n, node)) | (transmit ? cob::kNoRtr : 0U);
    const std::string name = std::string(transmit ? "TPDO" : "RPDO") + std::to_string(n + 1);
    const config::PdoSpec* p = find_pdo(pdos, n + 1);
    if (dev.pdo_policy == config::PdoPolicy::Verify) {
      if (!p) continue;
      const std::string stage = name + " verification";
      const std::string why = "this drive's mapping is fixed or needs save and restart: set it in the drive's tool";
      for (std::size_t k = 0; k < p->entries.size(); ++k)
        s.expect(stage, u32(map, static_cast<std::uint8_t>(k + 1)),
                 encode_mapping({p->entries[k].object, p->entries[k].bits}), 0xFFFFFFFF, why);
      s.expect(stage, u8(comm, 2), p->transmission_type, 0xFF, why);
      s.expect(stage, u32(comm, 1), cob & cob::kIdMask, cob::kInvalid | cob::kIdMask, why);
      continue;
    }
    if (!p) {
      // Unused PDOs are switched off so drive defaults (e.g. AKD event-driven TPDO3/4) do not flood
      // the bus (AKD part 1 §16 step 7). A drive with fewer PDOs may lack the object.
      if (dev.disable_unused_pdos) s.write(name + " disable", u32(comm, 1), cob | cob::kInvalid, true);
      continue;
    }
    const std::string stage = name + " mapping";
    s.write(stage, u32(comm, 1), cob | cob::kInvalid);
    s.write(stage, u8(map, 0), 0);
    for (std::size_t k = 0; k < p->entries.size(); ++k)
      s.write(stage, u32(map, static_cast<std::uint8_t>(k + 1)), encode_mapping({p->entries[k].object, p->entries[k].bits}));
    s.write(stage, u8(map, 0), static_cast<std::int64_t>(p->entries.size()));
    s.write(stage, u8(comm, 2), p->transmission_type);
    if (transmit && p->inhibit_time_100us > 0) s.write(stage, u16(comm, 3), p->inhibit_time_100us);
    if (transmit && p->event_timer_ms > 0) s.write(stage, u16(comm, 5), p->event_timer_ms);
    s.write(stage, u32(comm, 1), cob);
  }
}

}  // namespace

std::vector<BootStep> build_boot_steps(const config::AxisPlan& axis, const config::BusPlan& bus) {
  Steps s;
  const auto& dev = axis.device.section<config::CanopenDeviceSpec>();
  const auto node = static_cast<NodeId>(axis.address);
  const auto& opt = bus.section<config::CanopenBusOptions>();

  // Identity (AKD part 1 §16 step 4, SD6 gateway step B3).
  if (dev.device_type)
    s.expect("identity", u32(0x1000, 0), *dev.device_type, dev.device_type_mask,
             "device type (1000h) of a " + axis.device.name);
  if (axis.device.identity.vendor_id)
    s.expect("identity", u32(0x1018, 1), *axis.device.identity.vendor_id, 0xFFFFFFFF,
             "vendor-ID (1018h:01) of a " + axis.device.name);
  if (axis.device.identity.product_code)
    s.expect("identity", u32(0x1018, 2), *axis.device.identity.product_code, 0xFFFFFFFF,
             "product code (1018h:02) of a " + axis.device.name);

  for (const auto& w : dev.startup_writes) s.write("start-up write", w.def, w.value, false, w.why);
  for (const auto& w : axis.section<config::CanopenAxisOptions>().startup_writes)
    s.write("start-up write (axis)", w.def, w.value, false, w.why);

  pdo_steps(s, dev, false, node);
  pdo_steps(s, dev, true, node);

  // SYNC period: 1006h in us (SD6 §6.1 wants it to match A150); optional, not every drive has it.
  if (opt.sync)
    s.write("SYNC", u32(0x1006, 0),
            std::chrono::duration_cast<std::chrono::microseconds>(bus.cycle_time).count(), true);
  // ip/csp interpolation period = SYNC period, whole ms, both sub-indices (AKD part 2 §14 step 5).
  const bool cyclic_position = axis.device.modes.contains(core::Mode::InterpolatedPosition) ||
                               axis.device.modes.contains(core::Mode::CyclicPosition);
  const auto cycle_ms = ms(bus.cycle_time);
  if (cyclic_position && cycle_ms >= 1 && bus.cycle_time == std::chrono::milliseconds(cycle_ms)) {
    s.write("interpolation period", u8(0x60C2, 1), cycle_ms, true);
    s.write("interpolation period", i8(0x60C2, 2), -3, true);
  }

  // The drive's present values of what the gateway sends it cyclically (except the controlword,
  // which the profile owns from the first cycle).
  for (const auto& p : dev.rpdos)
    for (const auto& e : p.entries)
      if (e.object != cia402::obj::kControlword.id) s.seed({e.object, e.type});

  // Error control (AKD part 1 §16 step 10; SD6 gateway step B6: exactly one of the two). With
  // gateway_watch required / optional the drive is asked first what it has (1016h, else 100Ch and
  // 100Dh) and the steps of the one it has run; the others are skipped.
  const auto watch = config::gateway_watch_of(axis);
  const auto timeout = ms(opt.heartbeat_period) * opt.heartbeat_misses;
  const std::int64_t consumer_entry = (std::int64_t{opt.gateway_node_id} << 16) | timeout;
  const char* const kConsumerWhy = "consumer heartbeat: the drive stops when the gateway is silent";
  if (watch == config::GatewayWatch::Heartbeat) {
    s.write("error control", u16(0x1017, 0), ms(opt.drive_heartbeat));
    // The drive watches the gateway: timeout well above the gateway's heartbeat period.
    s.write("error control", u32(0x1016, 1), consumer_entry, false,
            std::string(kConsumerWhy) + " (gateway_watch: heartbeat demands 1016h)");
  } else if (watch == config::GatewayWatch::Guarding) {
    s.write("error control", u16(0x1017, 0), 0, true, "heartbeat off: guarding and heartbeat are exclusive");
    s.write("error control", u16(0x100C, 0), ms(opt.guard_time));
    s.write("error control", u8(0x100D, 0), opt.life_time_factor);
  } else {
    const auto branch = [&](std::uint8_t if_found, std::uint8_t if_missing) {
      s.list.back().if_found = if_found;
      s.list.back().if_missing = if_missing;
    };
    s.probe("error control", u8(0x1016, 0), kFoundConsumerHeartbeat);
    // 1016h: heartbeat both ways. A drive may have 1016h and still refuse the gateway's entry
    // (06010002h read-only: a fixed entry, 06090030h: a producer or time it does not take,
    // 08000020h); it is then treated like a drive without 1016h.
    s.write("error control", u16(0x1017, 0), ms(opt.drive_heartbeat));
    branch(kFoundConsumerHeartbeat, 0);
    s.write("error control", u32(0x1016, 1), consumer_entry, false, kConsumerWhy);
    branch(kFoundConsumerHeartbeat, 0);
    s.list.back().refused = kFoundConsumerHeartbeat;
    s.list.back().sets = kConsumerHeartbeatRefused;
    s.probe("error control", u16(0x100C, 0), kFoundGuardTime);
    branch(0, kFoundConsumerHeartbeat);
    s.probe("error control", u8(0x100D, 0), kFoundGuarding);
    branch(kFoundGuardTime, kFoundConsumerHeartbeat);
    // No usable 1016h, but 100Ch and 100Dh: node guarding.
    s.write("error control", u16(0x1017, 0), 0, true, "heartbeat off: guarding and heartbeat are exclusive");
    branch(kFoundGuarding, 0);
    s.write("error control", u16(0x100C, 0), ms(opt.guard_time));
    branch(kFoundGuarding, 0);
    s.write("error control", u8(0x100D, 0), opt.life_time_factor);
    branch(kFoundGuarding, 0);
    // Neither.
    const std::string who = "node " + std::to_string(axis.address);
    const std::string no_guarding = " 100Ch/100Dh (node guarding), so it would not stop if the gateway died";
    if (watch == config::GatewayWatch::Required) {
      s.fail("error control", who + " has neither 1016h (consumer heartbeat) nor" + no_guarding +
                                  " (gateway_watch: required)");
      branch(0, kFoundConsumerHeartbeat | kFoundGuarding | kConsumerHeartbeatRefused);
      s.fail("error control", who + " refused 1016h:01 (consumer heartbeat) and has no" + no_guarding +
                                  " (gateway_watch: required)");
      branch(kConsumerHeartbeatRefused, kFoundGuarding);
    } else {
      // The drive's heartbeat (already on when only the 1016h:01 entry was refused).
      s.write("error control", u16(0x1017, 0), ms(opt.drive_heartbeat));
      branch(0, kFoundConsumerHeartbeat | kFoundGuarding | kConsumerHeartbeatRefused);
    }
  }
  return std::move(s.list);
}

WatchOutcome watch_outcome(config::GatewayWatch watch, std::uint8_t found) noexcept {
  switch (watch) {
    case config::GatewayWatch::Heartbeat: return WatchOutcome::Heartbeat;
    case config::GatewayWatch::Guarding: return WatchOutcome::Guarding;
    default: break;
  }
  if ((found & kFoundConsumerHeartbeat) != 0) return WatchOutcome::Heartbeat;
  if ((found & kFoundGuarding) != 0) return WatchOutcome::Guarding;
  return WatchOutcome::Unwatched;
}

NodePdoConfig build_pdo_config(const config::AxisPlan& axis, core::Duration rpdo_refresh) {
  NodePdoConfig out;
  const auto node = static_cast<NodeId>(axis.address);
  const auto& dev = axis.device.section<config::CanopenDeviceSpec>();
  auto layout_of = [](const config::PdoSpec& p) {
    PdoLayout l;
    for (const auto& e : p.entries) (void)l.add({e.object, e.type}, e.bits);
    return l;
  };
  for (const auto& p : dev.rpdos) {
    RpdoConfig c;
    c.cob_id = cob::rpdo(p.number - 1, node);
    c.layout = layout_of(p);
    c.transmission_type = static_cast<std::uint8_t>(p.transmission_type);
    c.dlc = static_cast<std::uint8_t>(p.dlc);
    c.refresh = rpdo_refresh;
    out.rpdos.push_back(c);
  }
  for (const auto& p : dev.tpdos) {
    TpdoConfig c;
    c.cob_id = cob::tpdo(p.number - 1, node);
    c.layout = layout_of(p);
    c.transmission_type = static_cast<std::uint8_t>(p.transmission_type);
    c.event_timer = std::chrono::milliseconds(p.event_timer_ms);
    out.tpdos.push_back(c);
  }
  return out;
}

}  // namespace drivegate::canopen
