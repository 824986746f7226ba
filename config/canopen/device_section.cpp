#include "config/canopen/device_section.hpp"

#include <algorithm>
#include <cstdio>
#include <map>
#include <sstream>

#include "config/object_text.hpp"
#include "config/pdo_checks.hpp"
#include "config/canopen/parameter_names.hpp"
#include "config/text_util.hpp"
#include "profiles/cia402/standard_types.hpp"

namespace drivegate::config {

namespace {

using namespace std::chrono_literals;

// Objects a start-up write must not touch, and why: the gateway owns them.
std::optional<std::string> forbidden_write(cia402::ObjectId id) {
  const auto i = id.index;
  if (i == 0x1010 || i == 0x1011)
    return std::string{"stores or restores every drive parameter; never a start-up write "
                       "(akd-canopen-part1-communication.md §16 step 15)"};
  if (i >= 0x1400 && i <= 0x1BFF) return std::string{"is a PDO parameter; PDOs come from the profile's rpdos/tpdos"};
  if (i == 0x100C || i == 0x100D || i == 0x1016 || i == 0x1017)
    return std::string{"is error control; it comes from the bus options (heartbeat_period, drive_heartbeat, "
                       "guard_time, life_time_factor)"};
  if (id == cia402::obj::kControlword.id)
    return std::string{"is the controlword; only the gateway's state machine drives it, so nothing enables "
                       "without a client command"};
  return std::nullopt;
}

// "0x6040" / "0x6046:1", or a manufacturer parameter name when the device has a naming scheme.
std::optional<cia402::ObjectId> read_object(const YAML::Node& n, const std::string& path, const Source& src,
                                            const std::optional<ParameterNaming>& naming) {
  const auto text = read_string(n, path, src);
  if (!text) return std::nullopt;
  if (const auto id = parse_object_id(*text)) return id;
  if (naming && !text->starts_with("0x") && !text->starts_with("0X")) {
    const auto r = resolve_parameter_name(*text, *naming);
    if (r.id) return r.id;
    src.error(n.Mark(), path, r.error + ", got " + describe_value(n));
    return std::nullopt;
  }
  src.error(n.Mark(), path,
            std::string{"must be an object as \"0x6040\" or \"0x6046:1\" (hex index, optional sub-index)"} +
                (naming ? " or a parameter name such as A83" : "") + ", got " + describe_value(n));
  return std::nullopt;
}

// One map entry "INDEX[:SUB] TYPE", its type checked against CiA 402.
std::optional<PdoEntrySpec> read_entry(const YAML::Node& n, const std::string& path, const Source& src) {
  const auto entry = read_pdo_entry(n, path, src);
  if (entry) check_known_type(n, path, src, entry->object, entry->type);
  return entry;
}

}  // namespace

std::optional<PdoEntrySpec> read_pdo_entry(const YAML::Node& n, const std::string& path, const Source& src) {
  static const std::string kForm =
      "must be \"INDEX[:SUB] TYPE\" such as \"0x6040 u16\" or \"0x60C1:1 i32\" (TYPE one of i8 u8 i16 u16 i32 u32)";
  if (!n.IsScalar()) {
    src.error(n.Mark(), path, kForm + ", got " + describe_value(n));
    return std::nullopt;
  }
  std::istringstream words(n.Scalar());
  std::string object_word;
  std::string type_word;
  std::string extra;
  words >> object_word >> type_word >> extra;
  const auto id = parse_object_id(object_word);
  const auto type = parse_data_type(type_word);
  if (!id || type_word.empty() || !extra.empty()) {
    src.error(n.Mark(), path, kForm + ", got " + describe_value(n));
    return std::nullopt;
  }
  if (!type) {
    src.error(n.Mark(), path, "type \"" + type_word + "\" must be one of i8, u8, i16, u16, i32, u32" +
                                  did_you_mean(type_word, data_type_names()));
    return std::nullopt;
  }
  return PdoEntrySpec{*id, static_cast<std::uint8_t>(size_of(*type) * 8), *type};
}

namespace {

void read_pdos(const MapReader& c, const std::string& key, bool receive, const DeviceProfile& p,
               std::vector<PdoSpec>& out, std::vector<MappedEntry>& mapped) {
  const auto list = c.list(key, Need::Optional);
  if (!list) return;
  const Source& src = c.source();
  const std::string what = receive ? "RPDO" : "TPDO";
  std::map<std::int64_t, std::string> numbers;
  const int fixed = p.section<CanopenDeviceSpec>().fixed_mapping_count;
  const int max_entries = fixed > 0 ? fixed : 8;
  for (std::size_t i = 0; i < list->size(); ++i) {
    const MapReader m{(*list)[i], indexed(c.field(key), i), src};
    if (!m.present()) continue;
    if (receive)
      m.check_keys({"number", "transmission_type", "dlc", "map"});
    else
      m.check_keys({"number", "transmission_type", "inhibit_time_100us", "event_timer_ms", "map"});
    PdoSpec pdo;
    if (const auto n = m.integer("number", Need::Required, 1, 4)) {
      pdo.number = static_cast<int>(*n);
      const auto [it, added] = numbers.emplace(*n, m.field("number"));
      if (!added) m.error("number", what + " " + std::to_string(*n) + " is already defined by " + it->second);
    }
    if (const auto t = m.integer("transmission_type", Need::Optional, 0, 255)) {
      if (*t > 240 && *t < 254)
        m.error("transmission_type", "must be 0..240 (synchronous), 254 or 255 (event-driven), got " + std::to_string(*t));
      else if (*t == 255 && p.quirk("no_transmission_type_255"))
        m.error("transmission_type", "255 is reserved on this device (quirk no_transmission_type_255); use 254 "
                                     "(event-driven) or 1..240 (synchronous)");
      else
        pdo.transmission_type = static_cast<int>(*t);
    }
    if (!receive) {
      // 1800h sub 3 (100 us) and sub 5 (ms) are UNSIGNED16 [CiA 301; AKD part 1 §12.2].
      pdo.inhibit_time_100us = static_cast<int>(m.integer("inhibit_time_100us", Need::Optional, 0, 65535).value_or(0));
      pdo.event_timer_ms = static_cast<int>(m.integer("event_timer_ms", Need::Optional, 0, 65535).value_or(0));
    }
    if (const auto entries = m.list("map", Need::Required)) {
      if (entries->size() == 0) m.error("map", "must map at least one object (leave the PDO out to disable it)");
      for (std::size_t e = 0; e < entries->size(); ++e) {
        const std::string path = indexed(m.field("map"), e);
        const auto entry = read_entry((*entries)[e], path, src);
        if (!entry) continue;
        if (record_mapping((*entries)[e], path, src, entry->object, mapped)) pdo.entries.push_back(*entry);
      }
      if (entries->size() > static_cast<std::size_t>(max_entries))
        m.error("map", std::to_string(entries->size()) + " entries mapped, a PDO " +
                           (max_entries < 8 ? "of this device (fixed_mapping_count) " : "") + "holds at most " +
                           std::to_string(max_entries));
    }
    const int bytes = pdo.mapped_bytes();
    if (bytes > 8)
      src.error(m.mark(), m.path(), std::to_string(bytes) + " bytes mapped, a PDO holds at most 8");
    if (receive) {
      if (const auto dlc = m.integer("dlc", Need::Optional, 0, 8)) {
        if (*dlc != 0 && *dlc < bytes)
          m.error("dlc", "must be 0 (the mapped length) or " + std::to_string(bytes) + "..8 (at least the mapped bytes), got " +
                             std::to_string(*dlc));
        else
          pdo.dlc = static_cast<int>(*dlc);
      }
    }
    out.push_back(std::move(pdo));
  }
}

// 6040h/6041h, and 6060h in the RPDOs where the device needs it in every cycle.
void check_directions(const MapReader& c, const DeviceProfile& p, const std::vector<MappedEntry>& rx,
                      const std::vector<MappedEntry>& tx) {
  check_control_and_status(c, rx, "rpdos", tx, "tpdos");
  if (p.quirk("mode_object_always_valid") && !rx.empty() && !is_mapped(rx, cia402::obj::kModesOfOperation.id))
    c.error("rpdos", "must map 0x6060 (modes of operation): quirk mode_object_always_valid needs 6060h in every RPDO "
                     "cycle (nord-sk500p-ds402.md §13 step 6)");
}

void read_emcy(const MapReader& e, CanopenDeviceSpec& co) {
  e.check_keys({"fields", "zero_needs_clear_register"});
  co.emcy_zero_needs_clear_register = e.boolean("zero_needs_clear_register", Need::Optional).value_or(true);
  const auto fields = e.list("fields", Need::Optional);
  if (!fields) return;
  std::map<std::int64_t, std::string> bytes;
  for (std::size_t i = 0; i < fields->size(); ++i) {
    const MapReader f{(*fields)[i], indexed(e.field("fields"), i), e.source()};
    if (!f.present()) continue;
    f.check_keys({"byte", "name"});
    // Bytes 0..2 are the error code and register [CiA 301 §7.2.7]; 3..7 belong to the vendor.
    const auto byte = f.integer("byte", Need::Required, 3, 7);
    const auto name = f.name("name", Need::Required, false);
    if (!byte || !name) continue;
    const auto [it, added] = bytes.emplace(*byte, f.field("byte"));
    if (!added) {
      f.error("byte", "byte " + std::to_string(*byte) + " is already named by " + it->second);
      continue;
    }
    co.emcy_fields.push_back({static_cast<int>(*byte), *name});
  }
}

void read_naming(const MapReader& n, CanopenDeviceSpec& co) {
  n.check_keys({"base", "group_stride", "max_line"});
  ParameterNaming naming;
  const auto base = n.integer("base", Need::Required, 0x1000, 0xFFFF);
  const auto stride = n.integer("group_stride", Need::Required, 1, 0xFFFF);
  const auto max_line = n.integer("max_line", Need::Required, 0, 0xFFFF);
  if (!base || !stride || !max_line) return;
  if (*max_line >= *stride) {
    n.error("max_line", "must be below group_stride (" + std::to_string(*stride) + ") or groups would overlap, got " +
                            std::to_string(*max_line));
    return;
  }
  // Letters run to Z (group 25); its last line must still be a 16-bit index.
  if (*base + 25 * *stride + *max_line > 0xFFFF) {
    n.error("group_stride", "group Z would reach index " + std::to_string(*base + 25 * *stride + *max_line) +
                                ", beyond FFFFh");
    return;
  }
  naming.base = static_cast<std::uint16_t>(*base);
  naming.group_stride = static_cast<std::uint16_t>(*stride);
  naming.max_line = static_cast<int>(*max_line);
  co.parameter_naming = naming;
}

void read_sync_periods(const MapReader& c, CanopenDeviceSpec& co) {
  const auto list = c.list("sync_periods", Need::Optional);
  if (!list) return;
  for (std::size_t i = 0; i < list->size(); ++i)
    if (const auto d = read_duration((*list)[i], indexed(c.field("sync_periods"), i), c.source(), 100us, 1s))
      co.sync_periods.push_back(*d);
}

}  // namespace

void read_startup_writes(const MapReader& parent, std::string_view key, const std::optional<ParameterNaming>& naming,
                         std::vector<StartupWrite>& out) {
  const auto list = parent.list(key, Need::Optional);
  if (!list) return;
  const Source& src = parent.source();
  std::vector<MappedEntry> written;
  for (std::size_t i = 0; i < list->size(); ++i) {
    const MapReader w{(*list)[i], indexed(parent.field(key), i), src};
    if (!w.present()) continue;
    w.check_keys({"object", "type", "value", "why"});
    const YAML::Node object_node = w.find("object");
    std::optional<cia402::ObjectId> id;
    if (!object_node.IsDefined())
      w.error("object", "missing required field");
    else
      id = read_object(object_node, w.field("object"), src, naming);
    const auto type_name = w.choice("type", Need::Required, data_type_names());
    // A plain value and a flag rather than optional<DataType>: GCC 12 -O2 reports a false
    // "maybe uninitialized" for the optional.
    const auto parsed = type_name ? parse_data_type(*type_name) : std::nullopt;
    const bool has_type = parsed.has_value();
    const cia402::DataType type = parsed.value_or(cia402::DataType::U8);
    std::optional<std::int64_t> value;
    if (has_type) value = w.integer("value", Need::Required, type_min(type), type_max(type));
    else if (!w.has("value")) w.error("value", "missing required field");
    const auto why = w.string("why", Need::Required);
    if (why && why->empty()) w.error("why", "must say why the drive needs this write (it is shown when the write fails)");
    if (!id) continue;
    if (const auto reason = forbidden_write(*id)) {
      w.error("object", object_hex(*id) + " " + *reason);
      continue;
    }
    if (has_type) check_known_type(object_node, w.field("object"), src, *id, type);
    const auto dup = std::find_if(written.begin(), written.end(), [&](const MappedEntry& x) { return x.id == *id; });
    if (dup != written.end()) {
      w.error("object", object_hex(*id) + " is already written by " + dup->path);
      continue;
    }
    written.push_back({*id, w.path(), object_node.Mark()});
    if (has_type && value && why) out.push_back({{*id, type}, *value, *why});
  }
}

std::optional<GatewayWatch> read_gateway_watch(const MapReader& parent) {
  static const std::vector<std::string> kChoices{"heartbeat", "guarding", "required", "optional"};
  const auto v = parent.choice("gateway_watch", Need::Optional, kChoices);
  if (!v) return std::nullopt;
  if (*v == "heartbeat") return GatewayWatch::Heartbeat;
  if (*v == "guarding") return GatewayWatch::Guarding;
  if (*v == "required") return GatewayWatch::Required;
  return GatewayWatch::Optional;
}

void read_canopen_device(const MapReader& root, DeviceProfile& p) {
  if (!root.has("canopen")) return;
  const MapReader c = root.map("canopen", Need::Optional);
  if (!c.present()) return;
  auto& co = p.sections.edit<CanopenDeviceSpec>();
  c.check_keys({"device_type", "device_type_mask", "persona", "sdo_channels", "error_control", "consumer_heartbeat",
                "gateway_watch",
                "pdo_policy", "disable_unused_pdos", "fixed_mapping_count", "sync_periods", "rpdos", "tpdos",
                "startup_writes", "emcy", "parameter_names"});
  if (const auto v = c.integer("device_type", Need::Optional, 0, 0xFFFFFFFF)) co.device_type = static_cast<std::uint32_t>(*v);
  if (const auto v = c.integer("device_type_mask", Need::Optional, 1, 0xFFFFFFFF))
    co.device_type_mask = static_cast<std::uint32_t>(*v);
  if (c.has("device_type_mask") && !c.has("device_type"))
    c.error("device_type_mask", "only with device_type (the value 1000h is compared with)");
  static const std::vector<std::string> kPersonas{"akd", "nord-sk500p", "stoeber-sd6", "generic",
                                                    "generic-no-heartbeat", "generic-no-watch",
                                                    "generic-fixed-heartbeat"};
  co.persona = c.choice("persona", Need::Optional, kPersonas).value_or(co.persona);
  // SDO channel k answers on 580h + 20h*(k-1) + node [stoeber-sd6-canopen.md §5.3]: at most 4.
  co.sdo_channels = static_cast<int>(c.integer("sdo_channels", Need::Optional, 1, 4).value_or(1));

  static const std::vector<std::string> kErrorControl{"heartbeat", "guarding"};
  if (const auto ec = c.choice("error_control", Need::Optional, kErrorControl))
    co.error_control = *ec == "guarding" ? ErrorControl::Guarding : ErrorControl::Heartbeat;
  const auto consumer = c.boolean("consumer_heartbeat", Need::Optional);
  if (co.error_control == ErrorControl::Guarding) {
    co.consumer_heartbeat = false;
    if (consumer && *consumer)
      c.error("consumer_heartbeat", "only with error_control: heartbeat (a guarded drive watches the guarding RTRs)");
  } else {
    co.consumer_heartbeat = consumer.value_or(true);
    // DESIGN.md §4: the gateway configures each drive's own watchdog so a dead gateway stops it.
    if (!co.consumer_heartbeat)
      c.error("consumer_heartbeat", "false with error_control: heartbeat leaves the drive unable to notice a dead "
                                    "gateway; use error_control: guarding (as stoeber-sd6 does)");
  }

  co.gateway_watch = co.error_control == ErrorControl::Guarding ? GatewayWatch::Guarding : GatewayWatch::Heartbeat;
  if (const auto w = read_gateway_watch(c)) {
    if (co.error_control == ErrorControl::Guarding && *w != GatewayWatch::Guarding)
      c.error("gateway_watch", "only guarding with error_control: guarding");
    else
      co.gateway_watch = *w;
  }

  static const std::vector<std::string> kPolicies{"write", "verify"};
  if (const auto pol = c.choice("pdo_policy", Need::Optional, kPolicies))
    co.pdo_policy = *pol == "verify" ? PdoPolicy::Verify : PdoPolicy::Write;
  co.disable_unused_pdos = c.boolean("disable_unused_pdos", Need::Optional).value_or(true);
  if (const auto n = c.integer("fixed_mapping_count", Need::Optional, 1, 8)) {
    if (co.pdo_policy != PdoPolicy::Verify)
      c.error("fixed_mapping_count", "only with pdo_policy: verify (a constant mapping count cannot be written)");
    else
      co.fixed_mapping_count = static_cast<int>(*n);
  }
  read_sync_periods(c, co);

  std::vector<MappedEntry> rx;
  std::vector<MappedEntry> tx;
  read_pdos(c, "rpdos", true, p, co.rpdos, rx);
  read_pdos(c, "tpdos", false, p, co.tpdos, tx);
  check_one_way(c.source(), rx, tx);
  check_directions(c, p, rx, tx);

  if (c.has("parameter_names")) read_naming(c.map("parameter_names", Need::Optional), co);
  read_startup_writes(c, "startup_writes", co.parameter_naming, co.startup_writes);
  read_emcy(c.map("emcy", Need::Optional), co);
}

std::vector<cia402::ObjectId> canopen_mapped_objects(const DeviceProfile& p) {
  std::vector<cia402::ObjectId> mapped;
  const auto& co = p.section<CanopenDeviceSpec>();
  for (const auto* pdos : {&co.rpdos, &co.tpdos})
    for (const auto& pdo : *pdos)
      for (const auto& e : pdo.entries) mapped.push_back(e.object);
  return mapped;
}

}  // namespace drivegate::config
