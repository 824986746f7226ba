// The EDS parser (config/canopen/eds.hpp) on arbitrary file text: vendor files are INI text of uneven
// quality. Invariants: a parse either returns objects and no errors, or nullopt and at least one
// error; objects are sorted with each index and sub-index once, and each can be found again by its
// index and sub-index; a limit's text parses again to the value stored for it. Problems are the
// parser's legitimate answer; only crashes, sanitizer reports and broken invariants count.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "config/canopen/eds.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace drivegate::config;
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  Problems problems;
  const auto eds = load_eds_text(text, "fuzz.eds", problems);
  if (eds.has_value() == problems.has_errors()) std::abort();
  if (!eds) return 0;
  const auto& objects = eds->objects;
  if (objects.empty()) std::abort();
  for (std::size_t i = 0; i < objects.size(); ++i) {
    const EdsObject& o = objects[i];
    if (i > 0 && objects[i - 1].id.key() >= o.id.key()) std::abort();
    if (find_eds_object(objects, o.id) != &o) std::abort();
    (void)find_eds_object(objects, o.name);
    (void)eds_type_name(o.data_type);
    (void)eds_type_bits(o.data_type);
    (void)eds_type_kind(o.data_type);
    for (const auto* limit : {&o.low_limit, &o.high_limit}) {
      if (!*limit) continue;
      const auto again = parse_eds_number((*limit)->text, o.data_type);
      if (!again || !(*again == (*limit)->value)) std::abort();
      (void)(*limit)->value.for_node(127).as_double();
    }
    if (o.low_limit && o.high_limit) (void)compare(o.low_limit->value, o.high_limit->value);
  }
  for (const auto& s : eds->skipped) (void)find_eds_skipped(eds->skipped, s.id);
  return 0;
}
