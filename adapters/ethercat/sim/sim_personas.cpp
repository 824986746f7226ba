#include "adapters/ethercat/sim/sim_personas.hpp"

#include <algorithm>
#include <stdexcept>
#include <utility>

#include "adapters/ethercat/sim/cia402_slave.hpp"
#include "adapters/ethercat/sim/generic_io.hpp"
#include "adapters/sim/sim_bus.hpp"
#include "config/ethercat/plan.hpp"

namespace drivegate::ethercat::sim {

namespace {

SimSlaveParts make_cia402_parts(const SlaveRequest& q) {
  Cia402SlaveOptions options;
  options.serial = q.serial;
  // Each axis' mechanics from its config axis (slave axis 0 first); a slave axis no config axis
  // names takes the first one's.
  std::vector<const config::AxisPlan*> by_axis(q.axes.begin(), q.axes.end());
  std::stable_sort(by_axis.begin(), by_axis.end(), [](const config::AxisPlan* a, const config::AxisPlan* b) {
    return a->section<config::EthercatAxisSpec>().slave_axis < b->section<config::EthercatAxisSpec>().slave_axis;
  });
  if (!by_axis.empty()) options.drive = drivegate::sim::drive_config_for(*by_axis.front());
  const int axes = q.device != nullptr ? q.device->section<config::EthercatDeviceSpec>().axes : 1;
  for (int n = 1; n < axes; ++n) {
    options.more_drives.push_back(options.drive);
    for (const config::AxisPlan* a : by_axis)
      if (a->section<config::EthercatAxisSpec>().slave_axis == n) options.more_drives.back() = drivegate::sim::drive_config_for(*a);
  }
  auto app = make_cia402_slave(q.persona, options);
  Cia402Slave* p = app.get();
  SimSlaveParts parts;
  parts.sii.assign(p->sii().begin(), p->sii().end());
  parts.esc = p->esc_config();
  parts.power_on = [p] { p->power_cycle(); };
  parts.app = std::move(app);
  return parts;
}

}  // namespace

PersonaRegistry PersonaRegistry::builtin() {
  PersonaRegistry r;
  r.add(std::string(kGenericIoPersona), make_generic_io);
  // The CiA 402 drives (sim/cia402_slave.hpp), with the first axis' mechanics.
  for (const char* name : {"esr-triodrive", "generic-cia402", "generic-cia402-2axis"})
    r.add(name, make_cia402_parts);
  return r;
}

void PersonaRegistry::add(std::string name, PersonaFactory factory) {
  for (auto& e : entries_) {
    if (e.name == name) {
      e.make = std::move(factory);
      return;
    }
  }
  entries_.push_back(Entry{std::move(name), std::move(factory)});
}

const PersonaFactory* PersonaRegistry::find(std::string_view name) const noexcept {
  for (const auto& e : entries_) {
    if (e.name == name) return &e.make;
  }
  return nullptr;
}

std::string PersonaRegistry::names() const {
  std::string s;
  for (const auto& e : entries_) s += (s.empty() ? "" : ", ") + e.name;
  return s;
}

SimSlaveParts make_generic_io(const SlaveRequest& request) {
  const config::EthercatIoSlave* io = request.io;
  const int inputs = io != nullptr && io->input_bytes ? *io->input_bytes : kSimIoDefaultBytes;
  const int outputs = io != nullptr && io->output_bytes ? *io->output_bytes : kSimIoDefaultBytes;
  // GenericIoSlave's SM2/SM3 sit 100h apart (1000h outputs, 1100h inputs) and its PDOs hold one
  // entry per byte: at most 256 bytes each way.
  if (inputs < 0 || inputs > 256 || outputs < 0 || outputs > 256)
    throw std::invalid_argument(request.name + ": a simulated generic-io slave has 0..256 input and output bytes, got " +
                                std::to_string(inputs) + " in, " + std::to_string(outputs) + " out");
  const SiiIdentity identity{io != nullptr && io->vendor_id ? *io->vendor_id : kSimIoVendorId,
                             io != nullptr && io->product_code ? *io->product_code : kSimIoProductCode, 1,
                             request.serial};
  auto app = std::make_unique<GenericIoSlave>(static_cast<std::size_t>(inputs), static_cast<std::size_t>(outputs),
                                              identity);
  SimSlaveParts parts;
  parts.sii.assign(app->sii().begin(), app->sii().end());
  parts.app = std::move(app);
  return parts;
}

}  // namespace drivegate::ethercat::sim
