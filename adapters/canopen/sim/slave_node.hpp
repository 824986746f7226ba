#pragma once
// One simulated CANopen drive on one node-ID: the NMT slave with error control, SDO servers, PDOs
// and EMCY producer of CiA 301 around a CiA 402 drive model (profiles/cia402/sim/drive_model.hpp),
// behaving as its persona says (persona.hpp).
//
// Object dictionary as the SDO servers and PDOs see it, first match wins:
//   1001h         the model's error register, or the persona's EMCY rule register of the fault
//   1005h, 1006h, 100Ch, 100Dh, 1010h, 1014h..1017h, 1200h..1203h   communication objects owned here
//   1400h..1BFFh  the PDO parameters (SlavePdos)
//   the persona's manufacturer objects (parameters and live values)
//   the persona's hidden objects: 06020000h
//   the drive model's dictionary (1000h, 1018h and the 6xxxh objects)
//
// NMT resets [CiA 301 §7.3.2.2.2]: Reset Node sets the application objects (device profile and
// manufacturer areas) to their power-on values and then resets communication; the CiA 402 state
// machine follows its controlword, which is 0 again (so an enabled drive drops to Switch on
// disabled, a fault stays latched until reset). Reset Communication restores the communication
// objects only (1005h..1017h, SDO and PDO parameters). A power loss is more: power_on() also runs
// the model's power_cycle() (motor stopped, Not ready to switch on, then Switch on disabled).
//
// on_frame() and step() are the cyclic path: no allocation, lock, logging or blocking. What the
// engines produce goes through one outbox so that silence and damaged frames apply to every kind.
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "adapters/canopen/master/tx_queue.hpp"
#include "adapters/canopen/sim/emcy_producer.hpp"
#include "adapters/canopen/sim/nmt_slave.hpp"
#include "adapters/canopen/sim/persona.hpp"
#include "adapters/canopen/sim/sdo_server.hpp"
#include "adapters/canopen/sim/slave_config.hpp"
#include "adapters/canopen/sim/slave_pdo.hpp"
#include "adapters/canopen/wire/can_frame.hpp"
#include "core/clock.hpp"
#include "profiles/cia402/sim/drive_model.hpp"
#include "profiles/cia402/sim/object_dictionary.hpp"

namespace drivegate::canopen::sim {

// How damage_next() spoils a frame the node sends.
enum class FrameDamage : std::uint8_t {
  WrongDlc,  // one byte short (a 0-byte frame gets one byte): receivers see a wrong length
  Garbage,   // every data byte inverted, the length kept
};

struct SlaveNodeCounters {
  std::uint64_t frames = 0;              // frames this node took: NMT, SYNC, its SDO, RPDO, error control
  std::uint64_t ignored_off = 0;         // frames seen while powered off
  std::uint64_t ignored_silent = 0;      // frames seen while silent
  std::uint64_t ignored_state = 0;       // SDO requests or SYNCs the NMT state does not serve
  std::uint64_t malformed = 0;           // DLC above 8 or an id beyond 11 bits; a SYNC longer than its counter byte
  std::uint64_t refused_pdo_values = 0;  // RPDO values the drive refused (out of range, a NORD mode 0)
  std::uint64_t discarded_silent = 0;    // frames produced while silent (lost, like on a cut cable)
  std::uint64_t damaged = 0;             // frames sent with a wrong DLC or garbage
  std::uint64_t tx_full = 0;             // frames the caller's queue or the outbox refused
  std::uint64_t comm_losses = 0;         // life-guarding or heartbeat losses that faulted the drive
};

class SlaveNode final : private SdoBackend, private PdoObjects {
 public:
  static constexpr std::size_t kMaxSdoChannels = 4;
  // The model advances in steps of at most this, and by at most kMaxCatchUp per step() (a
  // stalled caller does not make the motor jump).
  static constexpr core::Duration kModelStep = std::chrono::milliseconds(1);
  static constexpr core::Duration kMaxCatchUp = std::chrono::seconds(1);

  // Powered on; the boot-up goes out at the first step(). Throws std::invalid_argument for PDO
  // defaults the persona refuses (slave_pdo.hpp) or an SDO channel count outside 1..4.
  explicit SlaveNode(SlaveNodeConfig config);
  SlaveNode(const SlaveNode&) = delete;
  SlaveNode& operator=(const SlaveNode&) = delete;
  ~SlaveNode() override;

  // Every frame on the bus; true when this node took it.
  bool on_frame(const CanFrame& frame, core::TimePoint now) noexcept;
  // Advance the drive model by the time since the last step, then put what is due (boot-up,
  // heartbeats, guard replies, SDO responses, TPDOs, EMCYs) into `tx`.
  void step(core::TimePoint now, TxQueue& tx) noexcept;

