// The ESI reader (config/ethercat/esi.hpp) on arbitrary file text: vendors' files are XML written
// by many tools. Invariants: a parse either returns devices and no errors, or nullopt and at least
// one error; every device's objects are sorted with each index and sub-index once, each found again
// by its index and sub-index and (when its name is unique) by its name; PDO entries and object
// sizes are within what the reader promises. Problems are the reader's legitimate answer; only
// crashes, sanitizer reports and broken invariants count.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <string_view>

#include "config/ethercat/esi.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace drivegate::config;
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  Problems problems;
  const auto esi = load_esi_text(text, "fuzz.xml", problems);
  if (esi.has_value() == problems.has_errors()) std::abort();
  if (!esi) return 0;
  if (esi->devices.empty()) std::abort();
  for (const auto& d : esi->devices) {
    (void)esi_device_text(d);
    if (find_esi_devices(*esi, d.product_code, d.revision).empty()) std::abort();
    for (const auto* pdos : {&d.rxpdos, &d.txpdos})
      for (const auto& p : *pdos) {
        if (p.sm && (*p.sm < 0 || *p.sm > 15)) std::abort();
        for (const auto& e : p.entries)
          if (e.bits < 1 || e.bits > 255) std::abort();
      }
    for (const auto& m : d.op_modes)
      if (m.assign_activate > 0xFFFF) std::abort();
    const auto& objects = d.objects;
    for (std::size_t i = 0; i < objects.size(); ++i) {
      const EsiObject& o = objects[i];
      if (i > 0 && objects[i - 1].id.key() >= o.id.key()) std::abort();
      if (find_esi_object(objects, o.id) != &o) std::abort();
      if (o.bits < 1 || o.bits > 0xFFFF) std::abort();
      const std::string name = o.parent.empty() ? o.name : o.parent + ":" + o.name;
      const auto named = find_esi_objects(objects, name);
      if (named.size() == 1 && named[0]->id.key() != o.id.key() && o.parent.empty()) std::abort();
      (void)to_string(o.access);
    }
  }
  return 0;
}
