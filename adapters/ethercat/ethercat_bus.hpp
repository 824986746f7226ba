#pragma once
// An EtherCAT bus (core::Bus): one Link, the master's sans-I/O engines (Transactions, LineBoot, per
// slave a CoeSdoClient and a PdoSetup, the ProcessImage and its CyclicExchange) and a CiA 402
// profile per axis over SlaveAccess (dunker-ethercat-coe.md "What an EtherCAT master must do").
//
// Life cycle, per configured slave (drives from the axes, I/O slaves from the bus' `io:` list):
//   boot:        LineBoot counts, resets and addresses the line, reads every SII, checks the
//                identities (the device profile's, any for a profile without identities: its 1000h
//                must then name CiA 402) and takes the slaves to PRE-OP. Mismatches and extra
//                slaves are bus events with the boot's sentences. The process image is laid out
//                once for every configured slave (one datagram per slave, so each has its own
//                working counter and the others keep their inputs when one is gone).
//   configure:   PdoSetup (start-up writes, PDO assignment and mapping read back, SM2/SM3, FMMUs,
//                SM watchdog from the bus options); then the DC step (bus_dc.hpp: with the bus
//                option distributed_clocks and a profile with distributed_clocks, once the line's
//                DC slaves are set up: DcSetup, SYNC0 every cycle_time + sync0_shift, then 1C32h:01
//                = 2 over CoE where the drive has 1C32h; an ESC without DC runs free); the cyclic
//                frame runs from here on with the slave's outputs zero, DcCyclic's FRMW first.
//   SAFE-OP, OP: LineBoot::request_state(); the axes' links are operational in OP only, and the
//                drives come up disabled (controlword 0).
//   lost:        no answer for `lost_cycles` cycles, or its AL state left OP (the AL status check
//                of CyclicExchange; the AL status code is read for the sentence): its axes Lost,
//                the other slaves keep cycling.
//   recovery:    after boot_retry (doubling up to boot_retry_max while it fails):
//                LineBoot::restart_slave() (probe at its station, re-address by position after a
//                power loss, INIT, SII, identity, mailbox, PRE-OP), CoeSdoClient::reset(), the whole
//                configuration again (a DC slave: its offset, delay and SYNC0 again, on its own),
//                SAFE-OP, OP; the axes come back disabled.
//   names:       in OP, while its CoE mailbox is otherwise idle, a drive's object names are read
//                over SDO Information (slave_dictionary.hpp), from the start after every
//                reconfiguration; find_object() looks names up in them.
//   safe stop:   the profile found the drive not following its controlword: link Degraded,
//                controlword quick stop (0002h) in the process data until the drive left
//                operation enabled (3 s at most), disable voltage (0000h), the slave to SAFE-OP,
//                then reconfigured as after a loss.
// A link that goes down takes every slave to Lost; when it is up again each one is recovered.
//
// link_detail() texts (per slave, shared by its axes):
//   "slave 2 (0x1002, ESR TrioDrive D/ES): booting"                         boot running
//   <LineBoot's or PdoSetup's sentence>                                     a failed step
//   "slave 2 (0x1002, ESR TrioDrive D/ES): in OP"                           operational
//   "slave 2 (0x1002, ESR TrioDrive D/ES): no answer for 3 cycles"          lost
//   "slave 2 (0x1002, ...): left OP: SAFE-OP + error 0x001B sync manager watchdog"
//   "slave 2 (0x1002, ...): restarting it (after 1000 ms)"                  recovery
//   "the Ethernet link is down (no carrier)"                                link loss
//
// receive() and transmit() are the cyclic path: no allocation, lock, logging or blocking.
#include <array>
#include <atomic>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "adapters/ethercat/bus_dc.hpp"
#include "adapters/ethercat/bus_io.hpp"
#include "adapters/ethercat/link/ethercat_link.hpp"
#include "adapters/ethercat/master/coe_sdo_client.hpp"
#include "adapters/ethercat/master/cyclic_exchange.hpp"
#include "adapters/ethercat/master/line_boot.hpp"
#include "adapters/ethercat/master/pdo_setup.hpp"
#include "adapters/ethercat/master/process_image.hpp"
#include "adapters/ethercat/master/transactions.hpp"
#include "adapters/ethercat/slave_access.hpp"
#include "adapters/ethercat/slave_dictionary.hpp"
#include "config/ethercat/plan.hpp"
#include "config/plan.hpp"
#include "core/bus.hpp"
#include "core/event_ring.hpp"
#include "profiles/cia402/cia402_master.hpp"

