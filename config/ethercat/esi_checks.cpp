#include "config/ethercat/esi_checks.hpp"

#include <algorithm>
#include <cstdio>
#include <set>

#include "config/object_text.hpp"
#include "config/text_util.hpp"

namespace drivegate::config {

namespace {

namespace fs = std::filesystem;

std::string hex16(std::uint16_t v) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "%04Xh", unsigned{v});
  return buf;
}

std::string type_text(cia402::DataType type) {
  return std::string{to_string(type)} + " (" + std::to_string(size_of(type) * 8) + " bits)";
}

std::string esi_object_text(const EsiObject& o) {
  return o.type + " (" + std::to_string(o.bits) + " bits, line " + std::to_string(o.line) + ")";
}

std::string pdo_mapping_text(const EsiObject& o) {
  if (o.rx_mappable && o.tx_mappable) return "RT";
  if (o.rx_mappable) return "R";
  if (o.tx_mappable) return "T";
  return "none";
}

// "vendor 0x0000000F product 0x00006755 revision 0x00000001".
std::string identity_text(const EthercatIdentity& id) {
  std::string s = "vendor " + esi_hex32(id.vendor_id) + " product " + esi_hex32(id.product_code);
  if (id.revision) s += " revision " + esi_hex32(*id.revision);
  return s;
}

std::string devices_text(const EsiFile& esi) {
  std::vector<std::string> items;
  for (const auto& d : esi.devices) items.push_back(esi_device_text(d));
  return "vendor " + esi_hex32(esi.vendor_id) + ": " + join(items);
}

// The one with the highest revision (a device without RevisionNo counts lowest).
const EsiDevice* newest(const std::vector<const EsiDevice*>& devices) {
  const EsiDevice* best = nullptr;
  for (const EsiDevice* d : devices)
    if (best == nullptr || d->revision.value_or(0) > best->revision.value_or(0) || (!best->revision && d->revision))
      best = d;
  return best;
}

// The products of the file, each once.
std::set<std::uint32_t> products(const EsiFile& esi) {
  std::set<std::uint32_t> out;
  for (const auto& d : esi.devices) out.insert(d.product_code);
  return out;
}

// Where the axis' objects are: a profile lists its PDO entries and start-up writes as the slave
// numbers them, every axis' at its own offset (ETG.6010; profiles/devices/README.md), and the bus
// maps and writes them so for the whole slave: the ESI is checked against them as they are, for
// any axis. (Offsetting them again by the axis took axis 1's 6840h for 7040h, its 6040h for 6840h.)
cia402::ObjectId on_axis(cia402::ObjectId id, const EthercatDeviceSpec& /*spec*/, int /*slave_axis*/) { return id; }

const EsiPdoEntry* find_pdo_entry(const EsiDevice& dev, cia402::ObjectId id, bool rx) {
  for (const auto& pdo : rx ? dev.rxpdos : dev.txpdos)
    for (const auto& e : pdo.entries)
      if (e.object == id) return &e;
  return nullptr;
}

std::string entry_text(cia402::ObjectId id, int bits) {
  return id.index == 0 ? "gap (" + std::to_string(bits) + " bits)"
                       : object_text(id) + " (" + std::to_string(bits) + " bits)";
}

void check_fixed(const MapReader& m, const DeviceProfile& device, const EthercatDeviceSpec& spec, int slave_axis,
                 const std::string& esi_name, const EsiDevice& dev, bool rx) {
  for (const auto& pdo : rx ? spec.rxpdos : spec.txpdos) {
    const auto& list = rx ? dev.rxpdos : dev.txpdos;
    const auto it = std::find_if(list.begin(), list.end(), [&](const EsiPdo& p) { return p.index == pdo.index; });
    if (it == list.end() || !it->fixed) continue;
    bool same = it->entries.size() == pdo.entries.size();
    for (std::size_t i = 0; same && i < pdo.entries.size(); ++i)
      same = it->entries[i].object == on_axis(pdo.entries[i].object, spec, slave_axis) &&
             it->entries[i].bits == pdo.entries[i].bits;
    if (same) continue;
    std::vector<std::string> ours;
    std::vector<std::string> theirs;
    for (const auto& e : pdo.entries) ours.push_back(entry_text(on_axis(e.object, spec, slave_axis), e.bits));
    for (const auto& e : it->entries) theirs.push_back(entry_text(e.object, e.bits));
    m.error("esi", "device \"" + device.name + "\" maps " + hex16(pdo.index) + " as " + join(ours) + "; " + esi_name +
                       " lists " + hex16(pdo.index) + " as fixed (line " + std::to_string(it->line) + ") with " +
                       join(theirs));
  }
}

