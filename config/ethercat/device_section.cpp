#include "config/ethercat/device_section.hpp"

#include <algorithm>

#include "config/canopen/device_section.hpp"
#include "config/object_text.hpp"
#include "config/pdo_checks.hpp"
#include "config/text_util.hpp"

namespace drivegate::config {

namespace {

std::string hex16(std::uint16_t v) { return object_hex({v, 0}); }

// Where a mapped object sits on a multi-axis slave [ETG.6010 §4: axis n's profile objects
// 6000h..67FFh at + n x axis_offset]: the axis and the object as axis 0 numbers it. Objects
// outside the axes' areas belong to the slave (axis -1).
struct AxisObject {
  int axis = -1;
  cia402::ObjectId local;
};
AxisObject axis_object(const EthercatDeviceSpec& spec, cia402::ObjectId id) {
  constexpr int kProfileArea = 0x6000;
  if (id.index < kProfileArea) return {-1, id};
  const int n = (id.index - kProfileArea) / spec.axis_offset;
  if (n >= spec.axes || (spec.axes == 1 && id.index >= kProfileArea + 0x800)) return {-1, id};
  return {n, cia402::ObjectId{static_cast<std::uint16_t>(id.index - n * spec.axis_offset), id.sub}};
}

bool is_mode_object(cia402::ObjectId id) {
  return id == cia402::obj::kModesOfOperation.id || id == cia402::obj::kModesOfOperationDisplay.id;
}

// The entry's size against CiA 402, except 6060h/6061h on a device with quirk mode_objects_16bit
// (ESR/Dunker: INTEGER16, dunker-ethercat-coe.md quirk 1).
void check_entry_type(const YAML::Node& n, const std::string& path, const Source& src, PdoEntrySpec e,
                      const DeviceProfile& p, const EthercatDeviceSpec& spec) {
  // Axis n's 6860h is a 6060h: its type is checked as that, the message names the entry.
  const AxisObject o = axis_object(spec, e.object);
  const std::string axis_hint =
      o.axis > 0 ? " (" + object_hex(e.object) + " is axis " + std::to_string(o.axis) + "'s " + object_hex(o.local) + ")" : "";
  e.object = o.local;
  if (is_mode_object(e.object) && p.quirk("mode_objects_16bit")) {
    if (e.type != cia402::DataType::I16)
      src.error(n.Mark(), path, object_hex(e.object) + " is INTEGER16 on this device (quirk mode_objects_16bit), got " +
                                    std::string{to_string(e.type)});
    return;
  }
  check_known_type(n, path, src, e.object, e.type,
                   axis_hint + (is_mode_object(e.object) ? " (a device with 16-bit mode objects needs quirk mode_objects_16bit)" : ""));
}

std::vector<std::uint16_t> read_indexes(const MapReader& m, const std::string& key, std::uint16_t lo, std::uint16_t hi) {
  std::vector<std::uint16_t> out;
  const auto list = m.list(key, Need::Optional);
  if (!list) return out;
  for (std::size_t i = 0; i < list->size(); ++i) {
    const auto v = read_integer((*list)[i], indexed(m.field(key), i), m.source(), lo, hi);
    if (!v) continue;
    if (std::find(out.begin(), out.end(), *v) != out.end())
      m.source().error((*list)[i].Mark(), indexed(m.field(key), i), hex16(static_cast<std::uint16_t>(*v)) + " is listed twice");
    else
      out.push_back(static_cast<std::uint16_t>(*v));
  }
  return out;
}

std::vector<cia402::ObjectId> read_objects(const MapReader& m, const std::string& key) {
  std::vector<cia402::ObjectId> out;
  const auto list = m.list(key, Need::Optional);
  if (!list) return out;
  for (std::size_t i = 0; i < list->size(); ++i) {
    const YAML::Node n = (*list)[i];
    const auto id = n.IsScalar() ? parse_object_id(n.Scalar()) : std::nullopt;
    if (!id)
      m.source().error(n.Mark(), indexed(m.field(key), i),
                       "must be an object as \"0x6040\" or \"0x60C1:1\", got " + describe_value(n));
    else
      out.push_back(*id);
  }
  return out;
}

void read_identities(const MapReader& e, EthercatDeviceSpec& spec) {
  const auto list = e.list("identities", Need::Optional);
  if (!list) return;
  if (list->size() == 0) e.error("identities", "must list at least one identity (vendor_id, product_code), or be left out");
  for (std::size_t i = 0; i < list->size(); ++i) {
    const MapReader m{(*list)[i], indexed(e.field("identities"), i), e.source()};
    if (!m.present()) continue;
    m.check_keys({"vendor_id", "product_code", "revision", "name"});
    const auto vendor = m.integer("vendor_id", Need::Required, 0, 0xFFFFFFFF);
    const auto product = m.integer("product_code", Need::Required, 0, 0xFFFFFFFF);
    const auto revision = m.integer("revision", Need::Optional, 0, 0xFFFFFFFF);
    const auto name = m.string("name", Need::Optional);
    if (!vendor || !product) continue;
    EthercatIdentity id;
    id.vendor_id = static_cast<std::uint32_t>(*vendor);
    id.product_code = static_cast<std::uint32_t>(*product);
    if (revision) id.revision = static_cast<std::uint32_t>(*revision);
    id.name = name.value_or("");
    spec.identities.push_back(id);
  }
}

// rxpdos / txpdos: [{ index: 0x1600, map: ["0x6040 u16", ...] }]
void read_pdos(const MapReader& e, bool receive, const DeviceProfile& p, EthercatDeviceSpec& spec,
               std::vector<MappedEntry>& mapped) {
  const std::string key = receive ? "rxpdos" : "txpdos";
  const auto list = e.list(key, Need::Optional);
  if (!list) return;
  const Source& src = e.source();
  // Mapping objects: RxPDO 1600h..17FFh, TxPDO 1A00h..1BFFh [ETG.1000.6 CoE object dictionary].
  const std::uint16_t lo = receive ? 0x1600 : 0x1A00;
  const std::uint16_t hi = receive ? 0x17FF : 0x1BFF;
  const auto& allowed = receive ? spec.rx_pdo_indexes : spec.tx_pdo_indexes;
  const auto& mappable = receive ? spec.rx_mappable : spec.tx_mappable;
  auto& out = receive ? spec.rxpdos : spec.txpdos;
  for (std::size_t i = 0; i < list->size(); ++i) {
    const MapReader m{(*list)[i], indexed(e.field(key), i), src};
    if (!m.present()) continue;
    m.check_keys({"index", "map"});
    EthercatPdoSpec pdo;
    if (const auto index = m.integer("index", Need::Required, lo, hi)) {
      pdo.index = static_cast<std::uint16_t>(*index);
      if (!allowed.empty() && std::find(allowed.begin(), allowed.end(), pdo.index) == allowed.end()) {
        std::vector<std::string> names;
        for (const auto a : allowed) names.push_back(hex16(a));
        m.error("index", hex16(pdo.index) + " is not a mapping object of this device; it has " + join(names, ", "));
      }
      for (const auto& other : out)
        if (other.index == pdo.index) m.error("index", hex16(pdo.index) + " is assigned twice");
    }
    if (const auto entries = m.list("map", Need::Required)) {
      if (entries->size() == 0) m.error("map", "must map at least one object (leave the PDO out instead)");
      if (static_cast<int>(entries->size()) > spec.max_entries)
        m.error("map", std::to_string(entries->size()) + " entries mapped, a PDO of this device holds at most " +
                           std::to_string(spec.max_entries));
      for (std::size_t k = 0; k < entries->size(); ++k) {
        const std::string path = indexed(m.field("map"), k);
        const auto entry = read_pdo_entry((*entries)[k], path, src);
        if (!entry) continue;
        check_entry_type((*entries)[k], path, src, *entry, p, spec);
        if (!mappable.empty() && std::find(mappable.begin(), mappable.end(), entry->object) == mappable.end()) {
          src.error((*entries)[k].Mark(), path,
                    object_hex(entry->object) + " may not be mapped into " + (receive ? "an RxPDO" : "a TxPDO") +
                        " of this device (its " + (receive ? "rx_mappable" : "tx_mappable") + " list)");
          continue;
        }
        if (record_mapping((*entries)[k], path, src, entry->object, mapped)) pdo.entries.push_back(*entry);
      }
    }
    out.push_back(std::move(pdo));
  }
}

// PDO objects belong to the gateway: a start-up write may not touch them.
void check_startup_writes(const MapReader& e, const EthercatDeviceSpec& spec) {
  for (std::size_t i = 0; i < spec.startup_writes.size(); ++i) {
    const auto id = spec.startup_writes[i].def.id;
    if ((id.index >= 0x1600 && id.index <= 0x17FF) || (id.index >= 0x1A00 && id.index <= 0x1BFF) ||
        (id.index >= 0x1C00 && id.index <= 0x1C3F))
      e.error("startup_writes", object_hex(id) + " is a PDO mapping or assignment object; the PDOs come from rxpdos/txpdos");
  }
}

// A multi-axis slave: every axis maps what axis 0 maps, at its own offset (each axis' master sees
// the same cyclic image), its controlword and statusword among them.
void check_axes(const MapReader& e, const EthercatDeviceSpec& spec) {
  if (spec.axes < 2) return;
  if (0x6000 + spec.axes * spec.axis_offset > 0x10000) {
    e.error("axes", std::to_string(spec.axes) + " axes at " + hex16(spec.axis_offset) + " apart do not fit below FFFFh");
    return;
  }
  std::vector<std::vector<cia402::ObjectId>> per_axis(static_cast<std::size_t>(spec.axes));
  for (const auto* pdos : {&spec.rxpdos, &spec.txpdos})
    for (const auto& pdo : *pdos)
      for (const auto& entry : pdo.entries)
        if (const AxisObject o = axis_object(spec, entry.object); o.axis >= 0)
          per_axis[static_cast<std::size_t>(o.axis)].push_back(o.local);
  for (int n = 1; n < spec.axes; ++n) {
    const auto d = cyclic_image_difference(per_axis[static_cast<std::size_t>(n)], per_axis[0], "mapped for axis 0");
    if (!d.empty())
      e.error("rxpdos", "axis " + std::to_string(n) + " of the slave (its objects at + " +
                            hex16(static_cast<std::uint16_t>(n * spec.axis_offset)) +
                            ") must map what axis 0 maps, as axis 0 numbers them:" + d);
  }
}

}  // namespace

void read_ethercat_device(const MapReader& root, DeviceProfile& p) {
  const MapReader e = root.map("ethercat", Need::Optional);
  if (!e.present()) return;
  auto& spec = p.sections.edit<EthercatDeviceSpec>();
  e.check_keys({"identities", "persona", "distributed_clocks", "coe_store", "axes", "axis_offset", "pdo_indexes",
                "max_entries", "mappable", "rxpdos", "txpdos", "startup_writes", "ignored_writes"});
  read_identities(e, spec);
  spec.persona = e.name("persona", Need::Optional).value_or(spec.persona);
  spec.distributed_clocks = e.boolean("distributed_clocks", Need::Optional).value_or(false);
  spec.coe_store = e.boolean("coe_store", Need::Optional).value_or(true);
  spec.axes = static_cast<int>(e.integer("axes", Need::Optional, 1, 8).value_or(1));
  spec.axis_offset = static_cast<std::uint16_t>(e.integer("axis_offset", Need::Optional, 0x100, 0x800).value_or(0x800));
  const MapReader indexes = e.map("pdo_indexes", Need::Optional);
  indexes.check_keys({"rx", "tx"});
  spec.rx_pdo_indexes = read_indexes(indexes, "rx", 0x1600, 0x17FF);
  spec.tx_pdo_indexes = read_indexes(indexes, "tx", 0x1A00, 0x1BFF);
  spec.max_entries = static_cast<int>(e.integer("max_entries", Need::Optional, 1, 254).value_or(254));
  const MapReader mappable = e.map("mappable", Need::Optional);
  mappable.check_keys({"rx", "tx"});
  spec.rx_mappable = read_objects(mappable, "rx");
  spec.tx_mappable = read_objects(mappable, "tx");
  std::vector<MappedEntry> rx;
  std::vector<MappedEntry> tx;
  read_pdos(e, true, p, spec, rx);
  read_pdos(e, false, p, spec, tx);
  check_one_way(e.source(), rx, tx);
  check_control_and_status(e, rx, "rxpdos", tx, "txpdos");
  check_axes(e, spec);
  read_startup_writes(e, "startup_writes", std::nullopt, spec.startup_writes);
  check_startup_writes(e, spec);
  spec.ignored_writes = read_objects(e, "ignored_writes");
}

std::vector<cia402::ObjectId> ethercat_mapped_objects(const DeviceProfile& p) {
  // The cyclic image of one axis: on a multi-axis slave the other axes' objects as axis 0 numbers
  // them (check_axes makes them the same), once.
  std::vector<cia402::ObjectId> mapped;
  const auto& spec = p.section<EthercatDeviceSpec>();
  for (const auto* pdos : {&spec.rxpdos, &spec.txpdos})
    for (const auto& pdo : *pdos)
      for (const auto& e : pdo.entries) {
        const cia402::ObjectId id = spec.axes > 1 ? axis_object(spec, e.object).local : e.object;
        if (spec.axes == 1 || std::find(mapped.begin(), mapped.end(), id) == mapped.end()) mapped.push_back(id);
      }
  return mapped;
}

}  // namespace drivegate::config
