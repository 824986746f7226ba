#pragma once
// EMCY consumer (CiA 301 §7.2.7): decodes 080h+n frames into the unified fault model, with the
// device profile's code table and named vendor bytes (AKD: category in byte 3, AKD part 1 §9.1;
// SD6: event E82 in byte 3 and cause E43 in byte 4, stoeber-sd6-canopen.md §6.9).
//
// EMCY 0000h means "no more errors" only when the error register says so (register 0): the AKD
// sends 0000h as an error-state update with the register still set (AKD part 1 quirk 4); the SD6
// sends 0000h with event 30 "inactive" when it leaves the fault state (TV-5).
#include <array>
#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include "adapters/canopen/wire/can_frame.hpp"
#include "adapters/canopen/wire/cob_id.hpp"
#include "adapters/canopen/wire/emcy_codec.hpp"
#include "core/fixed_string.hpp"
#include "profiles/cia402/error_codes.hpp"

namespace drivegate::canopen {

struct EmcyField {
  std::uint8_t byte = 3;  // 3..7
  std::string_view name;  // "event", "cause" (must outlive the consumer)
};

struct EmcyNodeConfig {
  NodeId node = 0;
  std::span<const cia402::FaultText> texts;  // vendor texts (looked up before the standard ones)
  std::span<const EmcyField> fields;
  bool zero_needs_clear_register = true;
};

struct EmcyReport {
  NodeId node = 0;
  Emcy emcy{};
  bool cleared = false;       // "no more errors" (0000h with register 0)
  // "0x7500 communication (event 52, cause 1)": code in hex, its text (vendor table first), then
  // the named vendor bytes in decimal. A 0000h update that leaves errors pending says so instead
  // of "no error": "0x0000 error state update, errors pending (register 0x10)".
  core::FixedString<160> text;
  core::TimePoint time{};
};

struct EmcyCounters {
  std::uint64_t received = 0;
  std::uint64_t unexpected = 0;  // from nodes that are not registered
  std::uint64_t malformed = 0;
  std::uint64_t reports_dropped = 0;
};

class EmcyConsumer {
 public:
  static constexpr std::size_t kReportCapacity = 64;

  // Throws std::invalid_argument for a node-ID outside 1..127, one registered twice, or a field
  // outside bytes 3..7.
  explicit EmcyConsumer(std::span<const EmcyNodeConfig> nodes);

  // Takes 080h+n frames of any node (returns false for other COB-IDs, including SYNC 080h).
  bool on_frame(const CanFrame& frame, core::TimePoint now) noexcept;
  bool next_report(EmcyReport& out) noexcept;
  // The last fault EMCY of a node that was not cleared since, if any. A 0000h update with errors
  // pending keeps it (AKD part 1 §9.2 transition 2); with none known yet, the update becomes it.
  [[nodiscard]] const EmcyReport* active(NodeId node) const noexcept;
  void reset(NodeId node) noexcept;  // node rebooted: forget its active fault

  [[nodiscard]] const EmcyCounters& counters() const noexcept { return counters_; }

 private:
  struct Node {
    EmcyNodeConfig config;
    EmcyReport active;
    bool has_active = false;
  };

  void describe(const Node& n, const Emcy& e, bool cleared, EmcyReport& out) const noexcept;

  EmcyCounters counters_;
  std::vector<Node> nodes_;                           // sized in the constructor
  std::array<std::uint8_t, kMaxNodeId + 1> index_{};  // node-ID -> position in nodes_ + 1 (0: none)
  std::vector<EmcyReport> reports_;                   // ring of kReportCapacity
  std::size_t report_head_ = 0;
  std::size_t report_count_ = 0;
};

}  // namespace drivegate::canopen
