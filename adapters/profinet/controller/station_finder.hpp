#pragma once
// The controller's DCP start-up [IEC 61158-6-10 §4.3; akd-profinet-profidrive.md §24 steps 3-4]:
// for each configured station, in order,
//
//   1. Identify by its NameOfStation and collect the answers for the whole window;
//   2. no answer: Missing. Two or more MACs: Duplicate, none of them is used (each MAC named);
//   3. an expected vendor/device ID that differs from the answer's DeviceID: WrongDevice;
//   4. the IP suite the device reports equals the configured one: Ready; else Set IP parameter
//      (temporary by default: the controller assigns it again at every start) and IpAssigned, or
//      IpSetFailed with the device's BlockError or the timeout.
//
// A configured name that breaks the NameOfStation rules, an unusable IP suite, or a name or
// address given to two stations, is InvalidConfig without any traffic. Each station ends with a
// report: its MAC, IP and device IDs, and one line of text for a person. Devices without a name
// are not named here (by MAC) yet: the config addresses devices by name.
//
// Sans-I/O over a DcpClient the caller owns (and may use for other requests in between). Built
// and run at start-up: the reports are std::strings; the frames pass without allocation.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "adapters/profinet/controller/dcp_client.hpp"

namespace drivegate::profinet {

struct StationConfig {
  std::string name;                       // NameOfStation
  IpSuite ip{};                           // address, netmask, gateway wanted
  std::optional<std::uint16_t> vendor_id; // checked against the DeviceID block when given
  std::optional<std::uint16_t> device_id;
};

enum class StationOutcome : std::uint8_t {
  Pending,
  Ready,          // found, the IP suite was already the configured one
  IpAssigned,     // found, the IP suite set
  Missing,        // no device answered to the name
  Duplicate,      // two or more devices answered to the name: none used
  WrongDevice,    // the DeviceID is not the configured one
  IpSetFailed,    // Set IP refused or not answered
  InvalidConfig,  // the configured name or IP suite cannot be used
};
std::string_view to_string(StationOutcome o) noexcept;

struct StationReport {
  std::string name;
  StationOutcome outcome = StationOutcome::Pending;
  MacAddress mac{};             // the device found (Ready, IpAssigned, WrongDevice, IpSetFailed)
  IpSuite ip{};                 // its IP suite now (the configured one after IpAssigned)
  IpSuite previous_ip{};        // IpAssigned: what it had before
  bool has_device_id = false;
  std::uint16_t vendor_id = 0;
  std::uint16_t device_id = 0;
  std::vector<MacAddress> macs;  // Duplicate: every MAC that answered
  std::string text;              // one line: what was found or why the station cannot be used
  bool ok() const noexcept { return outcome == StationOutcome::Ready || outcome == StationOutcome::IpAssigned; }
};

struct StationFinderOptions {
  std::uint16_t response_delay_factor = 1;        // of the Identify by name (1: answer at once)
  DcpQualifier ip_qualifier = DcpQualifier::Temporary;
};

class StationFinder {
 public:
  // Answers kept per name: enough to name the MACs of a duplicate.
  static constexpr std::size_t kMaxAnswers = 8;

  StationFinder(DcpClient& client, std::vector<StationConfig> stations, StationFinderOptions options = {});

  // Engine interface: poll() also submits the next request; frames go through the client.
  std::size_t poll(core::TimePoint now, std::span<std::uint8_t> out);
  bool on_frame(std::span<const std::uint8_t> frame, core::TimePoint now) noexcept {
    return client_.on_frame(frame, now);
  }
  [[nodiscard]] core::TimePoint next_deadline() const noexcept;

  [[nodiscard]] bool done() const noexcept { return next_ >= stations_.size() && request_ == kNoDcpRequest; }
  [[nodiscard]] const std::vector<StationReport>& reports() const noexcept { return reports_; }
  [[nodiscard]] bool all_ok() const noexcept;

 private:
  void step();
  bool start(std::size_t index);
  void identified(std::size_t index, const DcpResult& r);
  void ip_set(std::size_t index, const DcpResult& r);
  bool request_ended() const noexcept;
  void conclude(std::size_t index, StationOutcome outcome, std::string text);

  DcpClient& client_;
  std::vector<StationConfig> stations_;
  StationFinderOptions options_;
  std::vector<StationReport> reports_;
  std::size_t next_ = 0;      // next station to start
  std::size_t current_ = 0;   // the station request_ belongs to
  DcpRequestId request_ = kNoDcpRequest;
  bool setting_ip_ = false;
  std::array<DcpStation, kMaxAnswers> answers_{};
};

}  // namespace drivegate::profinet
