#include "config/pdo_checks.hpp"

#include <algorithm>

#include "config/object_text.hpp"
#include "profiles/cia402/standard_types.hpp"

namespace drivegate::config {

void check_known_type(const YAML::Node& n, const std::string& path, const Source& src, cia402::ObjectId id,
                      cia402::DataType type, std::string_view hint) {
  const auto known = cia402::profile_object_type(id);  // a profile that gives 6060h another size is caught
  if (known && size_of(*known) != size_of(type))
    src.error(n.Mark(), path,
              object_hex(id) + " is " + std::string{to_string(*known)} + " in CiA 402, got " +
                  std::string{to_string(type)} + std::string{hint});
}

bool is_mapped(const std::vector<MappedEntry>& mapped, cia402::ObjectId id) {
  return std::any_of(mapped.begin(), mapped.end(), [id](const MappedEntry& m) { return m.id == id; });
}

bool record_mapping(const YAML::Node& n, const std::string& path, const Source& src, cia402::ObjectId id,
                    std::vector<MappedEntry>& mapped) {
  const auto dup = std::find_if(mapped.begin(), mapped.end(), [&](const MappedEntry& m) { return m.id == id; });
  if (dup != mapped.end()) {
    src.error(n.Mark(), path, object_hex(id) + " is already mapped in " + dup->path);
    return false;
  }
  mapped.push_back({id, path, n.Mark()});
  return true;
}

void check_one_way(const Source& src, const std::vector<MappedEntry>& rx, const std::vector<MappedEntry>& tx) {
  for (const auto& t : tx) {
    const auto r = std::find_if(rx.begin(), rx.end(), [&](const MappedEntry& m) { return m.id == t.id; });
    if (r != rx.end())
      src.error(t.mark, t.path, object_hex(t.id) + " is also mapped in " + r->path + "; an object is either sent or received");
  }
}

void check_control_and_status(const MapReader& section, const std::vector<MappedEntry>& rx, const char* rx_key,
                              const std::vector<MappedEntry>& tx, const char* tx_key) {
  if (rx.empty() && tx.empty()) return;
  if (!is_mapped(rx, cia402::obj::kControlword.id))
    section.error(rx_key, "must map 0x6040 (controlword): the gateway drives every axis through it");
  if (!is_mapped(tx, cia402::obj::kStatusword.id))
    section.error(tx_key, "must map 0x6041 (statusword): the gateway follows every axis through it");
}

}  // namespace drivegate::config
