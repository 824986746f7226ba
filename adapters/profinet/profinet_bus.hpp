#pragma once
// A PROFINET bus (core::Bus): the project's IO controller, RT class 1 [IEC 61158-6-10; the AKD's
// controller procedure, akd-profinet-profidrive.md §24]. One raw Ethernet link (DCP, the RT
// frames, alarms) and two UDP ports (the controller's RPC calls, and port 34964 where the devices
// call ApplicationReady), the sans-I/O engines of controller/ per device, and a PROFIdrive master
// (profiles/profidrive) per axis over the device's telegram and its record-47 parameter channel.
//
// Life cycle, per device (a station used by axes, or by an `io:` device):
//   Find:     StationFinder over the device's own DcpClient: Identify by NameOfStation for the
//             whole window, then Set IP when its IP suite differs (temporary or permanent, the
//             bus option). All devices search at once (each client has its own Xid range).
//   Connect:  a new AR (fresh AR UUID, session key, activity): CmClient Connect with both IOCRs
//             (the bus' send clock, reduction ratio, a phase per device, watchdog = data hold
//             factor), the AlarmCR and the expected submodules (ar_layout.hpp); the records of an IO
//             device's `records:`; PrmEnd; the device's ApplicationReady. From the Connect
//             response on, the output CR runs (IOPS good, data zero until a master or a client
//             writes them) and the input CR's watchdog is armed; the alarm CR is open.
//   Running:  data exchange with valid input frames: the axes are Operational.
//   Wait:     after a failure or a loss: the axes Lost (Offline before the first data
//             exchange), the AR released where it may still exist, Find again after the back-off
//             (1 s, doubling to 16 s while it fails).
// Losses: the input CR's data-hold watchdog (a silent, rebooted or powered-off device), the
// device's ERR-RTA-PDU or an AlarmAck it never acknowledged (alarm_channel.hpp), the AR failing
// in the CmClient, the Ethernet link going down, and a drive that does not follow its STW1
// (TelegramPort::control_lost: the AR is released, which stops the AKD with fault 702 [§18.3]).
// Other devices' ARs are not touched.
//
// link_detail() texts (per device, shared by its axes):
//   station "akd-x" (00:1b:1b:00:0a:01 at 192.168.0.10): searching (DCP identify)
//   <StationFinder's report>                                  found, missing, duplicate, IP set
//   station "akd-x" (...): connecting (AR 3)
//   station "akd-x" (...): in data exchange (AR 3); I&M0 order AKD-P00306-NBPN-0000 serial ... hw 1 sw V1.2.3
//                                           (I&M0 of the DAP, read once data exchange started)
//   station "akd-x" (...): lost: input frame 0xC001 silent for 48 ms (...)
//   station "akd-x" (...): <CmClient's reason> (connect refused, module diff, ...)
//
// Events: each alarm (alarm_channel.hpp's text) as a Warning of the device's axes (a bus event
// for an IO device); the station finder's failures ride on the link detail.
//
// receive() and transmit() are the cyclic path: no allocation, lock, logging or blocking. A
// StationFinder is made (allocated) when a device starts searching: at open() and after a loss,
// never in a cycle of data exchange.
#include <array>
#include <atomic>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "adapters/link/datagram.hpp"
#include "adapters/link/link.hpp"
#include "adapters/profinet/ar_layout.hpp"
#include "adapters/profinet/controller/alarm_channel.hpp"
#include "adapters/profinet/controller/cm_client.hpp"
#include "adapters/profinet/controller/dcp_client.hpp"
#include "adapters/profinet/controller/rt_cyclic.hpp"
#include "adapters/profinet/controller/station_finder.hpp"
#include "config/plan.hpp"
#include "config/profinet/plan.hpp"
#include "core/bus.hpp"
#include "core/event_ring.hpp"
#include "profiles/profidrive/profidrive_master.hpp"

