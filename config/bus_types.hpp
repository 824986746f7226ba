#pragma once
// The bus types the configuration knows, with what each accepts: the address range of its axes
// and its type-specific option keys. A type is usable only when an adapter for it is available;
// the others are known so that their configs get a clear "not in this build" instead of a typo
// hint. Adapters announce themselves by adding (or replacing) an entry.
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "config/plan.hpp"

namespace drivegate::config {

// Choice: a string out of `choices` (stored as that string).
enum class OptionKind : std::uint8_t { Integer, Number, Boolean, String, Duration, Choice };

struct OptionSpec {
  std::string name;
  OptionKind kind = OptionKind::Integer;
  double min = 0;  // Integer and Number; Duration: seconds (both 0: any duration > 0 up to 1 h)
  double max = 0;
  OptionValue default_value;
  std::string help;
  std::vector<std::string> choices;  // Choice only
};

struct BusTypeInfo {
  std::string name;
  bool available = false;  // an adapter for it is linked in
  std::int64_t min_address = 1;
  std::int64_t max_address = 127;
  std::vector<OptionSpec> options;
  std::string axis_section;  // per-axis section only axes on this bus type may have ("sim")
  std::string address_words = "an integer";  // what an address is, for messages ("a CANopen node-ID")
  core::Duration min_cycle_time = std::chrono::microseconds(100);
  core::Duration max_cycle_time = std::chrono::seconds(1);
};

class BusTypeRegistry {
 public:
  // sim and canopen (available), ethercat, profinet (known, not yet available).
  static BusTypeRegistry builtin();
  void add(BusTypeInfo info);  // replaces an entry with the same name
  [[nodiscard]] const BusTypeInfo* find(std::string_view name) const noexcept;
  [[nodiscard]] std::vector<std::string> names() const;
  [[nodiscard]] std::vector<std::string> available_names() const;
  // Per-axis sections of all types ("sim"), so an axis key can be told apart from a typo.
  [[nodiscard]] std::vector<std::string> axis_sections() const;

 private:
  std::vector<BusTypeInfo> types_;
};

}  // namespace drivegate::config