namespace drivegate::ethercat {

// Something the bus steps every cycle besides its own engines (the simulated line of a
// `transport: sim` bus).
class CyclePeer {
 public:
  virtual ~CyclePeer() = default;
  virtual void step(core::TimePoint now) noexcept = 0;
};

// What a plan's slave needs for the image: configured positions in line order, the PDO bits per
// direction. Shared by the bus and the --check-config checks (bus_type.cpp).
struct PlannedSlave {
  std::uint16_t position = 0;  // 0-based
  std::string name;
  const config::AxisPlan* axis = nullptr;         // a drive: its first axis
  const config::EthercatIoSlave* io = nullptr;    // an I/O slave
  std::uint32_t output_bits = 0;
  std::uint32_t input_bits = 0;
};
// Throws core::BusError when a position between 1 and the last one is neither a drive nor an I/O
// slave, or there are more than LineBoot::kMaxSlaves.
std::vector<PlannedSlave> planned_slaves(const config::BusPlan& plan);
// The image the plan gives with the SM defaults (no SII known) and the bus' datagram layout.
ImageSlave planned_image_slave(const PlannedSlave& s);
ImageOptions bus_image_options();

class EthercatBus final : public core::Bus, private EmergencySink, private DatagramOwner {
 public:
  enum class Phase : std::uint8_t {
    Boot,       // the line boot runs
    Restart,    // LineBoot::restart_slave() runs
    DeviceType, // a generic profile: 1000h read over CoE
    Configure,  // PdoSetup
    Sync,       // distributed clocks (bus_dc.hpp), 1C32h:01 = 2
    SafeOp,     // PRE-OP -> SAFE-OP
    ToOp,       // SAFE-OP -> OP
    Op,
    LeftOp,     // reading its AL status code for the sentence
    Lost,       // waiting for the back-off before a restart
    SafeStop,
  };

  EthercatBus(const config::BusPlan& plan, std::unique_ptr<Link> link, std::unique_ptr<CyclePeer> peer = nullptr);
  ~EthercatBus() override;

  std::string_view name() const noexcept override { return name_; }
  std::string_view type() const noexcept override { return "ethercat"; }
  void open(core::TimePoint now) override;
  void close() noexcept override;
  std::size_t axis_count() const noexcept override { return axes_.size(); }
  core::AxisController& controller(std::size_t axis) noexcept override { return *axes_[axis].master; }
  core::LinkState link_state(std::size_t axis) const noexcept override;
  std::string_view link_detail(std::size_t axis) const noexcept override;
  void receive(core::TimePoint now) noexcept override;
  void transmit(core::TimePoint now) noexcept override;
  bool next_event(core::Event& out) noexcept override;
  core::BusCounters counters() const noexcept override;
  // The `io:` slaves (bus_io.hpp; defined in bus_io.cpp).
  std::size_t io_count() const noexcept override { return io_.count(); }
  core::IoInfo io_info(std::size_t k) const noexcept override;
  void io_read(std::size_t k, core::IoSnapshot& out) noexcept override;
  core::IoWriteStatus io_write(std::size_t k, std::size_t offset, std::span<const std::uint8_t> bytes) noexcept override;

  static constexpr std::size_t kMaxEvents = 32;
  // A drive out of the gateway's control gets this long on its quick-stop ramp.
  static constexpr core::Duration kSafeStopBudget = std::chrono::seconds(3);

