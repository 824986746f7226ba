#pragma once
// The simulator's persona factories: how a slave of a config's ethercat bus becomes a simulated
// slave (issue 9 "Simulator"). A device profile names its persona (`ethercat.persona`); an `io:`
// slave of the bus is the `generic-io` persona. A factory gets the plan's view of one position
// (SlaveRequest) and returns the parts of a slave (SimSlaveParts): the application behind the PDI
// (SlaveApplication), the SII EEPROM image and the EscConfig the application wants. The line
// builder (line_builder.hpp) puts an EscSlave on them and the slave on the line.
//
// PersonaRegistry::builtin() has `generic-io` (GenericIoSlave). The CiA 402 drive personas
// (`esr-triodrive`, `generic-cia402`: sim/cia402_slave.hpp) register there too, in
// sim_personas.cpp, as make_cia402_slave(name, options) -> { app, app->sii(), app->esc_config(),
// power_on = app->power_cycle() }.
//
// Factories run while the line is built (they may allocate and throw); nothing here runs while
// frames pass.
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "adapters/ethercat/sim/esc_slave.hpp"
#include "config/ethercat/plan.hpp"
#include "config/plan.hpp"

namespace drivegate::ethercat::sim {

// The persona of an I/O slave (`io:` of an ethercat bus).
inline constexpr std::string_view kGenericIoPersona = "generic-io";

// Identity of a simulated generic I/O slave whose `io:` entry names none: a vendor ID no
// manufacturer holds (ETG assigns IDs; this one marks the simulator) and product "IO" in ASCII.
inline constexpr std::uint32_t kSimIoVendorId = 0x00000DD5;
inline constexpr std::uint32_t kSimIoProductCode = 0x0000494F;
// Process data bytes of a simulated I/O slave whose `io:` entry gives no size.
inline constexpr int kSimIoDefaultBytes = 1;

// One position of the plan's line, as a factory sees it.
struct SlaveRequest {
  std::string bus;              // the bus' name
  std::size_t position = 0;     // 1 = the slave next to the gateway
  std::string persona;          // the factory's name
  std::string name;             // "io panel", "axis x", "axes x, y": for messages and status
  // A drive: its axes (one per slave axis, at least one) and their device profile. Null for I/O.
  std::vector<const config::AxisPlan*> axes;
  const config::DeviceProfile* device = nullptr;
  // An I/O slave: its `io:` entry. Null for a drive.
  const config::EthercatIoSlave* io = nullptr;
  std::uint32_t serial = 0;     // SII serial number (the builder numbers slaves 1, 2, ...)
};

// A slave a factory made.
struct SimSlaveParts {
  std::unique_ptr<SlaveApplication> app;  // may be null: an ESC without an application
  std::vector<std::uint8_t> sii;          // the EEPROM image (build_sii)
  EscConfig esc{};
  // The application's own power-on reset, run when the slave gets power back (the ESC restarts on
  // its own: SimLine::power_on). Empty: the application keeps its state.
  std::function<void()> power_on;
};

// Makes one slave; throws std::invalid_argument with a sentence when it cannot.
using PersonaFactory = std::function<SimSlaveParts(const SlaveRequest& request)>;

class PersonaRegistry {
 public:
  // The personas of this build: generic-io (and the drive personas once they are linked in).
  static PersonaRegistry builtin();
  // Adds or replaces the factory of `name`.
  void add(std::string name, PersonaFactory factory);
  // Null when there is none of that name.
  [[nodiscard]] const PersonaFactory* find(std::string_view name) const noexcept;
  // The names, in the order they were added, comma separated (for messages).
  [[nodiscard]] std::string names() const;

 private:
  struct Entry {
    std::string name;
    PersonaFactory make;
  };
  std::vector<Entry> entries_;
};

// The generic-io factory: GenericIoSlave with the `io:` entry's sizes (kSimIoDefaultBytes when not
// given) and identity (kSimIoVendorId / kSimIoProductCode when not given), revision 1.
SimSlaveParts make_generic_io(const SlaveRequest& request);

}  // namespace drivegate::ethercat::sim