void check_maps(const MapReader& m, const DeviceProfile& device, const EthercatDeviceSpec& spec, int slave_axis,
                const std::string& esi_name, const EsiDevice& dev, bool rx) {
  for (const auto& pdo : rx ? spec.rxpdos : spec.txpdos) {
    for (const auto& e : pdo.entries) {
      const cia402::ObjectId id = on_axis(e.object, spec, slave_axis);
      const std::string what = "device \"" + device.name + "\" maps " + object_text(id) + " in " + hex16(pdo.index) + ", ";
      const EsiPdoEntry* listed = find_pdo_entry(dev, id, rx);
      if (!dev.has_dictionary) {
        // Without a dictionary only the ESI's own PDOs say how large an object is.
        if (listed == nullptr) listed = find_pdo_entry(dev, id, !rx);
        if (listed != nullptr && listed->bits != e.bits)
          m.error("esi", what + "as " + type_text(e.type) + "; " + esi_name + " maps it with " +
                             std::to_string(listed->bits) + " bits (line " + std::to_string(listed->line) + ")");
        continue;
      }
      const EsiObject* o = find_esi_object(dev.objects, id);
      if (o == nullptr) {
        m.error("esi", what + "which " + esi_name + " does not list");
        continue;
      }
      if (o->bits != e.bits) {
        m.error("esi", what + "as " + type_text(e.type) + "; " + esi_name + " has " + esi_object_text(*o));
        continue;
      }
      // Mappable in that direction: PdoMapping R/T, or the ESI maps it into such a PDO itself.
      if (!(rx ? o->rx_mappable : o->tx_mappable) && listed == nullptr)
        m.error("esi", what + "which " + esi_name + " does not let map into " + (rx ? "an RxPDO" : "a TxPDO") +
                           " (PdoMapping " + pdo_mapping_text(*o) + ", line " + std::to_string(o->line) + ")");
    }
  }
}

void check_writes(const MapReader& m, const DeviceProfile& device, const EthercatDeviceSpec& spec, int slave_axis,
                  const std::string& esi_name, const EsiDevice& dev) {
  if (!dev.has_dictionary) return;
  for (const auto& w : spec.startup_writes) {
    const cia402::ObjectId id = on_axis(w.def.id, spec, slave_axis);
    const std::string what = "device \"" + device.name + "\" start-up write of " + object_text(id) + " ";
    const EsiObject* o = find_esi_object(dev.objects, id);
    if (o == nullptr)
      m.error("esi", what + "names an object " + esi_name + " does not list");
    else if (!o->writable())
      m.error("esi", what + "names an object that is " + std::string{to_string(o->access)} + " in " + esi_name +
                         " (line " + std::to_string(o->line) + ")");
    else if (o->bits != size_of(w.def.type) * 8)
      m.error("esi", what + "writes " + type_text(w.def.type) + "; " + esi_name + " has " + esi_object_text(*o));
  }
}

}  // namespace

std::optional<EsiFile> read_esi_key(const MapReader& m, const fs::path& base_dir, std::string& absolute) {
  const auto text = m.string("esi", Need::Optional);
  if (!text) return std::nullopt;
  const fs::path p{*text};
  const fs::path file = (p.is_absolute() ? p : base_dir / p).lexically_normal();
  std::error_code ec;
  if (!fs::is_regular_file(file, ec)) {
    m.error("esi", "file \"" + file.string() + "\" does not exist (relative paths start at the config file's directory)");
    return std::nullopt;
  }
  absolute = file.string();
  auto esi = load_esi(file, *m.source().problems);
  if (!esi) m.error("esi", "ESI \"" + file.string() + "\" has errors, listed with its file name");
  return esi;
}