  // Diagnostics (bus thread, or while the bus is not cycling).
  [[nodiscard]] std::size_t slave_count() const noexcept { return slaves_.size(); }
  [[nodiscard]] Phase phase(std::size_t slave) const noexcept { return slaves_[slave]->phase; }
  [[nodiscard]] std::string_view slave_detail(std::size_t slave) const noexcept { return slaves_[slave]->detail.view(); }
  [[nodiscard]] const ProcessImage& image() const noexcept { return image_; }
  [[nodiscard]] const CyclicExchange* exchange() const noexcept { return cx_ ? &*cx_ : nullptr; }
  [[nodiscard]] const LineBoot& boot() const noexcept { return *boot_; }
  [[nodiscard]] const Transactions& transactions() const noexcept { return tx_; }
  [[nodiscard]] std::uint64_t restarts(std::size_t slave) const noexcept { return slaves_[slave]->restarts; }
  [[nodiscard]] SlaveAccess& access(std::size_t axis) noexcept { return *axes_[axis].io; }
  [[nodiscard]] std::uint64_t events_dropped() const noexcept { return events_.dropped(); }
  [[nodiscard]] Link& link() noexcept { return *link_; }
  // Distributed clocks (bus thread): the line's setup, the cyclic FRMW, per slave its verdict.
  [[nodiscard]] const BusDc& dc() const noexcept { return *dc_; }
  // Any thread: the largest |system time difference| (092Ch) of the DC slaves' last complete
  // round in ns (0 when the reference clock is the only DC slave), -1 before one completed or
  // without DC; the master's system time minus the
  // reference clock's at the last cycle (ns, 0 without DC).
  [[nodiscard]] std::int64_t dc_max_difference_ns() const noexcept { return dc_difference_.load(std::memory_order_relaxed); }
  [[nodiscard]] std::int64_t dc_master_minus_reference_ns() const noexcept {
    return dc_master_offset_.load(std::memory_order_relaxed);
  }
  // Both figures for the bus status: valid once a 092Ch round completed (-1 before, without DC).
  // A name of the axis' slave's own dictionary (slave_dictionary.hpp); any thread.
  core::NamedObject find_object(std::size_t axis, std::string_view name) const override;
  // Diagnostics, any thread: the dictionary of a drive (null for a slave without axes).
  [[nodiscard]] const SlaveDictionary* dictionary(std::size_t slave) const noexcept { return slaves_[slave]->dict.get(); }
  core::ClockSync clock_sync() const noexcept override {
    core::ClockSync s;
    const std::int64_t d = dc_max_difference_ns();
    if (d < 0) return s;
    s.valid = true;
    s.max_difference_ns = d;
    s.master_minus_reference_ns = dc_master_minus_reference_ns();
    return s;
  }

 private:
  struct Slave {
    // What every cycle reads (advance(), dc_step(), link_state()), together at the start: the
    // rest of a slave, its CoE client and PDO set-up inline, takes kilobytes.
    Phase phase = Phase::Boot;
    int missing = 0;
    std::uint64_t op_cycle = 0;  // the exchange's cycle count when it reached OP
    bool dict_due = false;       // in OP: the dictionary reading is to start (again)
    std::atomic<core::LinkState> link{core::LinkState::Offline};
    std::vector<std::size_t> axes;
    std::unique_ptr<SlaveDictionary> dict;  // drives: the names read over SDO Information
    PlannedSlave plan;
    std::uint16_t station = 0;
    std::vector<SiiIdentity> identities;  // accepted (the first is LineBoot's expected one)
    bool any_identity = false;
    std::vector<PdoEntryConfig> entries;  // storage of rx/tx PdoConfig spans
    std::vector<PdoConfig> rx, tx;
    std::vector<CoeStartupWrite> startup;
    std::vector<CoeObjectId> ignored;
    std::optional<CoeSdoClient> coe;
    PdoSetup setup;
    core::TimePoint since{};
    core::Duration backoff{};
    bool had_op = false;
    bool image_from_sii = false;
    std::uint64_t restarts = 0;
    CoeSdoId probe = 0;          // DeviceType: the 1000h upload
    int safe_step = 0;
    bool left_op_waiting = false;
    std::uint16_t left_op_seq = 0;
    CoeSdoId sync_mode_sdo = 0;  // Sync: the 1C32h:01 = 2 download
    bool sync_mode_done = false;
    core::FixedString<200> detail;
  };
  struct Axis {
    std::size_t slave = 0;
    DictionaryAxis names;
    std::vector<cia402::FaultText> faults;  // views into the plan
    std::unique_ptr<SlaveAccess> io;
    std::unique_ptr<cia402::Cia402Master> master;
  };