  // --- Fault injection -----------------------------------------------------------------------
  // Power loss: silent and deaf until power_on(); nothing it was doing survives.
  void power_off() noexcept;
  // Power return at the next step(): boot-up, every object at its power-on value, the drive in
  // Not ready to switch on and then Switch on disabled (or in the fault again while an injected
  // cause persists). No effect while powered.
  void power_on() noexcept;
  // A drive fault whose cause persists until clear_fault_cause(); its EMCY carries the persona's
  // manufacturer bytes, `cause` in byte 4 where the persona has one (SD6 E43).
  void inject_fault(std::uint16_t code, std::uint8_t cause = 0) noexcept;
  void clear_fault_cause() noexcept;
  // An EMCY that changes nothing in the drive (a warning such as the AKD's n-numbers, an error
  // reset / no error 0000h): queued like the drive's own, sent while NMT serves EMCY. False when
  // suppressed or the producer's queue is full.
  bool send_emcy(const Emcy& emcy) noexcept { return emcy_.raise(emcy); }
  // A cut cable: nothing is received or sent (on_frame() and the outbox are the cable); the
  // engines behind it run on, so life guarding and the heartbeat consumer notice the silent master.
  void set_silent(bool on) noexcept { silent_ = on; }
  // The next SDO request for `object` (on any channel) is aborted with `code`.
  void inject_sdo_abort(ObjectId object, std::uint32_t code) noexcept;
  // The next `frames` frames this node sends are spoiled.
  void damage_next(std::uint32_t frames, FrameDamage how) noexcept;
  // A write through the drive's own service interface (keypad, vendor tool on USB), not the bus:
  // how a drive's configuration changes behind the gateway's back. Returns the SDO abort code the
  // same write over the bus would get (0: written).
  std::uint32_t service_write(ObjectId object, std::uint32_t raw, std::size_t size) noexcept {
    return write_value(object, raw, size);
  }

  // --- Observation ---------------------------------------------------------------------------
  [[nodiscard]] NodeId node() const noexcept { return config_.node; }
  [[nodiscard]] const Persona& persona() const noexcept { return config_.persona; }
  [[nodiscard]] bool powered() const noexcept { return powered_; }
  [[nodiscard]] bool silent() const noexcept { return silent_; }
  [[nodiscard]] NmtState nmt_state() const noexcept { return nmt_.state(); }
  [[nodiscard]] std::uint8_t error_register() const noexcept;
  [[nodiscard]] std::uint16_t fault_code() const noexcept { return active_code_; }  // of the last fault EMCY, 0 = none
  // The drive itself (tests and the simulator's status; not while another thread steps the node).
  [[nodiscard]] cia402::sim::DriveModel& drive() noexcept { return model_; }
  [[nodiscard]] const cia402::sim::DriveModel& drive() const noexcept { return model_; }
  [[nodiscard]] const NmtSlave& nmt() const noexcept { return nmt_; }
  [[nodiscard]] const SlavePdos& pdos() const noexcept { return pdos_; }
  [[nodiscard]] const EmcyProducer& emcy() const noexcept { return emcy_; }
  // SDO server of channel 1..4; nullptr while that channel is off.
  [[nodiscard]] const SdoServer* sdo(int channel) const noexcept;
  [[nodiscard]] const SlaveNodeCounters& counters() const noexcept { return counters_; }

 private:
  struct SdoChannel {
    std::uint32_t rx = cob::kInvalid;  // 120xh:01, client -> server
    std::uint32_t tx = cob::kInvalid;  // 120xh:02, server -> client
    std::uint8_t client = 0;           // 120xh:03
  };
  struct ValueRead {
    std::uint32_t abort = 0;
    std::uint32_t raw = 0;  // little-endian value bits
    std::uint8_t size = 0;  // bytes
  };

  // SdoBackend
  SdoReadResult sdo_read(ObjectId object, std::span<std::uint8_t> out) noexcept override;
  std::uint32_t sdo_write(ObjectId object, std::span<const std::uint8_t> data) noexcept override;
  // PdoObjects
  [[nodiscard]] std::optional<cia402::DataType> mappable(ObjectId id, bool receive) const noexcept override;
  [[nodiscard]] std::int64_t read(ObjectId id) const noexcept override;
  void write(ObjectId id, std::int64_t value) noexcept override;

