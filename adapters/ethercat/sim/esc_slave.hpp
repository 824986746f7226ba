#pragma once
// One simulated EtherCAT slave controller (ESC) with its application [ETG.1000.4 §5.4 datagram
// processing, §6 registers; ETG.1000.6 §5.3 AL state machine, §5.4 SII, §5.6 CoE].
//
// The ESC has a 64 KiB address space (registers 0000h-0FFFh, process RAM from 1000h), allocated
// once at construction; processing a frame allocates nothing. Sans-I/O: time comes in as a
// parameter (ns since an arbitrary epoch), the line (SimLine) calls process() for each datagram as
// the frame passes the slave and pdi_cycle() after it has passed.
//
// Modelled:
// - commands APxx/FPxx/BRx/LRx/ARMW/FRMW with the working counter rules of ETG.1000.4 §5.4;
//   FMMUs with byte granularity (the start/stop bits are stored but bit-wise mapping is not done:
//   logical_start_bit must be 0 and logical_stop_bit 7 for an FMMU to map anything);
// - ECAT write protection of read-only registers (a write to them is ignored, the WKC still counts,
//   as on an ESC);
// - SyncManagers: mailbox (1-buffer) and buffered (3-buffer, modelled as one buffer: the PDI side
//   runs between frames, so a frame never sees a half-updated buffer); an access the SM refuses
//   (write to a full mailbox, read of an empty one, any access while the SM is disabled or
//   deactivated by the PDI) does not touch memory and does not count;
// - AL state machine with the checks of ETG.1000.6 §5.3.2, SM watchdog, SII EEPROM interface,
//   mailbox with repeat, CoE server, DC registers;
// - distributed clocks (when EscConfig::dc_supported): a local clock with an offset and a drift
//   (DcClock), receive time latches, system time = local + 0920h, the system time difference 092Ch
//   of a written system time against the own one plus the delay 0928h, a control loop that makes
//   the clock follow, and SYNC0 pulses at start + k·cycle once 0981h activates them (0984h
//   activation status, 0990h reads the next pulse).
#include <array>
#include <bitset>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "adapters/ethercat/sim/coe_server.hpp"
#include "adapters/ethercat/sim/dc_clock.hpp"
#include "adapters/ethercat/sim/object_dictionary.hpp"
#include "adapters/ethercat/wire/frame.hpp"
#include "adapters/ethercat/wire/mailbox.hpp"
#include "adapters/ethercat/wire/registers.hpp"
#include "adapters/ethercat/wire/sii.hpp"

