#pragma once
// The CANopen bus scan (`drivegated --scan canopen:WHERE`, DESIGN.md §7): which nodes are on the
// bus, what they are, and which device profile runs them.
//
// It only listens and reads; it never changes anything on the bus: no NMT command, no SDO
// download. What it sends are SDO upload requests on each node's default SDO channel (600h + N),
// and, as CiA 301 has a client do, an SDO abort (05040000h) for a request that got no answer.
//
//   1. Listen for `listen`: boot-ups and heartbeats (700h + N), EMCY and TPDOs name nodes that are
//      there; SYNC, NMT, RPDOs, SDO requests and guarding requests mean another master runs the bus.
//      Then the scan stops without sending anything (refusal()): its requests on 600h + N would
//      break that master's SDO transfers on the same channels.
//   2. Read 1000h on every node-ID 1..127 at once: each node has its own SDO server channel, so
//      the 127 uploads run in parallel.
//   3. A node that answered (a value or an abort) is asked, in order, 1018h:01..04, 1008h, 1009h
//      and 100Ah. An object the node lacks is "not present"; an abort or a timeout on one object
//      does not stop the others.
//
// One SDO server answers each request once. A second answer to one of these requests (a second
// initiate response or abort for the same object) means more than one device answers on that
// node-ID's channel: a node-ID conflict, or another drive's extra SDO channel. The scan keeps the
// first answer, drops the others (they would confuse the next request on the channel) and says
// which answers came twice; the node's identity is then a mix that cannot be trusted.
//
// Every request has `answer_timeout` plus the time 2 x 127 frames take on the wire at the bus'
// bit rate (the probe's requests and answers queue on the wire) and no retry; so the scan ends by
// itself: with nobody there after listen + about one timeout, in the worst case (a node that
// answers 1000h and then nothing) after listen + 8 timeouts. A hard deadline a little beyond that
// cancels whatever is left.
//
// CanopenScan is the sans-I/O engine (adapters/canopen/README.md): frames and time in, frames out.
// run_scan() drives it on a real transport; tests drive it on the in-process bus in virtual time.
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "adapters/canopen/master/sdo_client.hpp"
#include "adapters/canopen/master/tx_queue.hpp"
#include "adapters/canopen/wire/can_frame.hpp"
#include "adapters/canopen/wire/nmt_codec.hpp"
#include "adapters/canopen/wire/sdo_codec.hpp"
#include "config/bus_types.hpp"
#include "config/plan.hpp"
#include "core/clock.hpp"
#include "core/scan.hpp"

namespace drivegate::canopen {

struct CanopenScanSettings {
  core::Duration listen = std::chrono::milliseconds(200);
  core::Duration answer_timeout = std::chrono::milliseconds(100);
  std::uint32_t bitrate = 500000;  // bit/s, for the time the probe's frames take on the wire
  std::uint16_t string_limit = 256;  // bytes read of 1008h, 1009h, 100Ah at most
};

// The frames of another master, by kind.
struct ForeignMasterFrames {
  std::uint64_t sync = 0;
  std::uint64_t nmt = 0;
  std::uint64_t rpdo = 0;
  std::uint64_t sdo_requests = 0;
  std::uint64_t guarding = 0;                        // node guarding RTRs on 700h + N
  std::array<bool, kMaxNodeId + 1> sdo_request_on{};  // [N]: an SDO request on 600h + N
  [[nodiscard]] std::uint64_t total() const noexcept { return sync + nmt + rpdo + sdo_requests + guarding; }
};

struct CanopenScanCounters {
  std::uint64_t frames = 0;              // frames received
  std::uint64_t malformed = 0;           // error-control frames of a wrong length or state, frames past 11 bits
  std::uint64_t foreign_master = 0;      // SYNC, NMT, RPDO, SDO requests and guarding RTRs from another master
  std::uint64_t sdo_unexpected = 0;      // SDO answers that fit no request (SdoClient::counters())
  std::uint64_t sdo_malformed = 0;
};

// What the scan learned of one node-ID.
struct ScannedNode {
  NodeId node = 0;
  bool heard = false;        // it sent something of its own (boot-up, heartbeat, EMCY, TPDO)
  bool boot_up = false;      // its boot-up message came during the scan
  NmtState state = NmtState::Unknown;  // from its last heartbeat
  bool answered = false;     // its SDO server answered the 1000h probe (a value or an abort)
  std::optional<std::uint32_t> device_type;
  core::DeviceIdentityNumbers identity;
  std::optional<std::string> name;
  std::optional<std::string> hardware_version;
  std::optional<std::string> software_version;
  std::vector<std::string> notes;
  // Not empty when more than one device answers at this node-ID: the objects answered twice and
  // how ("1000h: answered twice, differently: 0x00020192 and 0x00000192").
  std::vector<std::string> second_answers;
};

class CanopenScan {
 public:
  // Allocates everything it needs; the scan starts (listening) at `start`.
  CanopenScan(CanopenScanSettings settings, core::TimePoint start);