  // Objects read and written as bytes: the persona's identity strings (1008h..100Ah) and the test
  // objects every simulated drive adds so that a master can exercise every size and segmented
  // transfers (not from a manual): 5FF0h DOMAIN of 4 KiB, 5FF1h UNSIGNED64, 5FF2h REAL32, all rw.
  struct ByteObject {
    ObjectId id;
    bool writable = false;
    std::size_t fixed = 0;  // bytes a write must carry; 0: any length up to kMaxBytes
    std::vector<std::uint8_t> power_on;
    std::vector<std::uint8_t> value;  // capacity reserved at construction: writes never allocate
  };
  static constexpr std::size_t kMaxBytes = 4096;
  [[nodiscard]] static std::vector<ByteObject> byte_objects_of(const Persona& p);
  [[nodiscard]] ByteObject* byte_object(ObjectId id) noexcept;

  [[nodiscard]] ValueRead read_value(ObjectId id) const noexcept;
  std::uint32_t write_value(ObjectId id, std::uint32_t raw, std::size_t size) noexcept;
  [[nodiscard]] std::optional<ValueRead> read_comm(ObjectId id) const noexcept;
  std::optional<std::uint32_t> write_comm(ObjectId id, std::uint32_t raw, std::size_t size) noexcept;
  std::uint32_t write_sdo_parameter(std::size_t channel, std::uint8_t sub, std::uint32_t raw, std::size_t size) noexcept;
  [[nodiscard]] const VendorObject* vendor_object(ObjectId id) const noexcept;
  [[nodiscard]] std::int64_t vendor_value(const VendorObject& v) const noexcept;
  // The abort code for an object neither the persona nor the model has.
  [[nodiscard]] std::uint32_t missing_code(ObjectId id) const noexcept;
  [[nodiscard]] bool hidden(ObjectId id) const noexcept;
  [[nodiscard]] const EmcyRule* rule_for(std::uint16_t code) const noexcept;
  [[nodiscard]] std::uint32_t emcy_cob_id() const noexcept;
  [[nodiscard]] std::uint32_t manufacturer_status() const noexcept;

  void boot(core::TimePoint now) noexcept;
  void advance_model(core::TimePoint now) noexcept;
  void handle_nmt_events() noexcept;
  void apply_nmt_state() noexcept;
  void reset_application() noexcept;
  void restore_persona_defaults() noexcept;
  void reset_communication() noexcept;
  void open_channel(std::size_t channel) noexcept;
  void comm_loss() noexcept;
  void report(const cia402::sim::EmcyEvent& e) noexcept;
  void flush(TxQueue& tx) noexcept;

  SlaveNodeConfig config_;
  cia402::sim::DriveModel model_;
  cia402::sim::ObjectDictionary vendor_;  // the persona's Stored manufacturer objects
  // Writable device-profile objects (6000h..6FFFh) of the model with their power-on values, for
  // Reset Node; collected once at construction.
  std::vector<ObjectValue> model_defaults_;
  std::vector<ByteObject> byte_objects_;
  NmtSlave nmt_;
  EmcyProducer emcy_;
  SlavePdos pdos_;  // calls mappable() while it is constructed: everything above is ready by then
  std::array<SdoChannel, kMaxSdoChannels> channel_defaults_{};
  std::array<SdoChannel, kMaxSdoChannels> channels_{};
  std::array<std::optional<SdoServer>, kMaxSdoChannels> sdo_{};
  // Channel parameters written over SDO take effect at the next step(), since the request may
  // have come through the very server that is replaced.
  std::array<bool, kMaxSdoChannels> reopen_{};

  std::uint32_t sync_cob_ = cob::kSync;  // 1005h
  std::uint32_t cycle_period_ = 0;       // 1006h, us
  bool emcy_valid_ = true;               // 1014h bit 31 clear

  bool powered_ = true;
  bool boot_pending_ = true;
  bool model_fresh_ = true;  // constructed and never stepped: no power cycle needed at the first boot
  bool silent_ = false;
  core::TimePoint now_{};  // of the frame or step being handled (SDO writes of timer objects)
  core::TimePoint last_step_{};

  // Faults: the injected cause (and the comm-loss fault, whose cause ends once it is raised), and
  // the fault the last EMCY reported (E82/E43, 1001h).
  bool injected_cause_ = false;
  bool comm_fault_raised_ = false;
  std::uint16_t last_injected_code_ = 0;
  std::uint8_t last_injected_cause_ = 0;
  std::uint16_t active_code_ = 0;
  std::uint8_t active_cause_ = 0;

  std::uint32_t damage_left_ = 0;
  FrameDamage damage_ = FrameDamage::WrongDlc;
  TxQueue out_;  // everything the engines produce, handed to the caller by flush()
  std::uint64_t out_overflows_seen_ = 0;
  SlaveNodeCounters counters_;
};

}  // namespace drivegate::canopen::sim
