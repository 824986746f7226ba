#pragma once
// Start-up of an EtherCAT line, from an unknown line to every configured slave in PRE-OP
// (dunker-ethercat-coe.md "What an EtherCAT master must do", steps 1-2; ETG.1000.4 §6 registers,
// ETG.1000.6 §5.3 ESM, §5.4 SII):
//
//   1. count:    BRD 0000h; the working counter is the number of slaves [ETG.1000.4 §5.4 BRD].
//   2. reset:    one frame of broadcast writes, in this order: FMMUs and SyncManagers cleared, DC
//                activation off, DC system time / offset / delay cleared, DC speed counter start
//                1000h and filter depths (0934h = 0, 0935h = 0Ch), station alias off (0103h = 0),
//                then AL control = INIT with error acknowledge, then the EEPROM to EtherCAT (0500h =
//                2, then 0). Then BRD 0130h until every slave reports INIT (to_lower_state; a slave
//                not in INIT by then fails the line step).
//   3. address:  APWR 0010h = first_station + position (0x1001, 0x1002, ...).
//   4. per slave, all slaves in parallel, one datagram in flight each:
//      SII:      through the EEPROM interface [ETG.1000.4 Table 48]: FPRD 0502h (busy? 4 or 8 byte
//                reads?), FPWR 0502h = read command + word address, FPRD 0502h until not busy,
//                FPRD 0508h (4 or 8 bytes), until the category list ends (FFFFh) [ETG.1000.6 §5.4];
//                then parse_sii(). An error bit after a command (13: no acknowledge, 14: write
//                enable) is cleared with a NOP (0502h = 0) and the read given again, `retries`
//                times, then the slave fails at the SII step.
//      identity: vendor, product, revision against the expected slave at that position (revision
//                0 = any). A difference fails the slave and names both identities; a slave beyond
//                the configured ones is reported and left in INIT.
//      mailbox:  SM0/SM1 from the SII standard mailbox (FPWR 0800h, 16 bytes) when it has one.
//      PRE-OP:   a transition [ETG.1000.6 §5.3.2]: AL status read first; when its error bit is set
//                the error is acknowledged before anything else (AL control = current state | 10h,
//                or target | 10h when the target is lower, e.g. SAFE-OP + error -> INIT) and the
//                status polled until the bit clears. Then AL control = target, and AL status read
//                until the state is the target with no error (done), the error bit is set (refused:
//                0134h is read for the AL status code, the error acknowledged with current state |
//                10h and the status polled until the bit clears), or the transition's timeout passes.
//
// request_state() runs a later transition (SAFE-OP, OP, back down) on a slave the same way; part 2
// (PDO mapping, process data) calls it once the SMs/FMMUs are set. A slave whose transition failed
// (refused or timed out: status Failed at BootStep::Transition, the code and text kept in its
// report) can be asked again with request_state(): the error was acknowledged, so no new start()
// is needed.
//
// restart_slave() re-initialises one slave while the others keep running (recovery after it was
// lost, lost power or left OP): FPRD 0130h at its station; no answer there (a slave back from power
// loss has station 0) -> APWR 0010h by its position gives the station again [ETG.1000.4 §5.4
// auto-increment addressing]; then INIT (error acknowledged first), SII, identity, mailbox and
// PRE-OP exactly as in the boot. The caller resets the slave's CoeSdoClient and configures it again.
//
// Each failing slave stops at its step with one sentence, e.g.
//   "slave 2 (0x1002, ESR TrioDrive): PRE-OP -> SAFE-OP refused: 0x001D invalid output configuration"
// Slaves are numbered from 1 in texts (slave n = position n - 1, station first_station + n - 1).
//
// A lost datagram is sent again up to `retries` times, then the step fails with "no answer". The
// engine is driven by poll(now, tx) (queues what is due) and on_result() (Transactions calls it);
// it never blocks. LineBoot is large (an SII image and its parsed SiiInfo per slave, about 19 KB):
// the constructor allocates the per-slave records once, for capacity() slaves (the configured ones
// plus kSpareSlots for extra slaves, at least kMinSlots, at most kMaxSlaves); nothing allocates
// afterwards. A line with more slaves than capacity() fails the count step.
#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string_view>

#include "adapters/ethercat/master/transactions.hpp"
#include "adapters/ethercat/wire/registers.hpp"
#include "adapters/ethercat/wire/sii.hpp"
#include "core/clock.hpp"
#include "core/fixed_string.hpp"