namespace drivegate::profinet {

// Something the bus steps every cycle besides its engines (the in-process simulated devices of
// a `transport: sim` bus).
class PnCyclePeer {
 public:
  virtual ~PnCyclePeer() = default;
  virtual void step(core::TimePoint now) noexcept = 0;
};

// What the bus talks through.
struct ProfinetTransport {
  std::unique_ptr<link::Link> frames;          // raw Ethernet, EtherType 8892h
  std::unique_ptr<link::DatagramPort> client;  // the controller's RPC calls (any port)
  std::unique_ptr<link::DatagramPort> server;  // kRpcUdpPort: the devices' ApplicationReady
  MacAddress mac{};         // the controller's; all zero: read from `interface` at open()
  std::string interface;    // for the MAC and messages
  std::unique_ptr<PnCyclePeer> peer;
};

class ProfinetBus final : public core::Bus {
 public:
  enum class Phase : std::uint8_t { Idle, Find, Connect, Running, Wait };

  static constexpr core::Duration kRetryFirst = std::chrono::seconds(1);
  static constexpr core::Duration kRetryMax = std::chrono::seconds(16);
  static constexpr std::size_t kMaxEvents = 32;
  // Record requests of clients in flight or answered and not yet taken, over all devices.
  static constexpr std::size_t kMaxClientRecords = 4;

  // Throws core::BusError when a device profile has no module idents or a device's AR does not
  // lay out.
  ProfinetBus(const config::BusPlan& plan, ProfinetTransport transport);
  ~ProfinetBus() override;

  std::string_view name() const noexcept override { return name_; }
  std::string_view type() const noexcept override { return "profinet"; }
  void open(core::TimePoint now) override;
  void close() noexcept override;
  std::size_t axis_count() const noexcept override { return axes_.size(); }
  core::AxisController& controller(std::size_t axis) noexcept override { return *axes_[axis]->master; }
  core::LinkState link_state(std::size_t axis) const noexcept override;
  std::string_view link_detail(std::size_t axis) const noexcept override;
  void receive(core::TimePoint now) noexcept override;
  void transmit(core::TimePoint now) noexcept override;
  bool next_event(core::Event& out) noexcept override;
  core::BusCounters counters() const noexcept override;
  std::size_t io_count() const noexcept override { return io_.size(); }
  core::IoInfo io_info(std::size_t k) const noexcept override;
  void io_read(std::size_t k, core::IoSnapshot& out) noexcept override;
  core::IoWriteStatus io_write(std::size_t k, std::size_t offset, std::span<const std::uint8_t> bytes) noexcept override;
  // Records of any API/slot/subslot/index of an axis' device or an IO device, one at a time per
  // device over its CmClient; the PROFIdrive parameter channel (record 47 of an axis' telegram
  // submodule) stays the master's.
  core::Admission record(const core::ParamRequest& req, core::TimePoint now) noexcept override;
  bool next_record_reply(core::ParamReply& out) noexcept override;

  // Diagnostics (bus thread, or while the bus is not cycling).
  [[nodiscard]] std::size_t device_count() const noexcept { return devices_.size(); }
  [[nodiscard]] Phase phase(std::size_t device) const noexcept { return devices_[device]->phase; }
  [[nodiscard]] std::string_view device_detail(std::size_t device) const noexcept { return devices_[device]->detail.view(); }
  [[nodiscard]] std::uint64_t ars(std::size_t device) const noexcept { return devices_[device]->ars; }
  // The device's I&M0 as read at the start of its last data exchange ("" before).
  [[nodiscard]] std::string_view identity(std::size_t device) const noexcept { return devices_[device]->identity.view(); }
  [[nodiscard]] const CmClient* cm(std::size_t device) const noexcept {
    return devices_[device]->cm ? &*devices_[device]->cm : nullptr;
  }
  [[nodiscard]] const RtConsumer* input_cr(std::size_t device) const noexcept {
    return devices_[device]->consumer ? &*devices_[device]->consumer : nullptr;
  }
  [[nodiscard]] const AlarmChannel* alarms(std::size_t device) const noexcept {
    return devices_[device]->alarms ? &*devices_[device]->alarms : nullptr;
  }
  [[nodiscard]] std::uint64_t events_dropped() const noexcept { return events_.dropped(); }

 private:
  struct Device;
  struct Axis;

