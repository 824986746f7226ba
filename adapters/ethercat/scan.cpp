#include "adapters/ethercat/scan.hpp"

#include <poll.h>

#include <algorithm>
#include <cstdio>
#include <sstream>

#include "adapters/ethercat/link/ethercat_link.hpp"
#include "adapters/ethercat/wire/registers.hpp"
#include "config/device_profile.hpp"
#include "config/ethercat/plan.hpp"
#include "config/loader.hpp"
#include "config/scan_plan.hpp"
#include "profiles/cia402/sdo_abort.hpp"

namespace drivegate::ethercat {

namespace {

using namespace std::chrono_literals;

// CiA 402 device profile number in 1000h's low word [CiA 402-2 §6.2; digest "generic profile"].
constexpr std::uint32_t kCia402Profile = 0x0192;
// PDO assignment objects [ETG.1000.6 §5.6.7.4]: 1C12h the RxPDOs of SM2, 1C13h the TxPDOs of SM3.
constexpr std::uint16_t kRxAssign = 0x1C12;
constexpr std::uint16_t kTxAssign = 0x1C13;
// More PDOs or entries than this are not read (a mapping holds at most 254 entries; what the
// skeleton needs is the count and the sizes, and a bounded scan).
constexpr std::uint32_t kMaxAssigned = 32;
constexpr std::uint32_t kMaxMapped = 64;

std::string hex(std::uint32_t v, int digits) {
  char b[16];
  std::snprintf(b, sizeof b, "0x%0*X", digits, v);
  return b;
}

std::string hex4h(std::uint32_t v) {
  char b[16];
  std::snprintf(b, sizeof b, "%04Xh", v);
  return b;
}

std::string abort_words(std::uint32_t code) {
  return "abort " + hex(code, 8) + " (" + std::string(cia402::sdo_abort_text(code)) + ")";
}

}  // namespace

std::uint32_t ScannedPdo::bits() const noexcept {
  std::uint32_t b = 0;
  for (const auto& e : entries) b += e.bits;
  return b;
}

EthercatScan::EthercatScan(EthercatScanSettings settings) : settings_(settings) {
  LineBootConfig c;
  c.retries = 3;
  boot_ = std::make_unique<LineBoot>(std::span<const ExpectedSlave>(expected_), c);
  // No configured identity: every position takes any slave to PRE-OP.
  for (std::size_t k = 0; k < LineBoot::kMaxSlaves; ++k) boot_->accept_identities(k, {}, true);
}

EthercatScan::~EthercatScan() = default;

void EthercatScan::start(core::TimePoint now) {
  deadline_ = now + settings_.budget;
  phase_ = Phase::Boot;
  slaves_.clear();
  coe_.clear();
  line_text_.clear();
  boot_->start(now);
}

void EthercatScan::poll(core::TimePoint now, Transactions& tx) {
  if (phase_ == Phase::Done) return;
  if (now >= deadline_) {
    if (phase_ == Phase::Boot) {
      line_text_ = "the line did not finish its start-up within the scan's time";
      boot_finished();
    }
    for (auto& s : slaves_) {
      const auto k = static_cast<std::size_t>(s.position - 1);
      if (k < coe_.size() && coe_[k].client && !coe_[k].finished)
        s.notes.push_back("the scan's time ran out before its CoE objects were read");
    }
    finish(now);
    return;
  }
  switch (phase_) {
    case Phase::Boot:
      boot_->poll(now, tx);
      if (boot_->status() == LineStatus::Done || boot_->status() == LineStatus::Failed) boot_finished();
      break;
    case Phase::Registers:
      if (!registers_queued_) {
        registers_queued_ = true;
        registers_left_ = slaves_.size();
        for (const auto& s : slaves_)
          if (!tx.queue(this, s.position, Command::FPRD, physical_address(s.station, reg::kEscFeatures), 2))
            --registers_left_;
      }
      if (registers_left_ == 0) phase_ = Phase::Coe;
      break;
    case Phase::Coe: {
      bool all = true;
      for (std::size_t k = 0; k < coe_.size(); ++k) {
        CoeRun& run = coe_[k];
        if (!run.client || run.finished) continue;
        if (run.running != 0) {
          const CoeSdoResult r = run.client->result(run.running);
          if (r.status == CoeSdoStatus::Done || r.status == CoeSdoStatus::Failed) {
            run.client->take(run.running);
            run.running = 0;
            coe_answer(k, run.current, r);
          }
        }
        if (run.running == 0) {
          if (run.next < run.todo.size()) {
            run.current = run.todo[run.next++];
            run.running = coe_request(run);
            if (run.running == 0) {
              slaves_[k].notes.push_back("the CoE client refused a request for " + hex4h(run.current.index));
              run.finished = true;
            }
          } else {
            run.finished = true;
          }
        }
        if (!run.finished) {
          all = false;
          run.client->poll(now, tx);
        }
      }
      if (all) finish(now);
      break;
    }
    case Phase::Done: break;
  }
}

CoeSdoId EthercatScan::coe_request(CoeRun& run) {
  const Request& r = run.current;
  switch (r.what) {
    case Read::OdList: return run.client->od_list(OdListType::All, run.list);
    case Read::ObjectName: return run.client->object_description(r.index, run.name);
    default: return run.client->upload_value(r.index, r.subindex);
  }
}

void EthercatScan::boot_finished() {
  if (boot_->status() == LineStatus::Failed) line_text_ = std::string(boot_->line_text());
  const std::size_t n = boot_->slave_count();
  coe_.resize(n);
  for (std::size_t k = 0; k < n; ++k) {
    const SlaveReport& rep = boot_->slave(k);
    const SiiInfo& sii = boot_->sii(k);
    ScannedSlave s;
    s.position = static_cast<std::uint16_t>(k + 1);
    s.station = rep.station;
    s.state = rep.state;
    s.sii_ok = rep.status == SlaveStatus::Ready || rep.step > BootStep::Sii;
    if (rep.status != SlaveStatus::Ready) s.boot_text = std::string(rep.text.view());
    if (s.sii_ok) {
      s.identity = sii.header.identity;
      s.mailbox_protocols = sii.header.mailbox_protocols;
      if (sii.has_general) {
        s.coe_details = sii.general.coe_details;
        s.name = std::string(sii.string(sii.general.name_index));
      }
      for (std::size_t i = 0; i < sii.sync_manager_count; ++i) {
        const SiiSyncManager& sm = sii.sync_managers[i];
        if (sm.type == sii_sm_type::kOutputs) s.sm_output_bytes += sm.length;
        if (sm.type == sii_sm_type::kInputs) s.sm_input_bytes += sm.length;
      }
      // The SII's PDOs as assigned by default (SM2 outputs, SM3 inputs) [ETG.1000.6 §5.4 TXPDO/RXPDO].
      for (std::size_t i = 0; i < sii.pdo_count; ++i) {
        const SiiPdo& p = sii.pdos[i];
        if (p.sm != (p.tx ? 3 : 2)) continue;
        ScannedPdo out;
        out.index = p.index;
        for (const auto& e : sii.entries_of(p)) out.entries.push_back({e.index, e.subindex, e.bit_length});
        (p.tx ? s.txpdos : s.rxpdos).push_back(std::move(out));
      }
      if (!s.rxpdos.empty() || !s.txpdos.empty()) s.pdo_source = "SII";
    }
    const bool has_coe = (s.mailbox_protocols & mailbox_protocol::kCoE) != 0 && sii.header.standard_mailbox.present();
    if (s.sii_ok && has_coe && rep.status == SlaveStatus::Ready && rep.state == AlState::PreOp) {
      auto client = std::make_unique<CoeSdoClient>(rep.station, sii.header.standard_mailbox,
                                                   CoeSdoTiming{settings_.sdo_timeout, 1ms});
      if (client->valid()) {
        s.coe = true;
        CoeRun& run = coe_[k];
        run.client = std::move(client);
        run.todo.push_back({Read::DeviceType, 0x1000, 0, false, 0});
        for (std::uint8_t sub = 1; sub <= 4; ++sub) run.todo.push_back({Read::Identity, 0x1018, sub, false, 0});
        run.todo.push_back({Read::AssignCount, kRxAssign, 0, false, 0});
        run.todo.push_back({Read::AssignCount, kTxAssign, 0, true, 0});
        // SDO Information only where the SII offers it: a slave without it may not answer at
        // all, and the scan would wait for its timeout [ETG.1000.6 Table 21, CoE details].
        s.sdo_info = (s.coe_details & coe_details::kSdoInfo) != 0;
        if (s.sdo_info && settings_.max_objects > 0) {
          run.list.assign(settings_.max_objects, 0);
          run.todo.push_back({Read::OdList, 0, 0, false, 0});
        }
      } else {
        s.notes.push_back("its SII mailbox sizes cannot carry CoE SDO requests: objects not read");
      }
    } else if (s.sii_ok && has_coe) {
      s.notes.push_back("not in PRE-OP: its CoE objects were not read");
    }
    slaves_.push_back(std::move(s));
  }
  registers_queued_ = false;
  phase_ = Phase::Registers;
}

void EthercatScan::on_result(std::uint32_t tag, const DatagramAnswer& answer) noexcept {
  if (phase_ != Phase::Registers || tag == 0 || tag > slaves_.size()) return;
  ScannedSlave& s = slaves_[tag - 1];
  if (answer.outcome == DatagramOutcome::Answered && answer.wkc == 1 && answer.data.size() >= 2) {
    s.esc_features = static_cast<std::uint16_t>(answer.data[0] | (answer.data[1] << 8));
  }
  if (registers_left_ > 0) --registers_left_;
}

void EthercatScan::coe_answer(std::size_t k, const Request& r, const CoeSdoResult& result) {
  ScannedSlave& s = slaves_[k];
  CoeRun& run = coe_[k];
  const bool ok = result.status == CoeSdoStatus::Done;
  const std::uint32_t v = result.value;
  std::vector<ScannedPdo>& pdos = r.tx ? s.txpdos : s.rxpdos;
  switch (r.what) {
    case Read::DeviceType:
      if (ok) s.device_type = v;
      else s.notes.push_back("1000h (device type): " + abort_words(result.abort_code));
      break;
    case Read::Identity:
      if (ok) s.identity_object[static_cast<std::size_t>(r.subindex - 1)] = v;
      break;
    case Read::AssignCount: {
      if (!ok) {
        s.notes.push_back(hex4h(r.index) + " (PDO assignment): " + abort_words(result.abort_code) +
                          (s.pdo_source == "SII" ? "; the SII's PDOs are shown" : ""));
        break;
      }
      (r.tx ? run.assign_tx_ok : run.assign_rx_ok) = true;
      // The objects' PDOs replace the SII's for this direction.
      pdos.clear();
      const std::uint32_t n = std::min<std::uint32_t>(v & 0xFFU, kMaxAssigned);
      for (std::uint32_t i = 1; i <= n; ++i)
        run.todo.push_back({Read::AssignEntry, r.index, static_cast<std::uint8_t>(i), r.tx, 0});
      break;
    }
    case Read::AssignEntry:
      if (!ok) {
        s.notes.push_back(hex4h(r.index) + ":" + std::to_string(r.subindex) + ": " + abort_words(result.abort_code));
        break;
      }
      pdos.push_back(ScannedPdo{static_cast<std::uint16_t>(v & 0xFFFFU), {}});
      run.todo.push_back({Read::MapCount, static_cast<std::uint16_t>(v & 0xFFFFU), 0, r.tx, pdos.size() - 1});
      break;
    case Read::MapCount: {
      if (!ok) {
        s.notes.push_back(hex4h(r.index) + " (PDO mapping): " + abort_words(result.abort_code));
        break;
      }
      const std::uint32_t n = std::min<std::uint32_t>(v & 0xFFU, kMaxMapped);
      for (std::uint32_t i = 1; i <= n; ++i)
        run.todo.push_back({Read::MapEntry, r.index, static_cast<std::uint8_t>(i), r.tx, r.pdo});
      break;
    }
    case Read::MapEntry:
      if (!ok) {
        s.notes.push_back(hex4h(r.index) + ":" + std::to_string(r.subindex) + ": " + abort_words(result.abort_code));
        break;
      }
      // A mapping entry: index (bits 31..16), sub-index (15..8), length in bits (7..0) [ETG.1000.6 §5.6.7.4].
      if (r.pdo < pdos.size())
        pdos[r.pdo].entries.push_back({static_cast<std::uint16_t>(v >> 16), static_cast<std::uint8_t>((v >> 8) & 0xFFU),
                                       static_cast<std::uint8_t>(v & 0xFFU)});
      break;
    case Read::OdList:
      if (!ok) {
        s.notes.push_back("SDO Information (Get OD List): " + abort_words(result.abort_code));
        break;
      }
      s.objects_read = true;
      s.objects.clear();
      for (std::size_t i = 0; i < result.size && i < run.list.size(); ++i) s.objects.push_back({run.list[i], 0, {}});
      if (settings_.object_names)
        for (std::size_t i = 0; i < s.objects.size(); ++i)
          run.todo.push_back({Read::ObjectName, s.objects[i].index, 0, false, i});
      break;
    case Read::ObjectName:
      if (!ok) {
        if (run.names_failed++ == 0) run.first_name_abort = result.abort_code;
      } else if (r.pdo < s.objects.size()) {
        s.objects[r.pdo].object_code = result.info.object_code;
        s.objects[r.pdo].name.assign(run.name.data(), result.size);
      }
      if (r.pdo + 1 == s.objects.size() && run.names_failed > 0)
        s.notes.push_back("SDO Information: " + std::to_string(run.names_failed) + " of " +
                          std::to_string(s.objects.size()) + " object descriptions failed, the first with " +
                          abort_words(run.first_name_abort));
      break;
  }
  if (run.assign_rx_ok || run.assign_tx_ok) s.pdo_source = "1C12h/1C13h";
}

void EthercatScan::finish(core::TimePoint) {
  for (auto& run : coe_)
    if (run.client) run.finished = true;
  phase_ = Phase::Done;
}

// --- driving it ----------------------------------------------------------------------------------

std::vector<ScannedSlave> scan_line(Link& link, const EthercatScanSettings& settings, ScanClock& clock,
                                    std::string& line_text) {
  auto scan = std::make_unique<EthercatScan>(settings);
  auto tx = std::make_unique<Transactions>();
  auto rx = std::make_unique<std::array<FrameBuffer, 8>>();
  scan->start(clock.now());
  while (!scan->done()) {
    const core::TimePoint now = clock.now();
    for (std::size_t got; (got = link.receive(*rx)) > 0;)
      for (std::size_t i = 0; i < got; ++i) tx->on_frame((*rx)[i].view());
    tx->expire(now);
    scan->poll(now, *tx);
    const auto frames = tx->take_frames(now + settings.frame_timeout);
    if (!frames.empty()) (void)link.send(frames);
    if (!scan->done()) clock.wait(now + 1ms, link);
  }
  line_text = scan->line_text();
  return scan->slaves();
}

std::vector<config::DeviceProfile> ethercat_scan_profiles(const std::vector<std::filesystem::path>& dirs,
                                                          const config::BusTypeRegistry& types,
                                                          std::vector<std::string>& notes) {
  return config::scan_device_profiles(
      dirs, types, [](const config::DeviceProfile& p) { return p.has_section<config::EthercatDeviceSpec>(); }, notes);
}

// --- what was found ------------------------------------------------------------------------------

namespace {

std::string device_type_words(std::uint32_t device_type) {
  const std::uint32_t profile = device_type & 0xFFFFU;
  if (profile == kCia402Profile) {
    // Bits 23..16 the drive type [CiA 402-2 §6.2].
    switch ((device_type >> 16) & 0xFFU) {
      case 0x01: return "CiA 402 drive: frequency converter";
      case 0x02: return "CiA 402 drive: servo drive";
      case 0x03: return "CiA 402 drive: stepper motor";
      default: return "CiA 402 drive";
    }
  }
  if (profile == 0) return "no standard device profile";
  return "device profile " + std::to_string(profile);
}

std::string protocols_words(std::uint16_t p) {
  std::string s;
  const auto add = [&](std::uint16_t bit, const char* name) {
    if ((p & bit) != 0) s += (s.empty() ? "" : ", ") + std::string(name);
  };
  add(mailbox_protocol::kCoE, "CoE");
  add(mailbox_protocol::kFoE, "FoE");
  add(mailbox_protocol::kEoE, "EoE");
  add(mailbox_protocol::kSoE, "SoE");
  add(mailbox_protocol::kAoE, "AoE");
  add(mailbox_protocol::kVoE, "VoE");
  return s.empty() ? "none" : s;
}

std::string pdo_words(const std::vector<ScannedPdo>& pdos) {
  if (pdos.empty()) return "none";
  std::string s;
  std::uint32_t bits = 0;
  for (const auto& p : pdos) {
    s += (s.empty() ? "" : "; ") + hex4h(p.index) + " [";
    bool first = true;
    for (const auto& e : p.entries) {
      char b[24];
      std::snprintf(b, sizeof b, "%s%04X:%02X/%u", first ? "" : " ", e.index, e.subindex, e.bits);
      s += b;
      first = false;
    }
    s += "]";
    bits += p.bits();
  }
  return s + " (" + std::to_string((bits + 7) / 8) + " bytes)";
}

std::uint32_t pdo_bytes(const std::vector<ScannedPdo>& pdos) {
  std::uint32_t bits = 0;
  for (const auto& p : pdos) bits += p.bits();
  return (bits + 7) / 8;
}

// The OD list by area [CiA 301 §7.4.1 object dictionary structure; ETG.1000.6 §5.6.7]:
// "97 objects: 26 communication (1000h-1FFFh), 12 manufacturer (2000h-5FFFh), 59 profile (6000h-9FFFh)".
std::string objects_words(const std::vector<ScannedObject>& objects) {
  std::size_t comm = 0, manufacturer = 0, profile = 0, other = 0;
  for (const auto& o : objects) {
    if (o.index >= 0x1000 && o.index <= 0x1FFF) ++comm;
    else if (o.index >= 0x2000 && o.index <= 0x5FFF) ++manufacturer;
    else if (o.index >= 0x6000 && o.index <= 0x9FFF) ++profile;
    else ++other;
  }
  std::string s = std::to_string(objects.size()) + (objects.size() == 1 ? " object" : " objects");
  std::string parts;
  const auto add = [&](std::size_t n, const char* what) {
    if (n != 0) parts += (parts.empty() ? "" : ", ") + std::to_string(n) + " " + what;
  };
  add(comm, "communication (1000h-1FFFh)");
  add(manufacturer, "manufacturer (2000h-5FFFh)");
  add(profile, "profile (6000h-9FFFh)");
  add(other, "other");
  return parts.empty() ? s : s + ": " + parts;
}

std::string identity_words(const SiiIdentity& id) {
  return "vendor " + hex(id.vendor_id, 8) + " product " + hex(id.product_code, 8) + " revision " +
         hex(id.revision, 8);
}

// The profile of a slave (see the header): 3 an identity with its revision, 2 an identity for any
// revision, 1 a profile without identities whose 1000h fits.
const config::DeviceProfile* match(const ScannedSlave& s, const std::vector<config::DeviceProfile>& profiles,
                                   std::string& reason) {
  const config::DeviceProfile* best = nullptr;
  int best_score = 0;
  std::string others;
  for (const auto& p : profiles) {
    const auto& spec = p.section<config::EthercatDeviceSpec>();
    int score = 0;
    for (const auto& id : spec.identities) {
      if (id.vendor_id != s.identity.vendor_id || id.product_code != s.identity.product_code) continue;
      if (id.revision && *id.revision != s.identity.revision) continue;
      score = std::max(score, id.revision ? 3 : 2);
    }
    if (spec.identities.empty() && s.device_type && (*s.device_type & 0xFFFFU) == kCia402Profile) score = 1;
    if (score == 0) continue;
    if (score > best_score) {
      best = &p;
      best_score = score;
      others.clear();
    } else if (score == best_score) {
      others += (others.empty() ? "" : ", ") + p.name;
    }
  }
  if (best == nullptr) return nullptr;
  if (best_score > 1)
    reason = identity_words(s.identity) + " is " + best->name + "'s";
  else
    reason = identity_words(s.identity) + " matches no profile; " + best->name + " fits: 1000h = " +
             hex(*s.device_type, 8) + ", a CiA 402 drive";
  if (!others.empty()) reason += " (fits too: " + others + ")";
  return best;
}

bool plain_name(const std::string& v) {
  return !v.empty() && std::all_of(v.begin(), v.end(), [](char c) {
    return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_' || c == '-';
  });
}

}  // namespace

core::ScanResult ethercat_scan_result(const std::vector<ScannedSlave>& slaves, const std::string& line_text,
                                      const std::string& interface, const std::vector<config::DeviceProfile>& profiles) {
  core::ScanResult r;
  r.bus_type = "ethercat";
  r.bus_name = plain_name(interface) ? interface : "ec0";
  r.description = "raw ethernet " + interface;
  r.bus_options.emplace_back("transport", "raw");
  r.bus_options.emplace_back("interface", interface);
  // 1 ms first: the ESR/Dunker drives' usual cycle (dunker-ethercat-coe.md §9); the image check
  // takes a longer one when the line's frame does not fit in half of it.
  r.cycle_times = {1ms, 2ms, 4ms, 8ms, 16ms};
  if (!line_text.empty()) r.notes.push_back(line_text);

  // What each slave becomes: 2 an axis, 1 an io: entry, 0 a comment.
  std::vector<int> role(slaves.size(), 0);
  std::size_t last_configured = 0;  // position
  for (const auto& s : slaves) {
    core::FoundDevice d;
    d.address.number = s.position;
    d.address.text = "position " + std::to_string(s.position) + " (" + hex4h(s.station) + ")";
    d.device_type = s.device_type;
    if (s.device_type) d.device_type_text = device_type_words(*s.device_type);
    if (s.sii_ok) {
      d.identity.vendor_id = s.identity.vendor_id;
      d.identity.product_code = s.identity.product_code;
      d.identity.revision = s.identity.revision;
      d.identity.serial = s.identity_object[3] ? *s.identity_object[3] : s.identity.serial;
      if (!s.name.empty()) d.name = s.name;
      d.notes.push_back("mailbox protocols: " + protocols_words(s.mailbox_protocols));
      d.notes.push_back(std::string("distributed clocks: ") +
                        (!s.esc_features ? "unknown (0008h not read)"
                                         : s.dc() ? "yes (0008h = " + hex(*s.esc_features, 4) + ")"
                                                  : "no (0008h = " + hex(*s.esc_features, 4) + ")"));
      if (!s.pdo_source.empty())
        d.notes.push_back("PDOs (" + s.pdo_source + "): outputs " + pdo_words(s.rxpdos) + "; inputs " +
                          pdo_words(s.txpdos));
      if (s.objects_read) {
        d.notes.push_back("object dictionary (SDO Information): " + objects_words(s.objects));
        // With objects=1: one line per object that was described.
        for (const auto& o : s.objects) {
          if (o.name.empty() && o.object_code == 0) continue;
          const char* code = o.object_code == object_code::kArray    ? " (array)"
                             : o.object_code == object_code::kRecord ? " (record)"
                                                                     : "";
          d.notes.push_back("  " + hex4h(o.index) + " " + o.name + code);
        }
      } else if (s.coe && !s.sdo_info) {
        d.notes.push_back("object dictionary: not listed (the SII does not offer SDO Information)");
      }
      // 1018h differs from the SII: the SII is what the bus checks at every start.
      const auto& o = s.identity_object;
      if ((o[0] && *o[0] != s.identity.vendor_id) || (o[1] && *o[1] != s.identity.product_code))
        d.notes.push_back("1018h (vendor " + hex(o[0].value_or(0), 8) + " product " + hex(o[1].value_or(0), 8) +
                          ") differs from the SII's identity");
    }
    d.notes.push_back(std::string("left in ") + std::string(to_string(s.state)));
    if (!s.boot_text.empty()) d.notes.push_back(s.boot_text);
    d.notes.insert(d.notes.end(), s.notes.begin(), s.notes.end());
    const std::size_t k = r.devices.size();
    if (!s.sii_ok) {
      d.profile_reason = "its SII could not be read: no profile can be chosen";
      d.next_step = "check the slave (its EEPROM) and scan again";
    } else if (!s.coe) {
      const bool mailbox_coe = (s.mailbox_protocols & mailbox_protocol::kCoE) != 0;
      if (mailbox_coe) {
        d.profile_reason = identity_words(s.identity) + ": CoE, but its objects could not be read";
        d.next_step = "its CoE objects could not be read (see its notes); scan again";
      } else {
        role[k] = 1;
        d.profile_reason = identity_words(s.identity) + ": no CoE, an I/O slave";
        d.next_step = "its process data on the I/O topic: `io:` entry io-" + std::to_string(s.position) + " of the bus";
      }
    } else if (const auto* p = match(s, profiles, d.profile_reason)) {
      d.profile = p->name;
      d.drive = true;
      if (const int axes = p->section<config::EthercatDeviceSpec>().axes; axes > 1)
        for (int n = 0; n < axes; ++n) d.axis_keys.push_back("ethercat: { axis: " + std::to_string(n) + " }");
      role[k] = 2;
    } else {
      d.profile_reason = identity_words(s.identity) + " matches no profile" +
                         (s.device_type ? " and no profile fits 1000h = " + hex(*s.device_type, 8)
                                        : std::string(" and 1000h could not be read"));
      d.next_step = "add a device profile with an ethercat: section for it (profiles/devices/README.md) and scan again";
    }
    if (role[k] != 0) last_configured = s.position;
    r.devices.push_back(std::move(d));
  }
  // Every position up to the last configured one must be configured (the bus starts every slave
  // the frame passes): a slave before it without a profile goes into io: as well.
  std::vector<std::string> io;
  for (std::size_t k = 0; k < slaves.size(); ++k) {
    const ScannedSlave& s = slaves[k];
    if (role[k] == 2 || (role[k] == 0 && s.position > last_configured)) continue;
    std::string item = "{ name: io-" + std::to_string(s.position) + ", position: " + std::to_string(s.position);
    if (s.sii_ok) item += ", vendor_id: " + hex(s.identity.vendor_id, 8) + ", product_code: " + hex(s.identity.product_code, 8);
    // Sizes as the bus takes them: the SII's SyncM lengths, else the SII's default PDOs.
    const std::uint32_t in = s.sm_input_bytes != 0 ? s.sm_input_bytes : pdo_bytes(s.txpdos);
    const std::uint32_t out = s.sm_output_bytes != 0 ? s.sm_output_bytes : pdo_bytes(s.rxpdos);
    if (in != 0 && in <= 1024) item += ", inputs: " + std::to_string(in);
    if (out != 0 && out <= 1024) item += ", outputs: " + std::to_string(out);
    item += " }";
    if (role[k] == 0) {
      item += "    # CHECK: no device profile; its process data as I/O so that the line starts";
      r.devices[k].next_step = "`io:` entry io-" + std::to_string(s.position) +
                               " (the positions up to the last configured one must all be configured); " +
                               r.devices[k].next_step;
    }
    io.push_back(std::move(item));
  }
  if (!io.empty()) r.bus_lists.emplace_back("io", std::move(io));
  return r;
}

// --- the request ---------------------------------------------------------------------------------

namespace {

class SteadyScanClock final : public ScanClock {
 public:
  core::TimePoint now() override { return clock_.now(); }
  void wait(core::TimePoint until, const Link& link) override {
    const auto left = until - clock_.now();
    if (left <= core::Duration::zero()) return;
    const int ms = static_cast<int>(std::max<std::int64_t>(
        1, std::chrono::duration_cast<std::chrono::milliseconds>(left).count()));
    if (link.wait_fd() >= 0) {
      pollfd p{link.wait_fd(), POLLIN, 0};
      ::poll(&p, 1, ms);
    }
  }

