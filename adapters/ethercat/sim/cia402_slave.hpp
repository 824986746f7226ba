#pragma once
// A simulated EtherCAT CiA 402 drive: the application behind an EscSlave (SlaveApplication) around
// the bus-neutral drive model (profiles/cia402/sim/drive_model.hpp), behaving as its persona says
// (ethercat_persona.hpp). It builds its own SII image and EscConfig.
//
// CoE object dictionary, first match wins [ETG.1000.6 §5.6; CiA 301; ETG.6010]:
//   1008h..100Ah  identity strings (VISIBLE_STRING, read-only)
//   1010h         store parameters (persona.store_parameters; "save" is accepted, nothing persists)
//   1C00h         SM communication types 1, 2, 3, 4 (read-only)
//   1600h..       RxPDO mapping objects the persona has; 1A00h.. TxPDO mapping objects
//   1C12h/1C13h   PDO assignment of SM2/SM3
//   1C32h/1C33h   SM output/input parameters (persona.sync_manager_parameters)
//   6007h         abort connection option code (INTEGER16)
//   the persona's hidden objects: 06020000h
//   the persona's manufacturer objects
//   the drive model's dictionary (1000h, 1001h, 1018h, 6xxxh), with the persona's types
//
// PDO rules [ETG.1000.6 PDO mapping/assignment objects; CiA 301 §7.5.2.36; dunker §7.2]:
//   - mapping objects and 1C12h/1C13h are written in PRE-OP (ESR: RxPDO mapping in SAFE-OP too),
//     else 08000022h;
//   - an entry (sub-index 1..n) is written only while sub-index 0 is 0, else 06010003h ("sub-index
//     cannot be written, SI0 must be 0 for write access", ETG.1000.6 SDO abort codes);
//   - a mapping entry must name an object the drive maps in that direction (the persona's
//     whitelist, the access, the exact bit length of its type) or be 0, else 06040041h;
//   - sub-index 0 := n needs n <= the persona's entry limit (06090031h), entries 1..n set
//     (06040041h) and at most process_data_capacity bytes (06040042h); sub-indexes beyond the
//     limit do not exist (06090011h);
//   - 1C12h/1C13h entries name an existing mapping object of the direction or 0 (06090030h).
// SM2/SM3 lengths follow the assignment (output_size()/input_size(); the ESC checks them at
// PRE-OP -> SAFE-OP: 001Dh/001Eh).
//
// Multi-axis slave (persona.axes > 1) [ETG.6010 §4 modular device profile]: one drive model per
// axis; axis n's profile objects (6000h..67FFh, 6007h among them) sit at + n x persona.axis_offset
// in the dictionary and in the PDOs; everything below 6000h (identity, PDO mapping and assignment,
// 1C32h/1C33h) is the slave's, answered from axis 0's model where the model holds it. The SM
// watchdog runs every axis' own 6007h reaction; a requested exit from OP (per persona) those of
// the axes that are Operation enabled. EMCYs of every axis go out through the one mailbox.
//
// Cycle (exchange(), after every frame): in OP the outputs are written to the mapped objects
// (outside OP they are not applied: the drive keeps its last values [dunker §5]); the model steps
// by the elapsed time in 1 ms steps (at most 1 s per call); the drive's EMCYs go to
// EscSlave::post_emergency; the inputs are read from the mapped objects. Leaving OP by the SM
// watchdog (or, per persona, on request while Operation enabled) runs the 6007h reaction: 1 = fault comm_loss_code (EMCY),
// 2 = disable voltage, 3 = quick stop, 0 = nothing. Nothing on this path allocates.
#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string_view>
#include <vector>

#include "adapters/ethercat/sim/esc_slave.hpp"
#include "adapters/ethercat/sim/ethercat_persona.hpp"
#include "adapters/ethercat/sim/object_dictionary.hpp"
#include "profiles/cia402/objects.hpp"
#include "profiles/cia402/sim/drive_model.hpp"
#include "profiles/cia402/sim/object_dictionary.hpp"