const EsiDevice* pick_esi_device(const MapReader& m, const EsiFile& esi, const std::string& esi_name,
                                 const DeviceProfile& device) {
  const auto& spec = device.section<EthercatDeviceSpec>();
  if (spec.identities.empty()) {
    if (products(esi).size() != 1) {
      m.error("esi", esi_name + " describes " + std::to_string(products(esi).size()) + " products (" +
                         devices_text(esi) + "); device \"" + device.name +
                         "\" lists no identity to choose one by (give the profile identities)");
      return nullptr;
    }
    std::vector<const EsiDevice*> all;
    for (const auto& d : esi.devices) all.push_back(&d);
    const EsiDevice* d = newest(all);
    // A profile without identities stands for any CiA 402 drive [ETG.6010 profile number 402].
    if (d->profile_no && *d->profile_no != 402) {
      m.error("esi", esi_name + " describes " + esi_device_text(*d) + " with profile " + std::to_string(*d->profile_no) +
                         ", but device \"" + device.name + "\" lists no identity and so takes CiA 402 drives only");
      return nullptr;
    }
    return d;
  }
  for (const auto& id : spec.identities) {
    if (id.vendor_id != esi.vendor_id) continue;
    if (const EsiDevice* d = newest(find_esi_devices(esi, id.product_code, id.revision))) return d;
  }
  std::vector<std::string> ids;
  for (const auto& id : spec.identities) ids.push_back(identity_text(id));
  m.error("esi", esi_name + " describes " + devices_text(esi) + "; none is an identity of device \"" + device.name +
                     "\" (" + join(ids) + ")");
  return nullptr;
}

void check_device_against_esi(const MapReader& m, const DeviceProfile& device, int slave_axis,
                              const std::string& esi_name, const EsiDevice& dev) {
  const auto& spec = device.section<EthercatDeviceSpec>();
  for (const bool rx : {true, false}) {
    check_maps(m, device, spec, slave_axis, esi_name, dev, rx);
    check_fixed(m, device, spec, slave_axis, esi_name, dev, rx);
  }
  check_writes(m, device, spec, slave_axis, esi_name, dev);
}

void check_io_slave_against_esi(const MapReader& m, const EsiFile& esi, const std::string& esi_name,
                                EthercatIoSlave& slave) {
  const std::string who = "I/O slave \"" + slave.name + "\"";
  if (slave.vendor_id && *slave.vendor_id != esi.vendor_id) {
    m.error("esi", who + " has vendor_id " + esi_hex32(*slave.vendor_id) + "; " + esi_name + " describes " +
                       devices_text(esi));
    return;
  }
  const EsiDevice* dev = nullptr;
  if (slave.product_code) {
    dev = newest(find_esi_devices(esi, *slave.product_code, std::nullopt));
    if (dev == nullptr) {
      m.error("esi", who + " has product_code " + esi_hex32(*slave.product_code) + "; " + esi_name + " describes " +
                         devices_text(esi));
      return;
    }
  } else if (products(esi).size() == 1) {
    std::vector<const EsiDevice*> all;
    for (const auto& d : esi.devices) all.push_back(&d);
    dev = newest(all);
  } else {
    m.error("esi", esi_name + " describes " + std::to_string(products(esi).size()) + " products (" + devices_text(esi) +
                       "); give " + who + " the product_code of one");
    return;
  }
  slave.vendor_id = esi.vendor_id;
  slave.product_code = dev->product_code;
  slave.esi_device = esi_device_text(*dev);
  // The PDOs with an Sm= are the ones assigned by default [ETG.2000 PdoType], their bytes what the
  // slave exchanges unless configured otherwise.
  for (const bool rx : {true, false}) {
    const auto& given = rx ? slave.output_bytes : slave.input_bytes;
    if (!given) continue;
    int bits = 0;
    std::vector<std::string> names;
    for (const auto& p : rx ? dev->rxpdos : dev->txpdos)
      if (p.sm) {
        bits += p.bits();
        names.push_back(hex16(p.index));
      }
    const int bytes = (bits + 7) / 8;
    if (bytes != *given)
      m.error(rx ? "outputs" : "inputs",
              who + " has " + std::to_string(*given) + " byte" + (*given == 1 ? "" : "s") + " of " +
                  (rx ? "outputs" : "inputs") + ", but " + esi_name + " assigns " + std::to_string(bytes) + " byte" +
                  (bytes == 1 ? "" : "s") + " of " + (rx ? "RxPDOs" : "TxPDOs") + " by default" +
                  (names.empty() ? std::string{} : " (" + join(names) + ")") + " to " + esi_device_text(*dev));
  }
}

}  // namespace drivegate::config
