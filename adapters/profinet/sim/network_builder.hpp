#pragma once
// A simulated PROFINET network made from a config's profinet bus (issue 10 "Simulator"), shared by
// drivegate-sim and the tests: one PnDevice per station of the bus (`devices:`), in the order the
// config lists them, each with the persona of what uses the station:
//
//   an axis      the persona its device profile names (only kollmorgen-akd-profinet: an
//                AkdPersona with the axis' telegram plugged in slot 1); another profile is refused
//   an io: entry a GenericIoPersona: the DAP in slot 0 (module = the entry's DAP ident, one
//                submodule without IO in subslot 1 with the entry's dap_submodule_ident) and the entry's
//                submodules with their idents and input/output lengths, API 0
//   nothing      (the config warns) a GenericIoPersona with only a DAP (ident kSimDapModule)
//
// Every device has a locally administered MAC derived from the bus and station index
// (sim_station_mac), its NameOfStation stored as an engineering tool leaves it (permanent: it
// survives a power cycle) and no IP address: the controller gives it the configured one by DCP
// (temporary by default: after a power loss it is gone and the controller sets it again). The
// vendor and device ID are the station's when the config states them (the controller checks
// them), else the persona's [sim] ones.
//
// Building allocates; the devices do not afterwards (pn_device.hpp).
#include <cstddef>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "adapters/profinet/sim/akd_persona.hpp"
#include "adapters/profinet/sim/generic_io_persona.hpp"
#include "adapters/profinet/sim/pn_sim_network.hpp"
#include "config/plan.hpp"

namespace drivegate::profinet {

// A bus the builder cannot make a network of; what() is one sentence naming the bus and station.
class PnBuildError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The device profile whose stations get an AkdPersona (the only PROFINET drive persona).
inline constexpr std::string_view kAkdProfinetProfile = "kollmorgen-akd-profinet";
inline constexpr std::string_view kGenericIoPersona = "generic-io";
// [sim] Identities of the simulated devices where the config states none: the digest gives no
// PROFINET vendor or device ID for the AKD (akd-profinet-profidrive.md §4.1).
inline constexpr std::uint16_t kSimAkdVendorId = 0x0118;
inline constexpr std::uint16_t kSimAkdDeviceId = 0x0501;
inline constexpr std::uint16_t kSimIoVendorId = 0x00FE;
inline constexpr std::uint16_t kSimIoDeviceId = 0x0001;
// [sim] The DAP of a generic device: the config gives the module ident only (dap_ident).
inline constexpr std::uint32_t kSimDapModule = 0x00000001;
inline constexpr std::uint32_t kSimDapSubmodule = 0x00000001;

// 02:50:4E:BB:SS:SS (locally administered; "PN"), BB the bus' index among the plan's profinet
// buses, SSSS the station's index on the bus + 1. Throws PnBuildError beyond 256 buses or 65535
// stations.
MacAddress sim_station_mac(std::size_t bus_index, std::size_t station_index);

// One station of a built network.
struct PnSimStation {
  std::string name;     // the config's NameOfStation
  std::string persona;  // kAkdProfinetProfile or kGenericIoPersona
  std::string used_by;  // "axis x", "io panel", "" (no user)
  std::unique_ptr<PnPersona> persona_impl;
  AkdPersona* akd = nullptr;            // the persona as an AKD, or null
  GenericIoPersona* io = nullptr;       // the persona as generic IO, or null
  PnDevice* device = nullptr;
};

class BuiltPnNetwork {
 public:
  explicit BuiltPnNetwork(std::string bus) : bus_(std::move(bus)) {}
  BuiltPnNetwork(const BuiltPnNetwork&) = delete;
  BuiltPnNetwork& operator=(const BuiltPnNetwork&) = delete;

  // Adds a device for `station` with its persona; throws as PnSimNetwork::add does.
  PnSimStation& add(std::unique_ptr<PnSimStation> station, const PnDeviceConfig& config);

  [[nodiscard]] const std::string& bus() const noexcept { return bus_; }
  [[nodiscard]] PnSimNetwork& network() noexcept { return network_; }
  [[nodiscard]] std::size_t size() const noexcept { return stations_.size(); }
  [[nodiscard]] PnSimStation& station(std::size_t i) noexcept { return *stations_[i]; }
  [[nodiscard]] const PnSimStation& station(std::size_t i) const noexcept { return *stations_[i]; }
  // The station with this config name, or null.
  [[nodiscard]] PnSimStation* find(std::string_view name) noexcept;

 private:
  std::string bus_;
  std::vector<std::unique_ptr<PnSimStation>> stations_;  // the personas outlive the network's devices
  PnSimNetwork network_;
};

// The network of `bus` (a profinet plan), `bus_index` its index among the plan's profinet buses
// (for the MACs). Throws PnBuildError for an axis whose device profile has no simulated persona
// (naming the one there is) or a telegram the simulated AKD lacks.
std::unique_ptr<BuiltPnNetwork> build_pn_network(const config::BusPlan& bus, std::size_t bus_index);

}  // namespace drivegate::profinet