namespace drivegate::ethercat::sim {

// Process data layout of the persona's ESC (the SII's SyncM category says the same).
inline constexpr std::uint16_t kDriveMailboxOut = 0x1000;  // SM0
inline constexpr std::uint16_t kDriveMailboxIn = 0x1080;   // SM1
inline constexpr std::uint16_t kDriveMailboxSize = 128;
inline constexpr std::uint16_t kDriveOutputs = 0x1100;     // SM2
inline constexpr std::uint16_t kDriveInputs = 0x1500;      // SM3

struct Cia402SlaveOptions {
  std::uint32_t serial = 0;         // SII word 0Eh and 1018h:04
  std::uint16_t station_alias = 0;  // SII word 4
  // The drive model's mechanics; identity, device type, modes and the initial mode come from the
  // persona.
  cia402::sim::DriveModelConfig drive{};
  // Axes 1.. of a multi-axis persona: their mechanics, in axis order; an axis without one takes
  // `drive`'s.
  std::vector<cia402::sim::DriveModelConfig> more_drives;
  // The SII's CoE details offer SDO Information (bit 1); false: a drive whose SII does not, so a
  // master does not ask it for its object names [ETG.1000.6 Table 21].
  bool sdo_information = true;
};

struct Cia402SlaveCounters {
  std::uint64_t refused_pdo_values = 0;  // RxPDO values the drive refused (out of range, a mode it lacks)
  std::uint64_t emcy_dropped = 0;        // EMCYs the ESC's mailbox queue did not take
  std::uint64_t comm_losses = 0;         // 6007h reactions run
};

class Cia402Slave final : public SlaveApplication, private ObjectDictionary {
 public:
  static constexpr std::size_t kMaxEntries = 32;  // per mapping object
  static constexpr std::size_t kMaxPdos = 8;      // mapping objects per direction
  static constexpr std::size_t kMaxAssign = 8;    // 1C12h/1C13h sub-indexes
  static constexpr std::uint64_t kModelStepNs = 1'000'000;
  static constexpr std::uint64_t kMaxCatchUpNs = 1'000'000'000;
  static constexpr std::size_t kMaxAxes = 8;

  // Allocates here only. Throws std::invalid_argument for a persona table the drive cannot hold
  // (too many PDOs or entries, a default mapping it refuses, a broken SII profile).
  explicit Cia402Slave(const EthercatPersona& persona, Cia402SlaveOptions options = {});
  Cia402Slave(const Cia402Slave&) = delete;
  Cia402Slave& operator=(const Cia402Slave&) = delete;
  ~Cia402Slave() override;

  // --- SlaveApplication ------------------------------------------------------------------------
  std::size_t output_size() const noexcept override { return plan().output_bytes; }
  std::size_t input_size() const noexcept override { return plan().input_bytes; }
  void attach(EscSlave& esc) noexcept override { esc_ = &esc; }
  std::uint16_t on_state_change(AlState from, AlState to) noexcept override;
  void on_state_entered(AlState from, AlState to) noexcept override;
  void exchange(std::span<const std::uint8_t> outputs, std::span<std::uint8_t> inputs, AlState state,
                std::uint64_t now_ns) noexcept override;
  ObjectDictionary* object_dictionary() noexcept override { return this; }

  // --- The ESC this application wants ----------------------------------------------------------
  std::span<const std::uint8_t> sii() const noexcept { return sii_; }
  EscConfig esc_config() const noexcept;

  // --- Faults and environment ------------------------------------------------------------------
  // Power off and on (SimLine::power_off/on reset the ESC only; call this with it): every object
  // at its power-on value, the model power-cycled.
  void power_cycle() noexcept;
  // A drive fault whose cause persists until clear_fault_cause() (the model's inject_fault), on
  // one axis (out of range: ignored).
  void inject_fault(std::uint16_t code, std::size_t axis = 0) noexcept {
    if (axis >= axes_.size()) return;
    axes_[axis].injected = true;
    axes_[axis].model->inject_fault(code);
  }
  void clear_fault_cause(std::size_t axis = 0) noexcept {
    if (axis >= axes_.size()) return;
    axes_[axis].injected = false;
    axes_[axis].model->clear_fault_cause();
  }

  // --- Observation -----------------------------------------------------------------------------
  const EthercatPersona& persona() const noexcept { return persona_; }
  std::size_t axes() const noexcept { return axes_.size(); }
  // Axis `axis`'s model (axis < axes()).
  cia402::sim::DriveModel& drive(std::size_t axis = 0) noexcept { return *axes_[axis].model; }
  const cia402::sim::DriveModel& drive(std::size_t axis = 0) const noexcept { return *axes_[axis].model; }
  const Cia402SlaveCounters& counters() const noexcept { return counters_; }
  // 6007h (+ axis x axis_offset).
  std::int16_t abort_option(std::size_t axis = 0) const noexcept { return axes_[axis].abort_option; }
  // 1C32h:01 (0 free run, 1 SM2 synchronous, 2 DC SYNC0).
  std::uint16_t sync_mode() const noexcept { return sm_out_sync_mode_; }

