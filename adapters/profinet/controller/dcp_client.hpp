#pragma once
// The controller side of PN-DCP [IEC 61158-6-10 §4.3], sans-I/O: requests go in, whole Ethernet
// frames come out of poll() into the caller's buffer, received frames go to on_frame(), and the
// time is a parameter (DESIGN.md §2 rule 1).
//
//   Identify all / by NameOfStation: multicast to 01-0E-CF-00-00-00 with a ResponseDelayFactor;
//     each device answers after 10 ms × (a value of its own mod the factor), so the client
//     collects the responses until the window identify_window(factor) closes and the request is
//     Done with every station that answered (into the caller's array; those beyond it are
//     counted). A response whose name is not the one asked for, or a second one from a MAC
//     already listed, is counted and dropped.
//   Set NameOfStation / IP parameter (temporary or permanent) / Control Signal (flash once):
//     unicast to one MAC; the request fails on the first Control/Response block with an error
//     (its BlockError kept: to_string(DcpBlockError)), on a response "request not supported",
//     or when no response came in `set_timeout` after 1 + `set_retries` frames. A retry keeps its
//     Xid, so a device that saw the first frame answers again without acting twice.
//
// Every request has its own Xid (incremented per request from `first_xid`). Responses are matched
// by destination (our MAC), FrameID, ServiceID, ServiceType, Xid and (Set) the source MAC;
// well-formed DCP frames that do not match are counted by reason and dropped (another Xid, another
// service, a Hello, a request or response of another controller), frames that do not decode are
// counted malformed.
//
// One request at a time, the others wait in a FIFO of kQueueDepth. Nothing here allocates.
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

#include "adapters/profinet/wire/dcp.hpp"
#include "adapters/profinet/wire/ethernet.hpp"
#include "adapters/profinet/wire/station_name.hpp"
#include "core/clock.hpp"

namespace drivegate::profinet {

// How long a controller collects Identify responses for a ResponseDelayFactor: the devices spread
// their answers over factor × 10 ms [IEC 61158-6-10 §4.3, ResponseDelayFactor]; the client waits
// that spread plus 1 s, rounded up to whole seconds, and 400 ms when the factor asks for no
// spread (0 or 1). [The controller's timer is not in the public digests; these are the values
// public DCP stacks use.]
core::Duration identify_window(std::uint16_t response_delay_factor) noexcept;

// One station that answered an Identify: copies of the fields, not views into the frame.
struct DcpStation {
  MacAddress mac{};  // the response's source address (what Set is sent to)
  bool has_name = false;
  std::uint8_t name_length = 0;
  std::array<char, kMaxNameOfStationLength> name_chars{};
  bool has_type_of_station = false;
  std::uint8_t type_length = 0;  // TypeOfStation longer than the array is cut (type_truncated)
  bool type_truncated = false;
  std::array<char, 64> type_chars{};
  bool has_device_id = false;
  std::uint16_t vendor_id = 0;
  std::uint16_t device_id = 0;
  bool has_device_role = false;
  std::uint8_t device_role = 0;
  bool has_ip = false;
  std::uint16_t ip_block_info = 0;
  IpSuite ip{};

  std::string_view name() const noexcept { return {name_chars.data(), name_length}; }
  std::string_view type_of_station() const noexcept { return {type_chars.data(), type_length}; }
};

struct DcpClientTiming {
  core::Duration set_timeout = std::chrono::milliseconds(500);  // per frame of a Set
  int set_retries = 2;                                            // frames sent again after a timeout
};

using DcpRequestId = std::uint32_t;  // 0 = refused
inline constexpr DcpRequestId kNoDcpRequest = 0;

enum class DcpRequestStatus : std::uint8_t { Unknown, Queued, InFlight, Done, Failed };
std::string_view to_string(DcpRequestStatus s) noexcept;

enum class DcpFailure : std::uint8_t {
  None,
  Timeout,         // no Set response after all the frames
  BlockError,      // the device answered with a BlockError (DcpResult::block_error)
  NotSupported,    // the device answered ServiceType "request not supported"
  BadResponse,     // the device answered with a Set response without our block's result
  BufferTooSmall,  // poll() was given a buffer shorter than the request's frame: never sent
};
std::string_view to_string(DcpFailure f) noexcept;

struct DcpResult {
  DcpRequestStatus status = DcpRequestStatus::Unknown;
  DcpFailure failure = DcpFailure::None;
  DcpBlockError block_error = DcpBlockError::NoError;  // failure == BlockError
  std::uint16_t option = 0;      // the Set's Option/Suboption (dcp_option::), 0 for Identify
  std::uint32_t xid = 0;
  MacAddress target{};           // Set: the device
  int frames_sent = 0;
  std::size_t stations = 0;      // Identify: entries written into the caller's array
  std::size_t stations_lost = 0; // Identify: answers that did not fit it
};

struct DcpClientCounters {
  std::uint64_t requests = 0, completed = 0, failed = 0, queue_full = 0, refused = 0;
  std::uint64_t frames_sent = 0, retries = 0, timeouts = 0;
  std::uint64_t responses = 0;          // matched and used
  std::uint64_t foreign_xid = 0;        // a response with another Xid (late, or another controller's)
  std::uint64_t wrong_service = 0;      // the Xid in flight but another service, type or FrameID
  std::uint64_t wrong_source = 0;       // a Set response from another MAC than the target
  std::uint64_t wrong_name = 0;         // an Identify-by-name response with another name
  std::uint64_t duplicate_answers = 0;  // a second Identify response from one MAC
  std::uint64_t unsolicited = 0;        // a response while nothing is in flight
  std::uint64_t not_for_us = 0;         // a response addressed to another MAC
  std::uint64_t requests_seen = 0;      // DCP requests and Hellos (not for a controller)
  std::uint64_t malformed = 0;          // did not decode (Ethernet or DCP)
  std::uint64_t tx_too_small = 0;       // poll() was given a buffer shorter than the frame (request failed)
};

class DcpClient {
 public:
  static constexpr std::size_t kQueueDepth = 8;  // requests queued or in flight

