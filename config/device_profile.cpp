#include "config/device_profile.hpp"

#include <algorithm>
#include <set>

#include "config/object_text.hpp"
#include "config/scalars.hpp"
#include "config/text_util.hpp"
#include "config/yaml_reader.hpp"

namespace drivegate::config {

namespace fs = std::filesystem;

const std::vector<std::string>& known_quirks() {
  // Behaviours where a reference device departs from plain CiA 402; the digest sections give the
  // facts (akd-canopen-part2-ds402.md §15, nord-sk500p-ds402.md §14, stoeber-sd6-canopen.md quirks).
  static const std::vector<std::string> kQuirks{
      "switched_on_energises_power_stage",  // AKD §15.1: torque already in Switched on
      "fault_reset_needs_bit7_release",     // AKD §15.6: host must clear CW bit 7 after the reset
      "quick_stop_clears_setpoints",        // AKD §15.5: set-points must be re-sent after quick stop
      "mode_valid_when_displayed",          // AKD §15.10: wait for 6061h before using a new mode
      "setpoint_rewrite_after_mode_change", // AKD §15.10
      "supported_modes_object_incomplete",  // AKD §15.9: 6502h omits tq, do not trust it
      "homing_objects_not_pdo_mappable",    // AKD §15.15: 6098h/6099h/609Ah/607Ch by SDO only
      "setpoints_only_in_operation_enabled",  // AKD §15.23
      "no_sync_producer",                   // AKD §15.20: the drive cannot produce SYNC
      "mode_object_always_valid",           // NORD §13 step 6, quirk 18: 6060h in RxPDO1 must always
                                            // hold a valid mode (0 is reserved), even before enabling
      "no_transmission_type_255",           // SD6 quirk 3: PDO transmission type 255 is reserved
      "mode_objects_16bit",                 // ESR/Dunker quirk 1: 6060h/6061h are INTEGER16
      "pp_bit6_absolute",                   // ESR/Dunker quirk 14 [EXT]: pp controlword bit 6 = 1 is absolute
  };
  return kQuirks;
}

std::vector<fs::path> default_device_dirs() {
  return {fs::path{DRIVEGATE_DEVICE_DIR_SOURCE}, fs::path{DRIVEGATE_DEVICE_DIR_INSTALLED}};
}

namespace {

// The cyclic image must carry what the profile drives every cycle: the controlword and statusword
// always, and the target object of each cyclic mode the profile offers (without it the mode could
// not follow set-points and would jump to a stale target when enabled). When the image was derived
// from a bus type's section (the canopen PDO maps), that section is what is missing the object.
void check_cyclic_image(const DeviceProfile& p, const MapReader& root, const std::string& derived_from) {
  struct Need {
    std::optional<core::Mode> mode;  // nullopt: needed whatever the modes
    cia402::ObjectId object;
    const char* what;
  };
  const Need needs[] = {
      {std::nullopt, {0x6040, 0}, "0x6040 (controlword)"},
      {std::nullopt, {0x6041, 0}, "0x6041 (statusword)"},
      {core::Mode::InterpolatedPosition, {0x60C1, 1}, "0x60C1:1 (interpolation data record) for mode ip"},
      {core::Mode::CyclicPosition, {0x607A, 0}, "0x607A (target position) for mode csp"},
      {core::Mode::CyclicVelocity, {0x60FF, 0}, "0x60FF (target velocity) for mode csv"},
      {core::Mode::CyclicTorque, {0x6071, 0}, "0x6071 (target torque) for mode cst"},
  };
  for (const auto& n : needs) {
    if (n.mode && !p.modes.contains(*n.mode)) continue;
    bool found = false;
    for (const auto& id : p.cyclic_objects) found = found || id == n.object;
    if (!found && !derived_from.empty())
      root.error(derived_from, std::string("the PDO maps (the cyclic image) must include ") + n.what);
    else if (!found)
      root.error("cyclic_objects", std::string("must include ") + n.what);
  }
}

// And the bus types' sections (BusTypeInfo::device_section).
const std::vector<std::string> kProfileKeys{"name",        "vendor",         "description", "identity",
                                            "modes",       "units",          "homing_methods", "fault_texts",
                                            "quirks",      "cyclic_objects"};

void read_units(const MapReader& units, NativeUnitsSpec& out) {
  units.check_keys({"position", "velocity", "acceleration", "torque"});
  const Source& src = units.source();

  const MapReader pos = units.map("position", Need::Required);
  pos.check_keys({"per_rev"});
  if (const YAML::Node n = pos.find("per_rev"); n.IsScalar() && n.Scalar() == "counts") {
    out.position_base = UnitBase::EncoderCounts;
  } else if (pos.present()) {
    NumberRule rule = NumberRule::positive_up_to(1e12);
    rule.words = "\"counts\" (the axis' encoder_counts_per_rev) or a number > 0 and at most 1e12";
    if (const auto v = pos.number("per_rev", Need::Required, rule)) {
      out.position_base = UnitBase::Fixed;
      out.position_per_rev = *v;
    }
  }

  // velocity: { unit: position_per_s } or { per_rps: N }; acceleration likewise.
  const auto read_rate = [&src](const MapReader& m, const char* fixed_key,
                                const std::vector<std::string>& bases, UnitBase& base, double& value) {
    std::vector<std::string> keys{"unit", fixed_key};
    m.check_keys(keys);
    if (!m.present()) return;
    if (m.has("unit") == m.has(fixed_key)) {
      src.error(m.mark(), m.path(),
                "give exactly one of unit (" + join(bases) + ") or " + fixed_key + " (a number > 0)");
      return;
    }
    if (m.has("unit")) {
      if (const auto u = m.choice("unit", Need::Required, bases))
        base = (*u == "velocity_per_s") ? UnitBase::Velocity : UnitBase::Position;
    } else if (const auto v = m.number(fixed_key, Need::Required, NumberRule::positive_up_to(1e12))) {
      base = UnitBase::Fixed;
      value = *v;
    }
  };
  read_rate(units.map("velocity", Need::Required), "per_rps", {"position_per_s"}, out.velocity_base,
            out.velocity_per_rps);
  read_rate(units.map("acceleration", Need::Required), "per_rps2", {"position_per_s2", "velocity_per_s"},
            out.acceleration_base, out.acceleration_per_rps2);

  const MapReader torque = units.map("torque", Need::Optional);
  torque.check_keys({"per_rated"});
  if (const auto v = torque.number("per_rated", Need::Optional, NumberRule::positive_up_to(1e9)))
    out.torque_per_rated = *v;
}

void read_profile(const MapReader& root, const fs::path& file, const BusTypeRegistry& types, DeviceProfile& p) {
  const Source& src = root.source();
  std::vector<std::string> keys = kProfileKeys;
  const auto sections = types.device_sections();
  keys.insert(keys.end(), sections.begin(), sections.end());
  root.check_keys(keys);
  if (const auto name = root.name("name", Need::Required)) {
    p.name = *name;
    if (*name != file.stem().string())
      root.error("name", "must match the file name \"" + file.stem().string() + "\", got \"" + *name + "\"");
  }
  p.vendor = root.string("vendor", Need::Required).value_or("");
  p.description = root.string("description", Need::Optional).value_or("");

  const MapReader identity = root.map("identity", Need::Optional);
  identity.check_keys({"vendor_id", "product_code"});
  if (const auto v = identity.integer("vendor_id", Need::Optional, 0, 0xFFFFFFFF))
    p.identity.vendor_id = static_cast<std::uint32_t>(*v);
  if (const auto v = identity.integer("product_code", Need::Optional, 0, 0xFFFFFFFF))
    p.identity.product_code = static_cast<std::uint32_t>(*v);

  if (const auto modes = root.list("modes", Need::Required)) {
    for (std::size_t i = 0; i < modes->size(); ++i) {
      const YAML::Node n = (*modes)[i];
      const auto mode = n.IsScalar() ? core::parse_mode(n.Scalar()) : std::nullopt;
      if (!mode || *mode == core::Mode::None)
        src.error(n.Mark(), root.field("modes") + "[" + std::to_string(i) + "]",
                  "must be a mode name (pp, pv, vl, tq, hm, ip, csp, csv, cst, tb or the long form such "
                  "as profile_position), got " + describe_value(n));
      else
        p.modes.add(*mode);
    }
    if (modes->size() == 0) root.error("modes", "must list at least one mode");
  }

  read_units(root.map("units", Need::Required), p.units);

  if (const auto methods = root.list("homing_methods", Need::Optional)) {
    for (std::size_t i = 0; i < methods->size(); ++i) {
      // 6098h homing method is INTEGER8 [CiA 402; AKD digest §9.1].
      if (const auto m = read_integer((*methods)[i], root.field("homing_methods") + "[" + std::to_string(i) + "]",
                                      src, -128, 127))
        p.homing_methods.push_back(static_cast<std::int16_t>(*m));
    }
  }

  const MapReader faults = root.map("fault_texts", Need::Optional);
  if (faults.present()) {
    for (const auto& kv : faults.node()) {
      const std::string key = kv.first.IsScalar() ? kv.first.Scalar() : std::string{"?"};
      const std::string path = faults.path() + "." + key;
      const std::int64_t code = parse_integer(key).value_or(-1);
      // CiA 402 error codes (603Fh, EMCY) are 16 bits wide.
      if (code < 0 || code > 0xFFFF) {
        src.error(kv.first.Mark(), path, "fault codes must be integers 0..0xFFFF, got " + describe_value(kv.first));
        continue;
      }
      if (const auto text = read_string(kv.second, path, src)) p.fault_texts[static_cast<std::uint32_t>(code)] = *text;
    }
  }

  const MapReader quirks = root.map("quirks", Need::Optional);
  quirks.check_keys(known_quirks());
  for (const auto& q : known_quirks())
    if (const auto v = quirks.boolean(q, Need::Optional)) p.quirks[q] = *v;

  if (const auto objects = root.list("cyclic_objects", Need::Optional)) {
    for (std::size_t i = 0; i < objects->size(); ++i) {
      const YAML::Node n = (*objects)[i];
      const auto id = n.IsScalar() ? parse_object_id(n.Scalar()) : std::nullopt;
      if (!id)
        src.error(n.Mark(), root.field("cyclic_objects") + "[" + std::to_string(i) + "]",
                  "must be an object as \"0x6040\" or \"0x6099:1\" (hex index, optional sub-index), got " +
                      describe_value(n));
      else
        p.cyclic_objects.push_back(*id);
    }
  }
  for (const auto& type : types.types())
    if (type->read_device && root.has(type->device_section)) type->read_device(root, p);
  // The cyclic image is what the bus sections map: given in the file, or taken from the first
  // section that maps objects; every section that maps any must map exactly those.
  const bool cyclic_given = root.has("cyclic_objects");
  std::string derived_from;  // the section that filled cyclic_objects
  for (const auto& type : types.types()) {
    if (!type->mapped_objects || !root.has(type->device_section)) continue;
    const auto mapped = type->mapped_objects(p);
    if (mapped.empty()) continue;
    const std::string& section = type->device_section;
    if (!cyclic_given && derived_from.empty()) {
      p.cyclic_objects = mapped;
      derived_from = section;
    } else if (const auto d = cyclic_image_difference(mapped, p.cyclic_objects, cyclic_given ? "listed" : "cyclic");
               !d.empty()) {
      if (cyclic_given)
        root.error("cyclic_objects",
                   "must list exactly the objects of the " + section + " PDO maps (or be left out to derive them):" + d);
      else
        root.error(section, "the " + section + " PDO maps must carry the same objects as the " + derived_from +
                                " PDO maps (the cyclic image):" + d);
    }
  }
  // A profile only for bus types whose drives are not CiA 402 (PROFIdrive) has no CiA 402 image.
  bool cia402 = cyclic_given;
  bool any_section = false;
  for (const auto& type : types.types()) {
    if (type->device_section.empty() || !root.has(type->device_section)) continue;
    any_section = true;
    cia402 = cia402 || type->cia402_device;
  }
  if (cia402 || !any_section) check_cyclic_image(p, root, derived_from);
}

}  // namespace

core::NativeUnits NativeUnitsSpec::resolve(double encoder_counts_per_rev) const noexcept {
  core::NativeUnits n;
  n.position_per_rev = position_base == UnitBase::Fixed ? position_per_rev : encoder_counts_per_rev;
  n.velocity_per_rps = velocity_base == UnitBase::Fixed ? velocity_per_rps : n.position_per_rev;
  switch (acceleration_base) {
    case UnitBase::Fixed: n.acceleration_per_rps2 = acceleration_per_rps2; break;
    case UnitBase::Velocity: n.acceleration_per_rps2 = n.velocity_per_rps; break;
    default: n.acceleration_per_rps2 = n.position_per_rev; break;
  }
  n.torque_per_rated = torque_per_rated;
  return n;
}

std::optional<DeviceProfile> parse_device_profile(const fs::path& file, Problems& problems,
                                                  const BusTypeRegistry& types) {
  const Source src{file.string(), &problems};
  const std::size_t errors_before = problems.errors().size();
  const auto text = read_text_file(file.string(), src);
  if (!text) return std::nullopt;
  const auto doc = parse_document(*text, src);
  if (!doc) return std::nullopt;
  DeviceProfile p;
  p.file = file.string();
  read_profile(MapReader{*doc, "", src}, file, types, p);
  if (problems.errors().size() != errors_before) return std::nullopt;
  return p;
}

DeviceProfile load_device_profile(const fs::path& file, const BusTypeRegistry& types) {
  Problems problems;
  auto p = parse_device_profile(file, problems, types);
  problems.throw_if_errors();
  return std::move(*p);
}

std::optional<fs::path> DeviceCatalog::locate(const std::string& name) const {
  if (!is_valid_name(name)) return std::nullopt;  // never let a name walk out of the directories
  for (const auto& dir : dirs_) {
    std::error_code ec;
    const fs::path candidate = dir / (name + ".yaml");
    if (fs::is_regular_file(candidate, ec)) return candidate;
  }
  return std::nullopt;
}

const DeviceProfile* DeviceCatalog::get(const std::string& name, Problems& problems) {
  auto it = cache_.find(name);
  if (it == cache_.end()) {
    const auto file = locate(name);
    std::optional<DeviceProfile> profile;
    if (file) profile = parse_device_profile(*file, problems, types_);
    it = cache_.emplace(name, std::move(profile)).first;
  }
  return it->second ? &*it->second : nullptr;
}

std::vector<std::string> DeviceCatalog::available() const {
  std::set<std::string> names;
  for (const auto& dir : dirs_) {
    std::error_code ec;
    for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec))
      if (it->path().extension() == ".yaml" && is_valid_name(it->path().stem().string()))
        names.insert(it->path().stem().string());
  }
  return {names.begin(), names.end()};
}

}  // namespace drivegate::config