  void on_frame(const CanFrame& frame, core::TimePoint now) noexcept;
  void poll(core::TimePoint now, TxQueue& tx);
  [[nodiscard]] core::TimePoint next_deadline() const noexcept;
  // Every request answered, failed or cancelled at the hard deadline.
  [[nodiscard]] bool done() const noexcept { return phase_ == Phase::Done; }

  // The nodes that were heard or answered, by node-ID (after done()).
  [[nodiscard]] std::vector<ScannedNode> nodes() const;
  [[nodiscard]] CanopenScanCounters counters() const noexcept;
  [[nodiscard]] core::TimePoint hard_deadline() const noexcept { return hard_deadline_; }
  // Why the scan stopped after listening without sending a request (another master is active);
  // empty when it did not.
  [[nodiscard]] const std::string& refusal() const noexcept { return refusal_; }

 private:
  // The requests asked of a node after its probe, in this order.
  static constexpr std::size_t kIdentityReads = 7;
  enum class Phase : std::uint8_t { Listen, Probe, Done };
  // The answers to one object the scan asks (1000h, then the identity reads).
  struct Answers {
    std::optional<SdoBytes> first;
    std::optional<SdoBytes> second;  // the first answer one server would not have given
    bool segmented = false;          // `first` opened a segmented upload: the server may still abort it
  };
  struct Node {
    ScannedNode seen;
    std::array<Answers, kIdentityReads + 1> answers;
    SdoRequestId probe = kNoSdoRequest;
    std::array<SdoRequestId, kIdentityReads> reads{};
    std::array<std::vector<std::uint8_t>, 3> strings;  // 1008h, 1009h, 100Ah buffers
    bool finished = false;  // every request of the node has its outcome
  };

  // False when `frame` is a second answer to a request of `n` (noted, not for the SDO client).
  bool first_answer(Node& n, const CanFrame& frame) noexcept;
  void submit_identity(Node& n) noexcept;
  void collect(Node& n, core::TimePoint now);
  void finish_all();

  CanopenScanSettings settings_;
  core::TimePoint listen_end_;
  core::TimePoint hard_deadline_;
  Phase phase_ = Phase::Listen;
  SdoClient sdo_;
  std::array<Node, kMaxNodeId + 1> nodes_;  // [0] unused
  CanopenScanCounters counters_;
  ForeignMasterFrames foreign_;
  std::string refusal_;
};

// The bus a scan request names, checked by the same rules as a configuration file's canopen bus:
// WHERE is `INTERFACE` or `socketcan` (SocketCAN) or `udp-multicast`, then options
// `?key=value&key=value` (socketcan: interface, bitrate; udp-multicast: group, port, interface,
// bitrate). Throws core::ScanError naming the option and what it takes.
config::BusPlan scan_bus_plan(const core::ScanRequest& request, const config::BusTypeRegistry& types);

// The scan on the plan's transport in real time, then the table's rows: each node with its device
// type in words and the device profile (from request.device_dirs) that fits it. Throws
// core::ScanError when the transport does not open (no AF_CAN in the kernel, no such interface).
core::ScanResult run_scan(const config::BusPlan& plan, const core::ScanRequest& request,
                          const config::BusTypeRegistry& types);

// The rows of what `scan` saw, profiles matched; what run_scan() returns without the timing.
// `bitrate_given`: the scan request named the bit rate (SocketCAN does not tell it); when not, the
// skeleton marks it CHECK. Throws core::ScanError with scan.refusal() when the scan refused.
core::ScanResult scan_result(const CanopenScan& scan, const config::BusPlan& plan,
                             const std::vector<config::DeviceProfile>& profiles, bool bitrate_given);

// Whether the scan request's WHERE names `key` as an option ("can0?bitrate=250000": bitrate).
bool scan_option_given(const core::ScanRequest& request, const std::string& key);

// The device profiles with a canopen section in the directories, in name order; broken ones are
// left out with a note in `notes`.
std::vector<config::DeviceProfile> scan_profiles(const std::vector<std::filesystem::path>& dirs,
                                                 const config::BusTypeRegistry& types, std::vector<std::string>& notes);

// "CiA 402 servo drive", "CiA 401 I/O module", "device profile 405", ... for a 1000h value.
std::string device_type_text(std::uint32_t device_type);

}  // namespace drivegate::canopen