namespace drivegate::ethercat {

struct ExpectedSlave {
  std::uint32_t vendor_id = 0;
  std::uint32_t product_code = 0;
  std::uint32_t revision = 0;  // 0 = any revision
  std::string_view name{};     // for texts; the SII name when empty
};

struct LineBootConfig {
  std::uint16_t first_station = 0x1001;
  core::Duration sii_timeout = std::chrono::milliseconds(100);       // one EEPROM read (busy)
  core::Duration init_to_preop = std::chrono::seconds(3);
  core::Duration preop_to_safeop = std::chrono::seconds(10);
  core::Duration safeop_to_op = std::chrono::seconds(10);
  core::Duration to_lower_state = std::chrono::seconds(5);           // any transition downwards
  int retries = 3;  // a lost datagram is sent again this often
};

enum class BootStep : std::uint8_t { Count, Reset, Address, Sii, Identity, Mailbox, Transition };
std::string_view to_string(BootStep s) noexcept;

enum class SlaveStatus : std::uint8_t {
  Pending,  // not started (line steps still running)
  Busy,     // a step or transition is running
  Ready,    // in `state`, nothing running
  Failed,   // stopped at `step`, `text` says why
  Extra,    // not configured: left in INIT
};
std::string_view to_string(SlaveStatus s) noexcept;

struct SlaveReport {
  std::uint16_t position = 0;
  std::uint16_t station = 0;
  SlaveStatus status = SlaveStatus::Pending;
  BootStep step = BootStep::Sii;
  AlState state = AlState::Init;  // last state read (INIT after the reset)
  AlState target = AlState::Init; // of the last transition requested
  std::uint16_t al_code = 0;      // AL status code of a refused transition
  SiiIdentity found{};
  core::FixedString<240> text{};  // the failure / extra-slave sentence; empty when fine

  // The slave's identity differs from the configured one (it stopped at the identity step).
  [[nodiscard]] bool identity_mismatch() const noexcept {
    return status == SlaveStatus::Failed && step == BootStep::Identity;
  }
};

enum class LineStatus : std::uint8_t { Idle, Running, Done, Failed };

class LineBoot final : public DatagramOwner {
 public:
  static constexpr std::size_t kMaxSlaves = 64;
  static constexpr std::size_t kMinSlots = 16;   // slaves a boot can count and report at least
  static constexpr std::size_t kSpareSlots = 8;  // beyond the configured ones, for extra slaves
  static constexpr std::size_t kMaxSiiBytes = 8192;

  // `expected`: one entry per configured position, front first (at most kMaxSlaves are used;
  // name views must outlive the boot). Allocates the per-slave records (see capacity()).
  LineBoot(std::span<const ExpectedSlave> expected, LineBootConfig config);
  ~LineBoot();
  LineBoot(const LineBoot&) = delete;
  LineBoot& operator=(const LineBoot&) = delete;

  // Slaves this boot can take: min(kMaxSlaves, max(kMinSlots, configured + kSpareSlots)).
  [[nodiscard]] std::size_t capacity() const noexcept { return capacity_; }

  // (Re)starts the boot from the count. Answers to datagrams of an earlier run still in flight
  // are ignored.
  void start(core::TimePoint now) noexcept;
  // Queues the datagrams that are due and runs timeouts.
  void poll(core::TimePoint now, Transactions& tx) noexcept;
  void on_result(std::uint32_t tag, const DatagramAnswer& answer) noexcept override;

  // Done: the line steps finished and no slave is busy; Failed: a line step failed (count, reset,
  // addresses). Slave failures leave the line Done: see ok() and the reports.
  [[nodiscard]] LineStatus status() const noexcept;
  // Done, every configured slave found with its identity and Ready in PRE-OP (or later), no extra
  // and no missing slave.
  [[nodiscard]] bool ok() const noexcept;
  // Line-level sentence: the failed line step, or the missing slaves.
  [[nodiscard]] std::string_view line_text() const noexcept { return line_text_.view(); }
  [[nodiscard]] std::size_t slave_count() const noexcept { return found_; }
  [[nodiscard]] std::size_t missing() const noexcept { return expected_count_ > found_ ? expected_count_ - found_ : 0; }
  [[nodiscard]] const SlaveReport& slave(std::size_t position) const noexcept { return slaves_[position].report; }
  [[nodiscard]] const SiiInfo& sii(std::size_t position) const noexcept { return slaves_[position].info; }

  // Starts a transition of a Ready slave (SAFE-OP, OP, or down), or of a slave whose last
  // transition failed (Failed at BootStep::Transition). False otherwise (busy, or stopped at an
  // earlier step).
  bool request_state(std::size_t position, AlState target, core::TimePoint now) noexcept;

  // Identities accepted at `position` besides the expected one (a device profile that lists
  // several brandings; revision 0 = any); `any`: every identity is accepted there (a generic
  // profile: the caller checks the slave further, e.g. its 1000h). The span must outlive the boot.
  // Call before start().
  void accept_identities(std::size_t position, std::span<const SiiIdentity> also, bool any = false) noexcept;

  // Re-initialises the slave at `position` (see the header comment) without touching the others.
  // False when the line steps have not run (status() Idle or Failed), the position is beyond the
  // configured slaves, or the slave is busy. A position beyond the slaves found at the boot (it
  // was missing) is taken in, together with the missing ones before it.
  bool restart_slave(std::size_t position, core::TimePoint now) noexcept;