  explicit DcpClient(const MacAddress& own_mac, DcpClientTiming timing = {}, std::uint32_t first_xid = 1) noexcept;

  // Identify into the caller's array (it must stay valid until take()). The factor is 1..1900h;
  // the name must be a valid NameOfStation. kNoDcpRequest when refused or the queue is full.
  DcpRequestId identify_all(std::span<DcpStation> into, std::uint16_t response_delay_factor) noexcept;
  DcpRequestId identify_name(std::string_view name, std::span<DcpStation> into,
                             std::uint16_t response_delay_factor = 1) noexcept;
  DcpRequestId set_name(const MacAddress& device, std::string_view name, DcpQualifier qualifier) noexcept;
  DcpRequestId set_ip(const MacAddress& device, const IpSuite& ip, DcpQualifier qualifier) noexcept;
  DcpRequestId signal(const MacAddress& device) noexcept;

  [[nodiscard]] DcpResult result(DcpRequestId id) const noexcept;
  // Identify: the stations found so far (all of them once Done).
  [[nodiscard]] std::span<const DcpStation> stations(DcpRequestId id) const noexcept;
  // Forgets a finished request (or drops a queued one; one in flight is finished first and its
  // result then discarded) and returns its last result.
  DcpResult take(DcpRequestId id) noexcept;

  // Engine interface. poll() writes at most one frame into `out` and returns its length (0: none
  // due); call it until it returns 0. It also closes Identify windows and times Sets out. A frame
  // that does not fit `out` fails its request (BufferTooSmall) instead of staying due, so a
  // caller's loop on poll() or next_deadline() ends.
  std::size_t poll(core::TimePoint now, std::span<std::uint8_t> out) noexcept;
  // True when the frame was a DCP frame (used or counted); false for other traffic.
  bool on_frame(std::span<const std::uint8_t> frame, core::TimePoint now) noexcept;
  // TimePoint::min() while a frame waits for poll(), else the end of the window or timeout in
  // flight, else TimePoint::max().
  [[nodiscard]] core::TimePoint next_deadline() const noexcept;
  [[nodiscard]] bool idle() const noexcept;

  [[nodiscard]] const DcpClientCounters& counters() const noexcept { return counters_; }
  [[nodiscard]] const MacAddress& mac() const noexcept { return own_mac_; }

 private:
  enum class Kind : std::uint8_t { IdentifyAll, IdentifyName, SetName, SetIp, Signal };
  enum class State : std::uint8_t { Free, Queued, Sending, Waiting, Done, Failed };
  struct Slot {
    State state = State::Free;
    Kind kind = Kind::IdentifyAll;
    std::uint16_t generation = 0;
    std::uint64_t order = 0;  // FIFO position
    bool abandoned = false;   // taken while in flight: freed when it ends
    DcpResult result{};
    std::uint16_t factor = 1;
    std::uint8_t name_length = 0;
    std::array<char, kMaxNameOfStationLength> name{};
    IpSuite ip{};
    DcpQualifier qualifier = DcpQualifier::Temporary;
    std::span<DcpStation> into{};
    core::TimePoint deadline{};
  };

  DcpRequestId submit(Kind kind, const MacAddress& target, std::uint16_t option) noexcept;
  Slot* find(DcpRequestId id) noexcept;
  const Slot* find(DcpRequestId id) const noexcept;
  Slot* in_flight() noexcept;
  void start_next() noexcept;
  void finish(Slot& s, DcpFailure failure) noexcept;
  std::size_t encode(Slot& s, std::span<std::uint8_t> out) noexcept;
  void on_identify_response(Slot& s, const EthernetView& e, const DcpPdu& pdu) noexcept;
  void on_set_response(Slot& s, const EthernetView& e, const DcpPdu& pdu) noexcept;
  static std::string_view name_of(const Slot& s) noexcept { return {s.name.data(), s.name_length}; }
  static bool is_identify(Kind k) noexcept { return k == Kind::IdentifyAll || k == Kind::IdentifyName; }

  MacAddress own_mac_;
  DcpClientTiming timing_;
  std::uint32_t next_xid_;
  std::uint64_t next_order_ = 0;
  int current_ = -1;  // slot in flight (Sending or Waiting), -1 none
  std::array<Slot, kQueueDepth> slots_{};
  DcpClientCounters counters_{};
};

}  // namespace drivegate::profinet