namespace drivegate::ethercat::sim {

class EscSlave;

// What runs behind the PDI: the device's firmware. A CiA 402 drive model implements this.
class SlaveApplication {
 public:
  virtual ~SlaveApplication() = default;
  // Process data sizes the SMs must be configured with (SM2 outputs, SM3 inputs) [ETG.1000.6
  // §5.3.2: checked at PRE-OP -> SAFE-OP]. They may depend on the PDO assignment in the OD.
  virtual std::size_t output_size() const noexcept = 0;
  virtual std::size_t input_size() const noexcept = 0;
  // Called once by the EscSlave constructor: the application keeps `esc` to post emergencies.
  virtual void attach(EscSlave& /*esc*/) noexcept {}
  // A requested transition the generic checks passed: 0 accepts, otherwise the AL status code.
  virtual std::uint16_t on_state_change(AlState /*from*/, AlState /*to*/) noexcept { return 0; }
  // Every state change, requested or not (SM watchdog, limit_state()), as it happens.
  virtual void on_state_entered(AlState /*from*/, AlState /*to*/) noexcept {}
  // After each frame: `outputs` as the master last wrote them (all zero outside OP or after the
  // SM watchdog expired), `inputs` to fill (copied into SM3 in SAFE-OP and OP).
  virtual void exchange(std::span<const std::uint8_t> outputs, std::span<std::uint8_t> inputs, AlState state,
                        std::uint64_t now_ns) noexcept = 0;
  // The CoE object dictionary; null for a slave without CoE.
  virtual ObjectDictionary* object_dictionary() noexcept { return nullptr; }
  // SYNC0 fired (DC slaves with 0981h = 03h): `pulse_ns` is the system time of the last pulse since
  // the previous PDI cycle (several may have passed; EscSlave::sync0_pulses() counts them all),
  // `now_ns` the line's time. Called in the PDI cycle before exchange(), so a drive model can latch
  // its set-points on SYNC0.
  virtual void on_sync0(std::uint64_t /*pulse_ns*/, std::uint64_t /*now_ns*/) noexcept {}
};

struct EscConfig {
  // ESC identity registers [ETG.1000.4 Table 31].
  std::uint8_t type = 0x11;          // ESC type (an ET1100-like value)
  std::uint8_t revision = 0x00;
  std::uint16_t build = 0x0002;
  std::uint8_t fmmu_count = 3;
  std::uint8_t sm_count = 4;
  std::uint8_t ram_kib = 8;          // process RAM size in KiB
  std::uint8_t port_descriptor = 0x0F;  // ports 0 and 1 MII (11b each), 2 and 3 not implemented
  std::uint16_t features = 0x01CC;   // 0008h ESC features; bit 2 DC is set from dc_supported
  bool dc_supported = false;         // DC unit present (ESR/Dunker drives: none)
  bool dc_64bit = true;
  std::int64_t clock_offset_ns = 0;  // this slave's local clock minus the line's time at power-on
  double drift_ppm = 0.0;            // its oscillator's error: + runs fast (DcClock)
  // SII EEPROM reads: 8 bytes per read (0502h bit 6 = 1) or 4.
  bool sii_read_8_bytes = true;
  // Frames the SII busy bit stays set after a command (the master must poll).
  std::uint8_t sii_busy_frames = 1;
  std::size_t mailbox_queue = 16;       // slave -> master mailboxes waiting for SM1
  std::size_t max_object_bytes = 1024;  // largest SDO value
};

class EscSlave {
 public:
  // `sii` is the EEPROM image (build_sii); the mailbox and SM layout come from it. `app` may be
  // null (no process data). Allocates here only.
  EscSlave(const EscConfig& config, std::span<const std::uint8_t> sii, SlaveApplication* app);
  EscSlave(const EscSlave&) = delete;
  EscSlave& operator=(const EscSlave&) = delete;

  // Power-on reset: registers from the configuration and EEPROM, INIT, station address 0.
  void power_on() noexcept;

  // Timing of the frame at this slave, set by the line before process(): local times are
  // `now + clock_offset`; the frame enters port 0 at `port0_ns` and, with a downstream neighbour,
  // comes back through port 1 at `port1_ns`.
  void begin_frame(std::uint64_t port0_ns, std::uint64_t port1_ns, bool downstream) noexcept;
  // One datagram in place (the frame's bytes): header (ADP auto-incremented), data, WKC.
  void process(std::span<std::uint8_t> header, std::span<std::uint8_t> data, std::span<std::uint8_t> wkc) noexcept;
  // The same with the header already decoded by the line (command and length; the address is read
  // again from `header`, as the slaves before this one may have incremented the ADP).
  void process(const DatagramHeader& decoded, std::span<std::uint8_t> header, std::span<std::uint8_t> data,
               std::span<std::uint8_t> wkc) noexcept;
  // The PDI side after the frame: mailbox handling, process data exchange, watchdog. Also called
  // by the line for slaves the frame did not reach (time goes on for them).
  void pdi_cycle(std::uint64_t now_ns) noexcept;