 private:
  // One datagram an actor (the line or a slave) waits for, kept to be sent again when lost.
  struct Pending {
    bool due = false;      // to be queued by the next poll()
    bool waiting = false;  // queued, result not yet in
    std::uint16_t seq = 0;
    int retries_left = 0;
    Command command = Command::NOP;
    std::uint32_t address = 0;
    std::uint16_t length = 0;
    std::array<std::uint8_t, 16> data{};
    std::size_t data_size = 0;
  };
  enum class LinePhase : std::uint8_t { Idle, Count, Reset, ResetWait, Address, Slaves, Done, Failed };
  enum class Phase : std::uint8_t {
    Idle, Probe, Readdress, SiiStatus, SiiCommand, SiiBusy, SiiClear, SiiData, Mailbox, AlCheck, AlRequest, AlPoll, AlCode, AlAck, AlAckPoll,
  };
  struct Slave {
    SlaveReport report{};
    Phase phase = Phase::Idle;
    Pending pending{};
    core::TimePoint deadline{};
    AlState from = AlState::Init;
    std::uint16_t al_status_raw = 0;
    std::uint16_t ack_control = 0;  // AL control written by AlAck
    bool refused = false;           // AlAck acknowledges a refusal (else an error found before the request)
    bool eight_byte_reads = false;
    bool restart = false;           // restart_slave(): INIT reached -> SII and on
    std::span<const SiiIdentity> also{};  // accept_identities()
    bool any_identity = false;
    std::uint32_t sii_word = 0;  // next word address to read
    int sii_tries_left = 0;      // reads of this word given again after an EEPROM error
    std::size_t sii_next_category = 0;  // image offset of the next SII category header to walk
    std::size_t image_size = 0;
    std::array<std::uint8_t, kMaxSiiBytes> image{};
    SiiInfo info{};
  };
  static constexpr std::uint32_t kLineActor = 0xFF;

  void set(Pending& p, Command command, std::uint32_t address, std::uint16_t length,
           std::span<const std::uint8_t> data = {}) noexcept;
  void send(Pending& p, std::uint32_t actor, Transactions& tx) noexcept;
  void line_answer(const DatagramAnswer& a) noexcept;
  void line_group_done() noexcept;
  void reset_wait_answer(const DatagramAnswer& a) noexcept;
  void queue_reset(Transactions& tx) noexcept;
  void queue_addresses(Transactions& tx) noexcept;
  void slave_answer(Slave& s, const DatagramAnswer& a) noexcept;
  void slave_phase(Slave& s) noexcept;  // sets the pending datagram of the phase just entered
  // The boot step a slave in phase `p` is at (the step a failure there is reported under).
  [[nodiscard]] static BootStep step_of(Phase p) noexcept;
  void sii_chunk(Slave& s, std::span<const std::uint8_t> data) noexcept;
  void identify(Slave& s) noexcept;
  void start_sii(Slave& s) noexcept;
  void reached(Slave& s) noexcept;  // the transition's target reached, no error
  [[nodiscard]] bool identity_accepted(const Slave& s, const SiiIdentity& f) const noexcept;
  void begin_transition(Slave& s, AlState target) noexcept;
  void acknowledge(Slave& s, AlState state, bool refused) noexcept;  // AlAck with state | 10h
  void fail_refused(Slave& s) noexcept;
  void fail(Slave& s, BootStep step, const char* fmt, ...) noexcept __attribute__((format(printf, 4, 5)));
  void fail_line(const char* fmt, ...) noexcept __attribute__((format(printf, 2, 3)));
  [[nodiscard]] std::string_view name_of(const Slave& s) const noexcept;
  [[nodiscard]] core::Duration timeout_of(AlState from, AlState to) const noexcept;

  std::array<ExpectedSlave, kMaxSlaves> expected_{};
  std::size_t expected_count_ = 0;
  LineBootConfig config_;
  LinePhase line_ = LinePhase::Idle;
  Pending line_pending_{};      // count
  std::size_t group_left_ = 0;  // reset / address: datagrams of the group not yet answered
  bool group_lost_ = false;
  bool group_bad_ = false;
  int group_retries_ = 0;
  bool group_due_ = false;
  std::uint16_t group_seq_ = 0;
  std::uint8_t run_ = 0;  // run generation (0..15), counted up by start(), part of every tag
  std::size_t found_ = 0;
  core::TimePoint reset_deadline_{};  // every slave in INIT by then
  std::uint16_t reset_status_ = 0;    // last BRD 0130h: AL status OR-ed over the slaves
  std::uint16_t reset_wkc_ = 0;
  core::TimePoint now_{};
  core::FixedString<240> line_text_{};
  std::size_t capacity_ = 0;
  std::unique_ptr<Slave[]> slaves_;  // capacity_ records, allocated by the constructor
};

}  // namespace drivegate::ethercat