 private:
  core::SteadyClock clock_;
};

}  // namespace

config::BusPlan ethercat_scan_plan(const core::ScanRequest& request, const config::BusTypeRegistry& types) {
  const std::string& where = request.where;
  std::string interface = where.substr(0, where.find('?'));
  auto options = config::scan_where_options(where);
  if (interface == "sim")
    throw core::ScanError("sim: a simulated line exists only inside a gateway; scan the interface drivegate-sim "
                          "serves (ethercat:IFACE)");
  if (interface == "raw") interface.clear();  // ethercat:raw?interface=eth1
  const std::vector<std::string> allowed{"interface", "sdo_timeout", "transition_timeout", "objects"};
  std::ostringstream y;
  y << "gateway: { name: scan }\nbuses:\n  - name: scan\n    type: ethercat\n    cycle_time: 1ms\n"
    << "    options:\n      transport: raw\n";
  bool named = false;
  if (!interface.empty()) {
    if (!config::scan_plain_value(interface))
      throw core::ScanError("\"" + interface + "\": an interface name is letters, digits, '.', '_', '-' and '@'");
    y << "      interface: " << interface << "\n";
    named = true;
  }
  for (const auto& [key, value] : options) {
    if (std::find(allowed.begin(), allowed.end(), key) == allowed.end())
      throw core::ScanError("\"" + key + "\" is not a scan option of ethercat; it takes interface, sdo_timeout, "
                            "transition_timeout, objects");
    if (key == "objects") {  // the scan's own, not a bus option
      if (value != "0" && value != "1")
        throw core::ScanError("objects=\"" + value + "\": 1 lists every object's name, 0 (the default) counts them");
      continue;
    }
    if (!config::scan_plain_value(value)) throw core::ScanError(key + "=\"" + value + "\": a value is letters, digits, '.', '_' and '-'");
    if (key == "interface") {
      if (named) throw core::ScanError("the interface is named twice");
      named = true;
    }
    y << "      " << key << ": " << value << "\n";
  }
  if (!named)
    throw core::ScanError("name the Ethernet interface the line is plugged into: ethercat:eth1");
  y << "axes: []\n";
  return config::scan_bus_plan(y.str(), request, types);
}

bool ethercat_scan_object_names(const core::ScanRequest& request) {
  for (const auto& [key, value] : config::scan_where_options(request.where))
    if (key == "objects") return value == "1";
  return false;
}

core::ScanResult run_ethercat_scan(const config::BusPlan& plan, const core::ScanRequest& request,
                                   const config::BusTypeRegistry& types) {
  std::vector<std::string> profile_notes;
  const auto profiles = ethercat_scan_profiles(request.device_dirs, types, profile_notes);
  const auto& o = plan.section<config::EthercatBusOptions>();
  RawSocketOptions ro;
  ro.interface = o.interface;
  RawSocketLink link(std::move(ro));
  try {
    link.open();
  } catch (const LinkError& e) {
    throw core::ScanError(std::string("cannot open the line: ") + e.what());
  }
  EthercatScanSettings settings;
  settings.frame_timeout = std::max<core::Duration>(request.answer_timeout, 1ms);
  settings.sdo_timeout = o.sdo_timeout;
  settings.object_names = ethercat_scan_object_names(request);
  SteadyScanClock clock;
  const auto start = clock.now();
  std::string line_text;
  const auto slaves = scan_line(link, settings, clock, line_text);
  core::ScanResult r = ethercat_scan_result(slaves, line_text, o.interface, profiles);
  r.description = link.describe();
  r.elapsed = clock.now() - start;
  r.notes.insert(r.notes.end(), profile_notes.begin(), profile_notes.end());
  link.close();
  return r;
}

}  // namespace drivegate::ethercat
