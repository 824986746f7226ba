#pragma once
// The device side of PN-DCP for the simulated PROFINET devices [IEC 61158-6-10 §4.3], sans-I/O:
// on_frame() takes what the device's port receives, poll() gives the frames it sends (into the
// caller's buffer, one per call), the time is a parameter.
//
//   Identify (to 01-0E-CF-00-00-00 or the device's MAC): answered when the filter is the
//     AllSelector or the device's own NameOfStation; any other filter block (alias, DeviceID, IP,
//     ...) is not matched here, so such requests go unanswered (counted). The response leaves
//     after 10 ms × (R mod ResponseDelayFactor), R = the last two octets of the device's MAC as
//     a big-endian number: a fixed spread per device, so two devices answer at different times
//     when their MACs differ there [§4.3, ResponseDelayFactor: a value derived from the MAC]. A
//     factor of 0 (reserved) is taken as 1; one above 1900h as 1900h.
//   Get: one block per option asked for, with BlockInfo 0 (IP: set / not set); an option the
//     device does not have gets a Control/Response block with BlockError 1 (option) or 2
//     (suboption not supported).
//   Set: every block is answered by a Control/Response block with its BlockError: NameOfStation
//     (a valid name, or empty to remove it: else 3 "suboption not set"), IP parameter (a usable
//     suite, wire ip_suite_problem(), else 3), Signal (counted, the callback called), Start /
//     End Transaction (accepted). Any other option: 1, another suboption of a known option: 2.
//     While an AR is established (set_in_operation) NameOfStation and IP are refused with 6 "in
//     operation" (the AKD refuses DCP Set then: akd-profinet-profidrive.md §3.1 step 5).
//     BlockQualifier bit 0: permanent values survive power_cycle(); a temporary Set changes the
//     value now and clears the stored one, so after a power cycle the device has no name (no IP).
//     A Set or Get with the Xid and source of the last one is a retry: the stored response goes
//     out again and nothing is done twice.
//   Frames that do not decode, and requests with no block, are counted malformed and dropped.
//   Responses and other traffic are ignored (counted).
//
// Fixed buffers: nothing allocates after construction.
#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <string_view>

#include "adapters/profinet/wire/dcp.hpp"
#include "adapters/profinet/wire/ethernet.hpp"
#include "adapters/profinet/wire/station_name.hpp"
#include "core/clock.hpp"

namespace drivegate::profinet {

struct DcpResponderConfig {
  MacAddress mac{};
  std::string type_of_station;    // DeviceVendorValue, at most 240 octets
  std::uint16_t vendor_id = 0;
  std::uint16_t device_id = 0;
  std::uint8_t device_role = device_role::kIoDevice;
  std::uint8_t instance_high = 0;
  std::uint8_t instance_low = 1;
  std::string name_of_station;    // the stored name ("" = none); must be valid when not empty
  IpSuite ip{};                   // the stored IP suite (0.0.0.0 = none)
};

struct DcpResponderCounters {
  std::uint64_t identify_answered = 0;
  std::uint64_t identify_not_matched = 0;   // another name asked for
  std::uint64_t identify_other_filter = 0;  // a filter this responder does not match (unanswered)
  std::uint64_t gets = 0, sets = 0, set_errors = 0;  // set_errors: blocks answered with a BlockError
  std::uint64_t signals = 0;
  std::uint64_t retries_answered = 0;   // a Set/Get seen again: the stored response resent
  std::uint64_t not_for_us = 0;         // unicast to another MAC
  std::uint64_t ignored = 0;            // responses, Hellos, other FrameIDs
  std::uint64_t malformed = 0;
  std::uint64_t tx_dropped = 0;         // a response that found the send queue full
  std::uint64_t tx_too_small = 0;       // poll() given a buffer shorter than the frame
};

class DcpResponder {
 public:
  static constexpr std::size_t kTxSlots = 4;

  // Throws std::invalid_argument for a name that breaks the NameOfStation rules, an unusable IP
  // suite or a TypeOfStation over 240 octets.
  explicit DcpResponder(const DcpResponderConfig& config);

  bool on_frame(std::span<const std::uint8_t> frame, core::TimePoint now) noexcept;
  std::size_t poll(core::TimePoint now, std::span<std::uint8_t> out) noexcept;
  [[nodiscard]] core::TimePoint next_deadline() const noexcept;

  // Power lost and back: temporary values are gone, the stored ones come back; queued responses
  // are lost.
  void power_cycle() noexcept;
  // An AR is established (the controller connected): DCP Set of name and IP is refused.
  void set_in_operation(bool in_operation) noexcept { in_operation_ = in_operation; }
  // Called for each Set Signal (the LED flashes), besides counters().signals.
  void on_signal(std::function<void()> callback) { on_signal_ = std::move(callback); }

  [[nodiscard]] std::string_view name_of_station() const noexcept { return {name_.data(), name_length_}; }
  [[nodiscard]] const IpSuite& ip() const noexcept { return ip_; }
  [[nodiscard]] const MacAddress& mac() const noexcept { return mac_; }
  // The response delay for a factor (above).
  [[nodiscard]] core::Duration response_delay(std::uint16_t factor) const noexcept;
  [[nodiscard]] const DcpResponderCounters& counters() const noexcept { return counters_; }

 private:
  struct TxSlot {
    bool used = false;
    core::TimePoint due{};
    std::size_t length = 0;
    std::array<std::uint8_t, kMaxFrameSize> frame{};
  };

  DcpDeviceInfo device_info() const noexcept;
  // Reserves a send slot due at `due` and returns the span after its Ethernet header (empty when
  // no slot is free); commit() finishes the frame.
  TxSlot* reserve(core::TimePoint due) noexcept;
  bool commit(TxSlot& slot, const MacAddress& to, std::uint16_t frame_id, std::size_t pdu_length) noexcept;
  void on_identify(const EthernetView& e, const DcpPdu& pdu, core::TimePoint now) noexcept;
  void on_get(const EthernetView& e, const DcpPdu& pdu, core::TimePoint now) noexcept;
  void on_set(const EthernetView& e, const DcpPdu& pdu, core::TimePoint now) noexcept;
  DcpBlockError apply(const DcpSetBlock& block) noexcept;
  bool resend_if_retry(const EthernetView& e, const DcpPdu& pdu, core::TimePoint now) noexcept;
  void remember(const EthernetView& e, const DcpPdu& pdu, const TxSlot& slot) noexcept;
  void set_name(std::string_view name) noexcept;

  MacAddress mac_;
  std::string type_of_station_;
  std::uint16_t vendor_id_, device_id_;
  std::uint8_t device_role_, instance_high_, instance_low_;
  // Current values, and what survives a power cycle.
  std::array<char, kMaxNameOfStationLength> name_{};
  std::size_t name_length_ = 0;
  IpSuite ip_{};
  std::array<char, kMaxNameOfStationLength> stored_name_{};
  std::size_t stored_name_length_ = 0;
  IpSuite stored_ip_{};
  bool in_operation_ = false;
  std::function<void()> on_signal_;

  std::array<TxSlot, kTxSlots> tx_{};
  // The last Set/Get answered: its requester, Xid and response, for retries.
  bool have_last_ = false;
  MacAddress last_src_{};
  std::uint32_t last_xid_ = 0;
  DcpService last_service_ = DcpService::Set;
  std::size_t last_length_ = 0;
  std::array<std::uint8_t, kMaxFrameSize> last_frame_{};
  DcpResponderCounters counters_{};
};

}  // namespace drivegate::profinet
