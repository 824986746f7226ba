// The EDS parser (config/eds.hpp) on arbitrary file text: vendor files are INI text of uneven
// quality. Invariants: a parse either returns objects and no errors, or nullopt and at least one
// error; every object returned can be found again by its index and sub-index. Problems are the
// parser's legitimate answer; only crashes, sanitizer reports and broken invariants count.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "config/eds.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace drivegate::config;
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  Problems problems;
  const auto objects = parse_eds_text(text, "fuzz.eds", problems);
  if (objects.has_value() == problems.has_errors()) std::abort();
  if (!objects) return 0;
  for (const auto& o : *objects) {
    if (find_eds_object(*objects, o.id) == nullptr) std::abort();
    (void)find_eds_object(*objects, o.name);
    (void)eds_type_name(o.data_type);
    (void)eds_type_bits(o.data_type);
  }
  return 0;
}