  // State for tests and the line.
  AlState state() const noexcept { return state_; }
  std::uint16_t al_status_code() const noexcept;
  std::uint16_t station_address() const noexcept;
  std::span<const std::uint8_t> memory() const noexcept { return {mem_.data(), mem_.size()}; }
  // DC: the local clock and the system time (local + 0920h; 32 bits on a 32-bit DC) at line time
  // `now_ns`.
  std::uint64_t local_time(std::uint64_t now_ns) const noexcept { return clock_.local(now_ns); }
  std::uint64_t system_time(std::uint64_t now_ns) const noexcept;
  const DcClock& dc_clock() const noexcept { return clock_; }
  // SYNC0: pulses so far, the system time of the last one (0 before the first), whether the unit
  // runs (activated with a start time in the future).
  std::uint64_t sync0_pulses() const noexcept { return sync0_count_; }
  std::uint64_t last_sync0() const noexcept { return sync0_last_; }
  bool sync0_running() const noexcept { return sync0_running_; }
  // Queues a CoE emergency [ETG.1000.6 §5.6.4]; false when the mailbox queue is full or the slave
  // has no mailbox.
  bool post_emergency(const CoeEmergency& e) noexcept;
  // Link state of port 1 (the line sets it: false for the last slave or after a break).
  void set_port1_link(bool up) noexcept;
  // A frame with a bad FCS arrived on port 0 (corruption injected by the line).
  void count_rx_error() noexcept;
  // Fault: the slave refuses every state above `highest` with `code` (e.g. SAFE-OP and 001Ah, a
  // slave "stuck in SAFE-OP"); when it is above it now, it drops there on its own with the error
  // set, as after a local error [ETG.1000.6 §5.3.2]. AlState::Op lifts the fault.
  void limit_state(AlState highest, std::uint16_t code) noexcept;
  std::uint64_t mailbox_repeats() const noexcept { return repeats_; }
  std::uint64_t mailbox_duplicates() const noexcept { return duplicates_; }

 private:
  struct SmState {
    bool mailbox_full = false;  // 1-buffer state (also mirrored in the status register)
  };
  enum class Rw : std::uint8_t { Read, Write };

  std::uint16_t u16(std::uint16_t at) const noexcept;
  std::uint32_t u32(std::uint16_t at) const noexcept;
  std::uint64_t u64(std::uint16_t at) const noexcept;
  void set16(std::uint16_t at, std::uint16_t v) noexcept;
  void set32(std::uint16_t at, std::uint32_t v) noexcept;
  void set64(std::uint16_t at, std::uint64_t v) noexcept;

  SmEntry sm(unsigned n) const noexcept;
  // The SM's buffer in memory; empty when it would reach past 64 KiB (the master may configure
  // anything after the state checks passed).
  std::span<std::uint8_t> sm_buffer(unsigned n) noexcept { return sm_buffer(sm(n)); }
  std::span<std::uint8_t> sm_buffer(const SmEntry& e) noexcept;
  bool sm_active(unsigned n) const noexcept { return sm_active(sm(n)); }
  static bool sm_active(const SmEntry& e) noexcept;
  // Checks an ECAT access to [start, start+len): false when an SM refuses it.
  bool sm_allows(std::uint32_t start, std::uint32_t len, Rw rw) const noexcept;
  // Side effects of a completed access (mailbox full/empty, buffer written).
  void sm_after(std::uint32_t start, std::uint32_t len, Rw rw) noexcept;
  bool phys_read(std::uint32_t ado, std::span<std::uint8_t> data, bool or_in) noexcept;
  bool phys_write(std::uint32_t ado, std::span<const std::uint8_t> data) noexcept;
  void register_written(std::uint32_t start, std::uint32_t len) noexcept;
  void refresh_dynamic_registers() noexcept;
  bool logical(Command c, std::uint32_t address, std::span<std::uint8_t> data, std::uint16_t& wkc) noexcept;
  // The FMMUs that map anything (active, length > 0, byte granularity), decoded from 0600h.. once
  // and again after a write to their registers or a power-on, in register order.
  void decode_fmmus() noexcept;