 private:
  struct Pdo {
    std::uint16_t index = 0;
    std::uint8_t count = 0;
    std::array<std::uint32_t, kMaxEntries> entries{};
  };
  struct Assign {
    std::uint8_t count = 0;
    std::array<std::uint16_t, kMaxAssign> pdos{};
  };
  struct Value {
    std::uint32_t abort = 0;
    std::uint32_t raw = 0;  // little-endian value bits
    std::uint8_t size = 0;  // bytes
  };
  enum class Kind : std::uint8_t { Text, Comm, Vendor, Model };
  // One axis: its model and what the slave keeps per axis.
  struct AxisState {
    std::unique_ptr<cia402::sim::DriveModel> model;
    std::int16_t abort_option = 0;  // 6007h + n x axis_offset
    bool comm_fault_raised = false;
    bool injected = false;
    // Fine interpolation (persona.fine_interpolation): the set-point ramps from start to target.
    bool ip_active = false;
    std::int32_t ip_start = 0;
    std::int32_t ip_target = 0;
    std::uint64_t ip_elapsed_ns = 0;
  };
  // An object as one axis sees it: the axis and the index axis 0 has it under.
  struct Located {
    std::size_t axis = 0;
    cia402::ObjectId local;
  };
  Located locate(cia402::ObjectId id) const noexcept;
  // What the object lookups give for one object: all fixed for the life of the slave (the persona
  // and the models' dictionaries do not change), so a mapped entry is looked up once per mapping
  // instead of on every frame (a line of 64 drives did it some thousand times per cycle).
  struct Resolved {
    cia402::ObjectId id;
    Located at;
    std::optional<cia402::DataType> type;        // type_of()
    std::optional<cia402::sim::Access> access;   // access_of()
    std::optional<cia402::DataType> model_type;  // the axis model dictionary's own type
    const std::int64_t* model_value = nullptr;   // where that dictionary keeps the value
    const EcatVendorObject* vendor = nullptr;
    bool hidden = false;
    bool ignored = false;
  };
  struct MappedEntry {
    Resolved object;
    std::uint8_t bytes = 0;
  };
  // The assigned PDOs' entries in order (as apply_outputs()/fill_inputs() walk them) and the
  // assigned sizes; rebuilt after any change of a mapping or an assignment.
  struct Plan {
    std::array<MappedEntry, kMaxAssign * kMaxEntries> rx{};
    std::array<MappedEntry, kMaxAssign * kMaxEntries> tx{};
    std::size_t rx_n = 0;
    std::size_t tx_n = 0;
    std::size_t output_bytes = 0;  // assigned_bytes(true)
    std::size_t input_bytes = 0;   // assigned_bytes(false)
  };
  // One entry as SDO information describes it (built at construction).
  struct Entry {
    cia402::ObjectId id;
    std::uint16_t data_type = 0;
    std::uint16_t access = 0;  // object_access bits
    std::uint16_t bits = 0;
    Kind kind = Kind::Model;
  };

  // ObjectDictionary
  OdReadResult read(std::uint16_t index, std::uint8_t subindex, std::span<std::uint8_t> out,
                    AlState state) noexcept override;
  std::uint32_t write(std::uint16_t index, std::uint8_t subindex, std::span<const std::uint8_t> data,
                      AlState state) noexcept override;
  std::size_t list(OdListType type, std::span<std::uint16_t> out) const noexcept override;
  bool describe_object(std::uint16_t index, SdoInfoObjectDescription& out) const noexcept override;
  bool describe_entry(std::uint16_t index, std::uint8_t subindex, SdoInfoEntryDescription& out) const noexcept override;

