#pragma once
// The checks every bus type's PDO section shares (config/canopen, config/ethercat): entry sizes
// against CiA 402, each object mapped once and one way, controlword out and statusword in.
#include <string>
#include <string_view>
#include <vector>

#include "config/yaml_reader.hpp"
#include "profiles/cia402/objects.hpp"

namespace drivegate::config {

// An object mapped by a PDO entry, and where.
struct MappedEntry {
  cia402::ObjectId id;
  std::string path;
  YAML::Mark mark;
};

// The entry's size against the CiA 402 type of its object (when CiA 402 defines one); `hint` is
// added to the message.
void check_known_type(const YAML::Node& n, const std::string& path, const Source& src, cia402::ObjectId id,
                      cia402::DataType type, std::string_view hint = {});
// Records the entry at `path` in `mapped`; false (an error naming the first place) when the object
// is mapped already.
bool record_mapping(const YAML::Node& n, const std::string& path, const Source& src, cia402::ObjectId id,
                    std::vector<MappedEntry>& mapped);
[[nodiscard]] bool is_mapped(const std::vector<MappedEntry>& mapped, cia402::ObjectId id);
// Data goes one way: an object among the outputs `rx` and the inputs `tx` is refused at its input entry.
void check_one_way(const Source& src, const std::vector<MappedEntry>& rx, const std::vector<MappedEntry>& tx);
// The gateway drives an axis through 6040h and follows it through 6041h: when anything is mapped,
// 6040h must be among the outputs (reported at `rx_key`) and 6041h among the inputs (`tx_key`).
void check_control_and_status(const MapReader& section, const std::vector<MappedEntry>& rx, const char* rx_key,
                              const std::vector<MappedEntry>& tx, const char* tx_key);

}  // namespace drivegate::config