  void al_control_written() noexcept;
  void set_al(AlState s, std::uint16_t code, bool error) noexcept;
  std::uint16_t check_transition(AlState from, AlState to) noexcept;
  void enter_state(AlState from, AlState to) noexcept;
  void set_pdi_deactivate(unsigned n, bool deactivate) noexcept;
  void sii_command() noexcept;
  void mailbox_received() noexcept;
  void load_sm1() noexcept;
  void sm1_repeat() noexcept;
  void watchdog_check(std::uint64_t now_ns) noexcept;
  void system_time_written(std::uint32_t ado, std::span<const std::uint8_t> data) noexcept;
  void dc_activation_written() noexcept;
  void sync0_cycle(std::uint64_t now_ns) noexcept;
  // a is at or after b in the slave's system time width (32-bit DC wraps).
  bool time_reached(std::uint64_t a, std::uint64_t b) const noexcept;

  EscConfig cfg_;
  SlaveApplication* app_ = nullptr;
  std::vector<std::uint8_t> mem_;            // 64 KiB
  std::bitset<0x1000> writable_;             // ECAT-writable register bytes
  std::vector<std::uint8_t> sii_;            // EEPROM image
  std::unique_ptr<SiiInfo> sii_info_;        // large: kept off the stack
  std::array<SmState, 16> sms_{};
  AlState state_ = AlState::Init;
  AlState highest_ = AlState::Op;   // limit_state()
  std::uint16_t limit_code_ = 0;
  std::uint8_t sii_busy_ = 0;

  // mailbox
  bool has_mailbox_ = false;
  MailboxOutbox outbox_;
  CoeServer coe_;
  std::vector<std::uint8_t> last_sent_;      // last mailbox the master read from SM1 (repeat)
  std::size_t last_sent_size_ = 0;
  std::uint8_t last_rx_counter_ = 0;
  bool mailbox_pending_ = false;             // SM0 full, not yet handled by the PDI
  std::uint64_t repeats_ = 0;
  std::uint64_t duplicates_ = 0;

  // process data
  std::vector<std::uint8_t> inputs_;
  std::vector<std::uint8_t> zeros_;          // the outputs an application sees outside OP
  bool outputs_valid_ = false;
  bool wd_triggered_ = false;                // SM2 written since the last PDI cycle
  std::uint64_t wd_last_ns_ = 0;
  std::uint64_t now_ns_ = 0;

  // DC / frame timing
  std::uint64_t port0_ns_ = 0;
  std::uint64_t port1_ns_ = 0;
  bool downstream_ = false;
  bool port1_link_ = false;
  DcClock clock_;
  bool sync0_running_ = false;
  std::uint64_t sync0_next_ = 0;   // system time of the next pulse
  std::uint64_t sync0_cycle_ = 0;  // 09A0h at activation; 0 = one pulse
  std::uint64_t sync0_last_ = 0;
  std::uint64_t sync0_count_ = 0;
  bool sync0_fired_ = false;       // since the last PDI cycle
  std::array<std::uint8_t, kMaxDatagramData> scratch_{};

  // Derived from memory, kept while the inputs are unchanged (pure caches: what a datagram sees is
  // what it saw without them).
  struct MappedFmmu {
    std::uint64_t lo = 0;           // logical start
    std::uint64_t hi = 0;           // logical end (exclusive)
    std::uint16_t physical = 0;
    std::uint8_t type = 0;
    std::uint8_t index = 0;         // n of 0600h + 16 n
  };
  std::array<MappedFmmu, 16> fmmus_{};
  std::size_t fmmu_n_ = 0;
  std::uint64_t fmmu_lo_ = 0;       // the union of their logical ranges: [fmmu_lo_, fmmu_hi_)
  std::uint64_t fmmu_hi_ = 0;
  bool fmmus_valid_ = false;        // cleared by a write to 0600h-06FFh and by power_on()
  // 0910h holds the system time for the current frame time and clock: no register written, no
  // new frame or PDI cycle since it was computed.
  bool system_time_fresh_ = false;
};

}  // namespace drivegate::ethercat::sim