  // The record-47 channel of one axis over its device's CmClient [§5.1]: write the request,
  // then read the response (again while the drive answers "state conflict": not ready yet).
  class RecordChannel final : public profidrive::ParamChannel {
   public:
    RecordChannel(Device& device, std::uint32_t api, std::uint16_t slot, std::uint16_t subslot) noexcept
        : device_(device), api_(api), slot_(slot), subslot_(subslot) {}
    profidrive::ParamTicket submit(std::span<const std::uint8_t> request) noexcept override;
    profidrive::ParamResult poll(profidrive::ParamTicket ticket) noexcept override;
    void cancel(profidrive::ParamTicket ticket) noexcept override;
    // The CmClient's reply to one of this channel's records (false: not ours).
    bool on_reply(const CmRecordReply& reply) noexcept;
    // Once per cycle: a read that is due goes out.
    void step() noexcept;
    // The AR ended: an exchange in flight fails.
    void ar_ended() noexcept;
    // Record 47 of this submodule is this channel's.
    [[nodiscard]] bool carries(std::uint16_t slot, std::uint16_t subslot) const noexcept {
      return slot == slot_ && subslot == subslot_;
    }

   private:
    enum class State : std::uint8_t { Idle, Writing, ReadDue, Reading, Done, Failed };
    void fail(std::string_view why) noexcept;
    Device& device_;
    std::uint32_t api_;
    std::uint16_t slot_, subslot_;
    State state_ = State::Idle;
    profidrive::ParamTicket ticket_ = profidrive::kNoTicket;
    profidrive::ParamTicket last_ticket_ = profidrive::kNoTicket;
    CmRecordId record_ = 0;
    int reads_ = 0;
    std::array<std::uint8_t, 240> request_{};
    std::size_t request_size_ = 0;
    std::array<std::uint8_t, 240> response_{};
    std::size_t response_size_ = 0;
    core::FixedString<300> error_{};
  };

  // The telegram submodule of one axis in its device's CRs.
  class Telegram final : public profidrive::TelegramPort {
   public:
    Telegram(Device& device, std::size_t submodule, std::size_t out_size) noexcept
        : device_(device), submodule_(submodule), out_size_(out_size) {}
    std::span<const std::uint8_t> actual() const noexcept override;
    bool actual_fresh() const noexcept override;
    std::span<std::uint8_t> setpoint() noexcept override;
    void control_lost(std::string_view why) noexcept override;

   private:
    Device& device_;
    std::size_t submodule_;
    std::size_t out_size_;
    std::array<std::uint8_t, 64> parked_{};  // the setpoint while there is no output CR
  };

  struct Axis {
    std::size_t device = 0;
    std::vector<profidrive::FaultText> faults;  // views into the plan's device profile
    std::unique_ptr<RecordChannel> channel;
    std::unique_ptr<Telegram> telegram;
    std::unique_ptr<profidrive::ProfidriveMaster> master;
  };

  struct IoDevice {
    std::string name;
    std::size_t device = 0;
    std::vector<std::size_t> submodules;  // indices in the device's layout, in slot order
    std::size_t input_size = 0;
    std::size_t output_size = 0;
    std::array<std::uint8_t, core::kMaxIoBytes> outputs{};  // what goes out; zero after a loss
  };

