#include "adapters/ethercat/sim/line_builder.hpp"

#include <map>
#include <utility>

#include "config/ethercat/plan.hpp"

namespace drivegate::ethercat::sim {

BuiltLine::BuiltLine(std::string bus, SimLineConfig config)
    : bus_(std::move(bus)), link_(16), line_(link_, config) {}

std::size_t BuiltLine::add(SlaveRequest request, SimSlaveParts parts) {
  auto s = std::make_unique<SimSlave>();
  s->position = request.position;
  s->persona = std::move(request.persona);
  s->name = std::move(request.name);
  s->parts = std::move(parts);
  // The identity as the master will read it: parse the image now, and refuse one that does not
  // parse (a factory's bug, better seen here than as a master's SII error).
  auto info = std::make_unique<SiiInfo>();
  parse_sii(s->parts.sii, *info);
  if (!info->ok())
    throw LineBuildError("bus " + bus_ + " position " + std::to_string(s->position) + " (" + s->name +
                         "): the " + s->persona + " persona's SII image does not parse");
  s->identity = info->header.identity;
  s->esc = std::make_unique<EscSlave>(s->parts.esc, s->parts.sii, s->parts.app.get());
  line_.add(*s->esc);
  slaves_.push_back(std::move(s));
  stuck_.push_back(Stuck{});
  return slaves_.size() - 1;
}

void BuiltLine::open() { link_.open(); }

void BuiltLine::pass(FrameView frame, std::uint64_t now_ns) noexcept {
  if (corrupt_left_ > 0 && !corrupt_armed_) {
    --corrupt_left_;
    line_.corrupt_next();
    corrupt_armed_ = true;
  }
  // SimLine serves the frame to the slaves it reaches (SimLine::reachable(), fixed while the
  // frame passes) unless it drops it, loses it to the injected CRC error (at the first slave) or
  // finds it malformed: the counters tell which happened.
  const SimLineCounters before = line_.counters();
  const std::size_t reached = line_.reachable();
  line_.set_time(now_ns);
  link_.send(frame);
  const SimLineCounters& after = line_.counters();
  if (after.corrupted != before.corrupted) {
    corrupt_armed_ = false;
    if (reached > 0) ++slaves_[0]->frames_seen;
    return;
  }
  if (after.dropped != before.dropped || after.malformed != before.malformed || after.unreachable != before.unreachable ||
      after.frames == before.frames)
    return;
  for (std::size_t k = 0; k < reached; ++k) ++slaves_[k]->frames_seen;
}

void BuiltLine::power_off(std::size_t index) noexcept {
  if (index >= slaves_.size()) return;
  slaves_[index]->powered = false;
  line_.power_off(index);
}

void BuiltLine::power_on(std::size_t index) {
  if (index >= slaves_.size() || slaves_[index]->powered) return;
  SimSlave& s = *slaves_[index];
  s.powered = true;
  line_.power_on(index);
  if (s.parts.power_on) s.parts.power_on();
  // A stuck slave stays stuck over a power cycle: the fault stands for the device, not its state.
  if (stuck_[index].highest != AlState::Op) s.esc->limit_state(stuck_[index].highest, stuck_[index].code);
}

void BuiltLine::break_after(std::size_t index) noexcept {
  if (index >= slaves_.size()) return;
  broken_after_ = index;
  line_.break_after(index);
}

void BuiltLine::mend() noexcept {
  broken_after_.reset();
  line_.repair_cable();
}

void BuiltLine::stick(std::size_t index, AlState highest, std::uint16_t code) noexcept {
  if (index >= slaves_.size()) return;
  stuck_[index] = Stuck{highest, code};
  line_.stick(index, highest, code);
}

std::optional<AlState> BuiltLine::stuck_at(std::size_t index) const noexcept {
  if (index >= stuck_.size() || stuck_[index].highest == AlState::Op) return std::nullopt;
  return stuck_[index].highest;
}

namespace {

std::string axes_name(const std::vector<const config::AxisPlan*>& axes) {
  std::string s = axes.size() == 1 ? "axis " : "axes ";
  for (std::size_t i = 0; i < axes.size(); ++i) s += (i == 0 ? "" : ", ") + axes[i]->spec.name;
  return s;
}

}  // namespace

std::unique_ptr<BuiltLine> build_line(const config::BusPlan& bus, const PersonaRegistry& personas,
                                      SimLineConfig config) {
  const std::string where = "bus " + bus.name;
  // Position -> what the plan puts there.
  std::map<int, SlaveRequest> at;
  for (const auto& axis : bus.axes) {
    SlaveRequest& q = at[axis.address];
    if (q.io != nullptr)
      throw LineBuildError(where + " position " + std::to_string(axis.address) + ": axis " + axis.spec.name +
                           " and I/O slave " + q.io->name + " share it");
    if (q.device != nullptr && q.device->name != axis.device.name)
      throw LineBuildError(where + " position " + std::to_string(axis.address) + ": axes " + q.axes.front()->spec.name +
                           " and " + axis.spec.name + " share it with different devices");
    q.device = &axis.device;
    q.axes.push_back(&axis);
  }
  for (const auto& io : bus.section<config::EthercatBusOptions>().io) {
    SlaveRequest& q = at[io.position];
    if (q.io != nullptr || !q.axes.empty())
      throw LineBuildError(where + " position " + std::to_string(io.position) + ": I/O slave " + io.name +
                           " shares it with " + (q.io != nullptr ? "I/O slave " + q.io->name : axes_name(q.axes)));
    q.io = &io;
  }
  if (at.empty()) throw LineBuildError(where + ": no slaves (neither axes nor io: slaves)");

  auto line = std::make_unique<BuiltLine>(bus.name, config);
  int expected = 1;
  std::uint32_t serial = 1;
  for (auto& [position, q] : at) {
    if (position != expected)
      throw LineBuildError(where + ": no slave at position " + std::to_string(expected) + " (the next is at " +
                           std::to_string(position) + "); a simulated line has a slave at every position from 1 on");
    ++expected;
    q.bus = bus.name;
    q.position = static_cast<std::size_t>(position);
    q.serial = serial++;
    if (q.io != nullptr) {
      q.persona = std::string(kGenericIoPersona);
      q.name = "io " + q.io->name;
    } else {
      q.persona = q.device->section<config::EthercatDeviceSpec>().persona;
      q.name = axes_name(q.axes);
    }
    const PersonaFactory* make = personas.find(q.persona);
    const std::string what = where + " position " + std::to_string(position) + " (" + q.name + ")";
    if (make == nullptr)
      throw LineBuildError(what + ": no simulated persona \"" + q.persona + "\" in this build (known: " +
                           personas.names() + ")");
    SimSlaveParts parts;
    try {
      parts = (*make)(q);
    } catch (const LineBuildError&) {
      throw;
    } catch (const std::exception& e) {
      throw LineBuildError(what + ": " + e.what());
    }
    line->add(std::move(q), std::move(parts));
  }
  line->open();
  return line;
}

}  // namespace drivegate::ethercat::sim