  // Values (SDO and PDO).
  Value get(cia402::ObjectId id) const noexcept { return get(resolve(id)); }
  Value get(const Resolved& r) const noexcept;
  Resolved resolve(cia402::ObjectId id) const noexcept;
  const Plan& plan() const noexcept;
  void build_plan() const noexcept;
  std::uint32_t put(cia402::ObjectId id, std::uint32_t raw, std::size_t size, AlState state) noexcept;
  std::optional<Value> get_comm(cia402::ObjectId id) const noexcept;
  std::optional<std::uint32_t> put_comm(cia402::ObjectId id, std::uint32_t raw, std::size_t size, AlState state) noexcept;
  std::uint32_t put_pdo(Pdo& pdo, bool receive, std::uint8_t sub, std::uint32_t raw, std::size_t size,
                        AlState state) noexcept;
  std::uint32_t put_assign(Assign& a, bool receive, std::uint8_t sub, std::uint32_t raw, std::size_t size,
                           AlState state) noexcept;
  std::uint32_t put_app(cia402::ObjectId id, std::int64_t value) noexcept { return put_app(resolve(id), value); }
  std::uint32_t put_app(const Resolved& r, std::int64_t value) noexcept;  // typed value into vendor/model

  // Objects.
  std::optional<cia402::DataType> type_of(cia402::ObjectId id) const noexcept;
  std::optional<cia402::sim::Access> access_of(cia402::ObjectId id) const noexcept;
  std::optional<cia402::DataType> mappable(cia402::ObjectId id, bool receive) const noexcept;
  std::uint32_t check_entry(std::uint32_t entry, bool receive) const noexcept;
  bool hidden(cia402::ObjectId id) const noexcept;
  bool ignored(cia402::ObjectId id) const noexcept;
  const EcatVendorObject* vendor_object(cia402::ObjectId id) const noexcept;
  // The object's name in SDO Information: the persona's for a manufacturer object, else the CiA name.
  std::string_view name_of(std::uint16_t index) const noexcept;
  std::string_view text_of(cia402::ObjectId id) const noexcept;
  Pdo* pdo(std::uint16_t index, bool* receive) noexcept;
  const Pdo* pdo(std::uint16_t index, bool* receive) const noexcept;
  std::size_t pdo_bytes(const Pdo& p) const noexcept;
  std::size_t assigned_bytes(bool receive) const noexcept;
  const Entry* find_entry(cia402::ObjectId id) const noexcept;
  void build_entries();
  void build_sii(std::uint32_t serial, std::uint16_t alias, bool sdo_information);

  // Cycle.
  void apply_outputs(std::span<const std::uint8_t> outputs) noexcept;
  void fill_inputs(std::span<std::uint8_t> inputs) const noexcept;
  void advance(std::uint64_t now_ns) noexcept;
  void report_emcys() noexcept;
  void watch_al_status() noexcept;
  void comm_loss(AxisState& a) noexcept;
  void restore_defaults() noexcept;
  std::uint16_t to_model_controlword(const AxisState& a, std::uint16_t cw) const noexcept;
  std::uint16_t from_model_controlword(const AxisState& a, std::uint16_t cw) const noexcept;

  const EthercatPersona& persona_;
  std::vector<AxisState> axes_;
  cia402::sim::ObjectDictionary vendor_;
  std::vector<Pdo> rx_;
  std::vector<Pdo> tx_;
  Assign rx_assign_;
  Assign tx_assign_;
  mutable Plan plan_;
  mutable bool plan_valid_ = false;  // cleared wherever rx_, tx_ or the assignments change
  std::vector<Entry> entries_;  // sorted by index, sub-index
  std::vector<std::uint8_t> sii_;
  EscSlave* esc_ = nullptr;
  Cia402SlaveCounters counters_;

  std::uint16_t sm_out_sync_mode_ = 0;       // 1C32h:01
  std::uint32_t sm_out_cycle_ns_ = 0;        // 1C32h:02
  std::uint16_t sm_in_sync_mode_ = 0;        // 1C33h:01

  bool started_ = false;
  std::uint64_t model_ns_ = 0;  // time the models have been stepped to
  bool al_error_seen_ = false;
};

// A drive and its ESC, ready for SimLine::add(*esc).
struct Cia402Device {
  std::unique_ptr<Cia402Slave> app;
  std::unique_ptr<EscSlave> esc;
};

// A fresh slave of the named persona; throws std::invalid_argument for an unknown name (the
// message lists the known ones).
std::unique_ptr<Cia402Slave> make_cia402_slave(std::string_view persona, Cia402SlaveOptions options = {});
Cia402Device make_cia402_device(std::string_view persona, Cia402SlaveOptions options = {});

}  // namespace drivegate::ethercat::sim