  struct Device final : CmRecordListener, AlarmListener {
    ProfinetBus* bus = nullptr;
    std::size_t index = 0;
    StationConfig station;
    std::unique_ptr<ArLayout> layout;
    std::vector<std::vector<std::uint8_t>> record_data;  // the parameter records' bytes
    std::vector<CmRecordWrite> parameters;
    std::vector<std::size_t> axes;
    std::optional<std::size_t> io;
    std::optional<DcpClient> dcp;
    std::unique_ptr<StationFinder> finder;
    MacAddress mac{};
    std::uint32_t ip = 0;
    std::uint16_t vendor_id = 0, device_id = 0;
    Phase phase = Phase::Idle;
    core::TimePoint since{};
    core::Duration backoff{};
    bool had_op = false;
    std::uint64_t ars = 0;
    CmClientConfig cm_config{};
    std::optional<CmClient> cm;
    std::optional<RtProvider> provider;
    std::optional<RtConsumer> consumer;
    std::optional<AlarmChannel> alarms;
    bool cyclic = false;            // the CRs and the alarm CR run for the present AR
    std::uint64_t frames_seen = 0;  // the consumer's frame count at the previous cycle
    bool fresh = false;             // a new input frame was taken this cycle
    CmRecordId im0_read = 0;        // the I&M0 read of the DAP after the start of data exchange
    core::FixedString<160> identity{};  // from I&M0: order ID, serial, revisions ("" before)
    CmRecordId client_record = 0;   // a client's record request in flight (record())
    core::ParamReply client_reply{};  // its reply as far as known at submit (id, axis, type, a write's bytes)
    bool lose_pending = false;      // control lost: lose it at the next step
    core::FixedString<200> lose_reason{};
    core::FixedString<400> detail{};
    std::atomic<core::LinkState> link{core::LinkState::Offline};

    void on_record_reply(const CmRecordReply& reply) noexcept override;
    void on_alarm(const AlarmEvent& event) noexcept override;
    [[nodiscard]] bool exchanging() const noexcept;  // Running with valid inputs
  };

  void set_detail(Device& d, const char* fmt, ...) noexcept __attribute__((format(printf, 3, 4)));
  void enter(Device& d, Phase p, core::TimePoint now) noexcept;
  void start_find(Device& d, core::TimePoint now);
  void found(Device& d, core::TimePoint now) noexcept;
  void connect(Device& d, core::TimePoint now) noexcept;
  void start_cyclic(Device& d, core::TimePoint now) noexcept;
  void stop_cyclic(Device& d) noexcept;
  void lose(Device& d, std::string_view why, core::TimePoint now) noexcept;
  void step(Device& d, core::TimePoint now) noexcept;
  void dispatch_frame(std::span<const std::uint8_t> frame, core::TimePoint now) noexcept;
  void dispatch_datagram(const link::Datagram& g, CmSocket socket, core::TimePoint now) noexcept;
  void flush_datagrams() noexcept;
  void send_frame(std::span<const std::uint8_t> frame) noexcept;
  void handle_link(core::TimePoint now) noexcept;
  void push_event(const core::Event& e) noexcept;
  // The client record of `d` ends: with the CmClient's reply, or failed for `why` (reply null).
  void client_record_done(Device& d, const CmRecordReply* reply, std::string_view why) noexcept;

  std::string name_;
  config::ProfinetBusOptions options_;
  ProfinetTransport transport_;
  std::vector<std::unique_ptr<Device>> devices_;
  std::vector<std::unique_ptr<Axis>> axes_;
  std::vector<IoDevice> io_;
  std::uint64_t uuid_seed_ = 0;
  bool open_ = false;
  link::LinkState link_seen_ = link::LinkState::Closed;
  core::TimePoint last_now_{};
  CmOutbox out_;
  std::array<link::FrameBuffer, 8> rx_{};
  link::Datagram datagram_{};
  std::array<std::uint8_t, link::kMaxFrameBytes> tx_{};

  core::EventRing<kMaxEvents> events_;
  std::array<core::ParamReply, kMaxClientRecords> record_replies_{};  // a ring
  std::size_t record_head_ = 0, record_count_ = 0;
  std::size_t records_in_flight_ = 0;
  std::array<std::uint8_t, core::kMaxParamBytes> record_scratch_{};  // a write's bytes in record order

  std::atomic<std::uint64_t> sent_{0};
  std::atomic<std::uint64_t> received_{0};
  std::atomic<std::uint64_t> lost_{0};
  std::atomic<std::uint64_t> dropped_{0};
  std::atomic<std::uint64_t> errors_{0};
};

// The bus of a plan: transport raw -> the raw link and UDP ports on the bus' interface; transport
// sim -> make_simulated_profinet_bus (sim_transport.hpp).
std::unique_ptr<ProfinetBus> make_profinet_bus(const config::BusPlan& plan);

}  // namespace drivegate::profinet