  void on_emergency(std::uint16_t station, const CoeEmergency& e) noexcept override;
  void on_result(std::uint32_t tag, const DatagramAnswer& answer) noexcept override;

  void start_boot(core::TimePoint now) noexcept;
  void boot_done(core::TimePoint now) noexcept;
  void advance(std::size_t k, core::TimePoint now) noexcept;
  void enter(Slave& s, Phase p, core::TimePoint now) noexcept;
  void configure(std::size_t k, core::TimePoint now) noexcept;
  void start_setup(std::size_t k, core::TimePoint now) noexcept;
  void lose(std::size_t k, core::TimePoint now) noexcept;   // detail set by the caller
  void fail(std::size_t k, core::TimePoint now) noexcept;   // a failed step: back-off doubles
  void run_safe_stop(std::size_t k, core::TimePoint now) noexcept;
  // In OP: the dictionary reading started (once a lookup no longer holds the table) and stepped.
  void read_names(std::size_t k) noexcept;
  void handle_link(core::TimePoint now) noexcept;
  void push_event(const core::Event& e) noexcept;
  void bus_event(core::EventKind kind, std::string_view text) noexcept;
  void set_detail(Slave& s, const char* what) noexcept;  // "slave n (0x..., name): what"
  // Distributed clocks (bus_dc.hpp): DcCyclic's FRMW queued first in the cycle's frame; the line
  // state once per cycle; the per-slave step between the PDO set-up and SAFE-OP (false: wait;
  // a failure fails the slave itself).
  void queue_dc(core::TimePoint now) noexcept;
  void dc_step(core::TimePoint now) noexcept;
  [[nodiscard]] bool dc_ready(std::size_t k, core::TimePoint now) noexcept;
  void publish_counters() noexcept;
  [[nodiscard]] bool all_op() const noexcept;

  std::string name_;
  config::EthercatBusOptions options_;
  core::Duration cycle_time_;
  std::unique_ptr<Link> link_;
  std::unique_ptr<CyclePeer> peer_;
  Transactions tx_;
  std::vector<ExpectedSlave> expected_;
  std::unique_ptr<LineBoot> boot_;
  ProcessImage image_;
  std::array<ImageSlave, ProcessImage::kMaxSlaves> image_slaves_{};
  std::optional<CyclicExchange> cx_;
  std::vector<std::unique_ptr<Slave>> slaves_;
  std::vector<Axis> axes_;
  BusIo io_;
  std::array<FrameBuffer, 8> rx_{};
  std::unique_ptr<BusDc> dc_;

  bool open_ = false;
  bool line_booting_ = false;
  bool line_backoff_ = false;
  core::TimePoint line_since_{};
  core::Duration line_wait_{};
  LinkState link_seen_ = LinkState::Closed;
  core::TimePoint last_now_{};
  std::uint64_t cycles_seen_ = 0;  // exchange cycles already looked at
  std::uint64_t wkc_seen_ = 0;
  std::uint64_t wkc_errors_ = 0;   // since every slave was in OP once
  bool counting_errors_ = false;
  std::uint64_t tx_unsent_ = 0;

  core::EventRing<kMaxEvents> events_;

  std::atomic<std::uint64_t> sent_{0};
  std::atomic<std::uint64_t> received_{0};
  std::atomic<std::uint64_t> lost_{0};
  std::atomic<std::uint64_t> dropped_{0};
  std::atomic<std::uint64_t> errors_{0};
  std::atomic<std::int64_t> dc_difference_{-1};
  std::atomic<std::int64_t> dc_master_offset_{0};
};

// A bus for the plan: transport raw -> RawSocketLink on the interface; transport sim -> BusError
// (the simulated line builder is wired by the integrator).
std::unique_ptr<EthercatBus> make_ethercat_bus(const config::BusPlan& plan);

}  // namespace drivegate::ethercat
