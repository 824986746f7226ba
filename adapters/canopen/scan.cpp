#include "adapters/canopen/scan.hpp"

#include <poll.h>

#include <algorithm>
#include <bit>
#include <cstdio>
#include <sstream>
#include <thread>

#include "adapters/canopen/canopen_bus.hpp"
#include "adapters/canopen/flush_queue.hpp"
#include "adapters/canopen/wire/bit_timing.hpp"
#include "adapters/canopen/wire/cob_id.hpp"
#include "config/canopen/bus_options.hpp"
#include "config/canopen/plan.hpp"
#include "config/loader.hpp"
#include "config/scan_plan.hpp"
#include "profiles/cia402/sdo_abort.hpp"

namespace drivegate::canopen {

namespace {

using namespace std::chrono_literals;

// Abort codes the scan acts on: the node has no such object, the node did not answer, the value
// does not fit [CiA 301 §7.2.4.3.17].
using cia402::sdo_abort_code::kNoObject;
using cia402::sdo_abort_code::kNoSubIndex;
using cia402::sdo_abort_code::kOutOfMemory;
using cia402::sdo_abort_code::kTimeout;

constexpr ObjectId kDeviceType{0x1000, 0};
// The identity reads after the probe, in CanopenScan::Node::reads order.
constexpr std::array<ObjectId, 7> kIdentityObjects{{
    {0x1018, 1}, {0x1018, 2}, {0x1018, 3}, {0x1018, 4}, {0x1008, 0}, {0x1009, 0}, {0x100A, 0}}};
constexpr std::size_t kFirstString = 4;

std::string hex32(std::uint32_t v) {
  char b[16];
  std::snprintf(b, sizeof b, "0x%08X", v);
  return b;
}

std::string object_name(ObjectId o) {
  char b[16];
  if (o.index == 0x1018)
    std::snprintf(b, sizeof b, "%04Xh:%02X", o.index, o.sub);
  else
    std::snprintf(b, sizeof b, "%04Xh", o.index);
  return b;
}

std::string abort_words(std::uint32_t code) {
  return "abort " + hex32(code) + " (" + std::string(cia402::sdo_abort_text(code)) + ")";
}

// A VISIBLE_STRING as a person reads it: trailing NULs and blanks dropped (drives pad fixed-size
// strings), anything outside printable ASCII shown as \xNN.
std::string visible_string(std::span<const std::uint8_t> bytes) {
  std::size_t n = bytes.size();
  while (n > 0 && (bytes[n - 1] == 0 || bytes[n - 1] == ' ')) --n;
  std::string s;
  for (std::size_t i = 0; i < n; ++i) {
    const auto c = bytes[i];
    if (c >= 0x20 && c < 0x7F) {
      s += static_cast<char>(c);
    } else {
      char b[8];
      std::snprintf(b, sizeof b, "\\x%02X", c);
      s += b;
    }
  }
  return s;
}

std::vector<SdoChannelConfig> every_default_channel() {
  std::vector<SdoChannelConfig> channels;
  for (int n = kMinNodeId; n <= kMaxNodeId; ++n) channels.push_back({static_cast<NodeId>(n), 1, 0, 0});
  return channels;
}

// Each request's answer time: the configured time plus what the probe's 127 requests and their
// answers take on the wire, since they queue there behind each other.
core::Duration request_timeout(const CanopenScanSettings& s) {
  return s.answer_timeout + 2 * kMaxNodeId * frame_time(8, s.bitrate);
}

std::string times(std::uint64_t n) { return std::to_string(n) + (n == 1 ? " time" : " times"); }

// "another CANopen master is active on this bus (SYNC 080h seen 25 times, SDO requests on 605h): ..."
std::string refusal_words(const ForeignMasterFrames& f) {
  std::string seen;
  const auto add = [&](const std::string& what) { seen += (seen.empty() ? "" : ", ") + what; };
  if (f.sync > 0) add("SYNC 080h seen " + times(f.sync));
  if (f.nmt > 0) add("NMT commands on 000h seen " + times(f.nmt));
  if (f.rpdo > 0) add("RPDOs seen " + times(f.rpdo));
  if (f.sdo_requests > 0) {
    std::string on;
    int listed = 0;
    for (int n = kMinNodeId; n <= kMaxNodeId; ++n) {
      if (!f.sdo_request_on[static_cast<std::size_t>(n)]) continue;
      if (++listed > 8) {
        on += ", ...";
        break;
      }
      char b[8];
      std::snprintf(b, sizeof b, "%03Xh", cob::sdo_rx(static_cast<NodeId>(n)));
      on += (on.empty() ? " on " : ", ") + std::string(b);
    }
    add("SDO requests" + on + " seen " + times(f.sdo_requests));
  }
  if (f.guarding > 0) add("node guarding requests seen " + times(f.guarding));
  return "another CANopen master is active on this bus (" + seen +
         "): stop it, or scan while it is off; the scan sent nothing, its SDO requests would break that "
         "master's transfers";
}

}  // namespace

CanopenScan::CanopenScan(CanopenScanSettings settings, core::TimePoint start)
    : settings_(settings),
      listen_end_(start + settings.listen),
      // The probe, then at most 7 identity reads one after the other, each within its timeout.
      hard_deadline_(listen_end_ + (kIdentityReads + 2) * request_timeout(settings)),
      sdo_(every_default_channel(), SdoTiming{request_timeout(settings), 0}) {
  for (int n = kMinNodeId; n <= kMaxNodeId; ++n) {
    auto& node = nodes_[static_cast<std::size_t>(n)];
    node.seen.node = static_cast<NodeId>(n);
    for (auto& s : node.strings) s.resize(settings_.string_limit);
  }
}

void CanopenScan::on_frame(const CanFrame& frame, core::TimePoint now) noexcept {
  ++counters_.frames;
  if (!frame.valid()) {
    ++counters_.malformed;
    return;
  }
  if (frame.extended) return;  // not CANopen's (CiA 301 uses 11-bit identifiers); another protocol's
  const CobSplit s = split_cob_id(frame.id);
  Node* node = valid_node_id(s.node) ? &nodes_[s.node] : nullptr;
  switch (s.function) {
    case Function::SdoTx:
      if (node == nullptr || first_answer(*node, frame)) sdo_.on_frame(frame, now);
      break;
    case Function::ErrorControl:
      if (node == nullptr) break;
      if (frame.remote) {  // a node guarding request: someone guards this node
        ++foreign_.guarding;
        break;
      }
      if (const auto ec = decode_error_control(frame.payload())) {
        node->seen.heard = true;
        node->seen.state = ec->state;
        if (ec->state == NmtState::Initialising) node->seen.boot_up = true;
      } else {
        ++counters_.malformed;
      }
      break;
    case Function::Emcy:
    case Function::Tpdo:
      if (node != nullptr) node->seen.heard = true;
      break;
    case Function::Nmt:
      ++foreign_.nmt;
      break;
    case Function::Sync:
      ++foreign_.sync;
      break;
    case Function::Rpdo:
      ++foreign_.rpdo;
      break;
    case Function::SdoRx:
      ++foreign_.sdo_requests;
      if (node != nullptr) foreign_.sdo_request_on[s.node] = true;
      break;
    case Function::Time:
    case Function::Other: break;
  }
}

bool CanopenScan::first_answer(Node& n, const CanFrame& frame) noexcept {
  const SdoDecoded d = decode_sdo_response(frame.payload());
  const SdoCommand c = d.message.command;
  if (d.error != SdoDecodeError::None || (c != SdoCommand::InitiateUploadResponse && c != SdoCommand::Abort))
    return true;
  Answers* a = d.message.object == kDeviceType ? &n.answers[0] : nullptr;
  for (std::size_t i = 0; a == nullptr && i < kIdentityObjects.size(); ++i)
    if (d.message.object == kIdentityObjects[i]) a = &n.answers[i + 1];
  if (a == nullptr) return true;  // not an object the scan asks: the SDO client counts it
  SdoBytes bytes{};
  std::copy_n(frame.data.begin(), bytes.size(), bytes.begin());
  if (!a->first) {
    a->first = bytes;
    a->segmented = c == SdoCommand::InitiateUploadResponse && !d.message.expedited;
    return true;
  }
  if (c == SdoCommand::Abort && a->segmented) {  // the server ends its segmented upload
    a->segmented = false;
    return true;
  }
  if (!a->second) a->second = bytes;
  return false;
}

void CanopenScan::submit_identity(Node& n) noexcept {
  for (std::size_t i = 0; i < kIdentityObjects.size(); ++i)
    n.reads[i] = i < kFirstString
                     ? sdo_.read(n.seen.node - 1, kIdentityObjects[i], 4)
                     : sdo_.read_into(n.seen.node - 1, kIdentityObjects[i], n.strings[i - kFirstString]);
}

void CanopenScan::collect(Node& n, core::TimePoint now) {
  // A request still under way: wait for it (the hard deadline cancels it).
  const auto running = [&](SdoRequestId id) {
    const auto st = sdo_.result(id).status;
    return id != kNoSdoRequest && (st == SdoStatus::Queued || st == SdoStatus::InFlight);
  };
  if (n.finished) return;
  auto& seen = n.seen;
  if (n.probe != kNoSdoRequest) {
    if (running(n.probe)) return;
    const SdoResult r = sdo_.take(n.probe);
    n.probe = kNoSdoRequest;
    if (r.status == SdoStatus::Done) {
      seen.answered = true;
      seen.device_type = r.value;
      if (r.size != 4) seen.notes.push_back("1000h answered " + std::to_string(r.size) + " bytes, not 4");
    } else if (r.abort_code != kTimeout) {
      seen.answered = true;
      seen.notes.push_back("1000h: " + abort_words(r.abort_code));
    } else {
      if (seen.heard)
        seen.notes.push_back(std::string("heard on the bus (") + to_string(seen.state) +
                             ") but its SDO server did not answer 1000h");
      n.finished = true;
      return;
    }
    submit_identity(n);
    return;
  }
  if (std::any_of(n.reads.begin(), n.reads.end(), running) && now < hard_deadline_) return;
  for (std::size_t i = 0; i < kIdentityObjects.size(); ++i) {
    const ObjectId o = kIdentityObjects[i];
    const SdoRequestId id = n.reads[i];
    const SdoResult r = sdo_.result(id);
    std::optional<std::string> text;
    if (r.status == SdoStatus::Done) {
      if (i < kFirstString) {
        std::optional<std::uint32_t>* const fields[] = {&seen.identity.vendor_id, &seen.identity.product_code,
                                                         &seen.identity.revision, &seen.identity.serial};
        *fields[i] = r.value;
      } else {
        text = visible_string(sdo_.data(id));
      }
    } else if (r.status == SdoStatus::Failed && (r.abort_code == kNoObject || r.abort_code == kNoSubIndex)) {
      seen.notes.push_back(object_name(o) + " not present");
    } else if (r.status == SdoStatus::Failed && r.abort_code == kTimeout) {
      seen.notes.push_back(object_name(o) + ": no answer in time");
    } else if (r.status == SdoStatus::Failed && r.abort_code == kOutOfMemory && i >= kFirstString) {
      // The client aborts an upload longer than its buffer with 05040005h (sdo_client.hpp).
      seen.notes.push_back(object_name(o) + ": longer than " + std::to_string(settings_.string_limit) +
                           " bytes, not read");
    } else if (r.status == SdoStatus::Failed) {
      seen.notes.push_back(object_name(o) + ": " + abort_words(r.abort_code));
    } else {
      seen.notes.push_back(object_name(o) + ": no answer before the scan's deadline");
    }
    if (i == kFirstString) seen.name = text;
    if (i == kFirstString + 1) seen.hardware_version = text;
    if (i == kFirstString + 2) seen.software_version = text;
    sdo_.cancel(id);
  }
  n.finished = true;
}

void CanopenScan::poll(core::TimePoint now, TxQueue& tx) {
  if (phase_ == Phase::Listen && now >= listen_end_ && foreign_.total() > 0) {
    refusal_ = refusal_words(foreign_);
    phase_ = Phase::Done;
    return;
  }
  if (phase_ == Phase::Listen && now >= listen_end_) {
    phase_ = Phase::Probe;
    for (int n = kMinNodeId; n <= kMaxNodeId; ++n)
      nodes_[static_cast<std::size_t>(n)].probe = sdo_.read(n - 1, kDeviceType, 4);
  }
  if (phase_ == Phase::Probe) {
    for (int n = kMinNodeId; n <= kMaxNodeId; ++n) collect(nodes_[static_cast<std::size_t>(n)], now);
    if (now >= hard_deadline_) finish_all();
    if (std::all_of(nodes_.begin() + 1, nodes_.end(), [](const Node& n) { return n.finished; })) phase_ = Phase::Done;
  }
  sdo_.poll(now, tx);
}

void CanopenScan::finish_all() {
  for (int i = kMinNodeId; i <= kMaxNodeId; ++i) {
    auto& n = nodes_[static_cast<std::size_t>(i)];
    if (n.finished) continue;
    if (n.probe != kNoSdoRequest) {  // the probe itself is still running: treat it as unanswered
      sdo_.cancel(n.probe);
      n.probe = kNoSdoRequest;
      n.seen.notes.push_back("1000h: no answer before the scan's deadline");
      n.finished = true;
      continue;
    }
    collect(n, hard_deadline_);
  }
}

core::TimePoint CanopenScan::next_deadline() const noexcept {
  switch (phase_) {
    case Phase::Listen: return listen_end_;
    case Phase::Probe: return std::min(sdo_.next_deadline(), hard_deadline_);
    case Phase::Done: break;
  }
  return core::TimePoint::max();
}

namespace {

// One answer as the note on a second answer shows it: the value, the upload's size, the abort.
std::string answer_words(const SdoBytes& bytes) {
  const SdoMessage m = decode_sdo_response(bytes).message;
  if (m.command == SdoCommand::Abort) return abort_words(m.abort_code);
  if (!m.expedited) return m.size_indicated ? "a segmented upload of " + std::to_string(m.size) + " bytes"
                                            : "a segmented upload";
  std::uint32_t v = 0;
  for (std::size_t i = m.length; i-- > 0;) v = (v << 8) | m.data[i];
  return hex32(v);
}

}  // namespace

std::vector<ScannedNode> CanopenScan::nodes() const {
  std::vector<ScannedNode> out;
  for (int i = kMinNodeId; i <= kMaxNodeId; ++i) {
    const auto& n = nodes_[static_cast<std::size_t>(i)];
    if (!n.seen.heard && !n.seen.answered) continue;
    out.push_back(n.seen);
    for (std::size_t k = 0; k < n.answers.size(); ++k) {
      const Answers& a = n.answers[k];
      if (!a.second) continue;
      // Compared as read: 42h (size not indicated) and 43h with the same value say the same.
      const std::string object = object_name(k == 0 ? kDeviceType : kIdentityObjects[k - 1]);
      const std::string first = answer_words(*a.first);
      const std::string second = answer_words(*a.second);
      out.back().second_answers.push_back(first == second
                                              ? object + ": answered twice, the same (" + first + ")"
                                              : object + ": answered twice, differently: " + first + " and " + second);
    }
  }
  return out;
}

CanopenScanCounters CanopenScan::counters() const noexcept {
  CanopenScanCounters c = counters_;
  c.foreign_master = foreign_.total();
  c.sdo_unexpected = sdo_.counters().unexpected;
  c.sdo_malformed = sdo_.counters().malformed;
  return c;
}

// --- the bus a request names ------------------------------------------------------------------

bool scan_option_given(const core::ScanRequest& request, const std::string& key) {
  const auto options = config::scan_where_options(request.where);
  return std::any_of(options.begin(), options.end(), [&](const auto& o) { return o.first == key; });
}

config::BusPlan scan_bus_plan(const core::ScanRequest& request, const config::BusTypeRegistry& types) {
  const std::string& where = request.where;
  std::string transport = where.substr(0, where.find('?'));
  auto options = config::scan_where_options(where);
  if (transport.empty())
    throw core::ScanError("name the bus: a CAN interface (canopen:can0) or udp-multicast "
                          "(canopen:udp-multicast?group=239.74.163.2&port=43113&interface=127.0.0.1)");
  if (transport == "sim")
    throw core::ScanError("sim: the in-process bus exists only inside a gateway; scan socketcan or udp-multicast");
  if (transport != "socketcan" && transport != "udp-multicast") {
    options.insert(options.begin(), {"interface", transport});  // canopen:can0
    transport = "socketcan";
  }
  const std::vector<std::string> allowed = transport == "socketcan"
                                               ? std::vector<std::string>{"interface", "bitrate"}
                                               : std::vector<std::string>{"group", "port", "interface", "bitrate"};
  std::ostringstream y;
  y << "gateway: { name: scan }\nbuses:\n  - name: scan\n    type: canopen\n    cycle_time: 4ms\n"
    << "    options:\n      transport: " << transport << "\n";
  for (const auto& [key, value] : options) {
    if (std::find(allowed.begin(), allowed.end(), key) == allowed.end()) {
      std::string list;
      for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
      throw core::ScanError("\"" + key + "\" is not a scan option of " + transport +
                            "; it takes " + list);
    }
    if (!config::scan_plain_value(value))
      throw core::ScanError(key + "=\"" + value +
                            "\": a value is letters, digits, '.', '_' and '-'");
    y << "      " << key << ": " << value << "\n";
  }
  y << "axes: []\n";
  return config::scan_bus_plan(y.str(), request, types);
}

// --- what was found -------------------------------------------------------------------------

std::string device_type_text(std::uint32_t device_type) {
  const std::uint32_t profile = device_type & 0xFFFF;
  const std::uint32_t kind = (device_type >> 16) & 0xFF;
  switch (profile) {
    case 0: return "no standard device profile";
    case 401: return "CiA 401 I/O module";
    case 402:
      // Bits 23..16 the drive type [CiA 402-2 §6.2; 02h servo drive: AKD part 1 §13.1,
      // dunker-ethercat-coe.md §10].
      switch (kind) {
        case 0x01: return "CiA 402 drive: frequency converter";
        case 0x02: return "CiA 402 drive: servo drive";
        case 0x03: return "CiA 402 drive: stepper motor";
        default: return "CiA 402 drive";
      }
    case 404: return "CiA 404 measuring device";
    case 406: return "CiA 406 encoder";
    default: return "device profile " + std::to_string(profile);
  }
}

std::vector<config::DeviceProfile> scan_profiles(const std::vector<std::filesystem::path>& dirs,
                                                 const config::BusTypeRegistry& types, std::vector<std::string>& notes) {
  return config::scan_device_profiles(
      dirs, types, [](const config::DeviceProfile& p) { return p.has_section<config::CanopenDeviceSpec>(); }, notes);
}

namespace {

bool type_fits(const config::DeviceProfile& p, std::optional<std::uint32_t> device_type) {
  const auto& c = p.section<config::CanopenDeviceSpec>();
  return !c.device_type || (device_type && (*device_type & c.device_type_mask) == (*c.device_type & c.device_type_mask));
}

std::string identity_words(const core::DeviceIdentityNumbers& id) {
  std::string s = id.vendor_id ? "vendor " + hex32(*id.vendor_id) : "no vendor-ID";
  if (id.product_code) s += " product " + hex32(*id.product_code);
  return s;
}

// The device profile that runs the device: one whose identity (vendor-ID, and product code where it
// names one) is the device's, else one without an identity whose device type fits 1000h. Among
// equals, the one that asks least of 1000h (fewest mask bits), then by name.
void match_profile(core::FoundDevice& d, const std::vector<config::DeviceProfile>& profiles) {
  const auto& id = d.identity;
  struct Fit {
    const config::DeviceProfile* profile;
    int score;  // 3 vendor and product, 2 vendor, 1 device type only
  };
  std::vector<Fit> fits;
  std::string identity_of;  // a profile whose identity is the device's, but not its 1000h
  for (const auto& p : profiles) {
    const auto& pid = p.identity;
    if (pid.vendor_id || pid.product_code) {
      const bool same = (!pid.vendor_id || pid.vendor_id == id.vendor_id) &&
                        (!pid.product_code || pid.product_code == id.product_code);
      if (!same) continue;
      if (!type_fits(p, d.device_type)) {
        d.notes.push_back(identity_words(id) + " is " + p.name + "'s, but its 1000h " +
                          (d.device_type ? hex32(*d.device_type) : std::string("(not read)")) + " is not the " +
                          hex32(*p.section<config::CanopenDeviceSpec>().device_type) + " that profile expects");
        if (identity_of.empty()) identity_of = p.name;
        continue;
      }
      fits.push_back({&p, pid.product_code ? 3 : 2});
    } else if (p.section<config::CanopenDeviceSpec>().device_type && type_fits(p, d.device_type)) {
      fits.push_back({&p, 1});
    }
  }
  std::sort(fits.begin(), fits.end(), [](const Fit& a, const Fit& b) {
    if (a.score != b.score) return a.score > b.score;
    const int ma = std::popcount(a.profile->section<config::CanopenDeviceSpec>().device_type_mask);
    const int mb = std::popcount(b.profile->section<config::CanopenDeviceSpec>().device_type_mask);
    if (ma != mb) return ma < mb;
    return a.profile->name < b.profile->name;
  });
  const std::string type = d.device_type ? "1000h = " + hex32(*d.device_type) + ", a " + d.device_type_text
                                         : std::string("1000h not read");
  if (fits.empty()) {
    d.profile_reason = identity_words(id) + " matches no profile and no profile fits " + type;
    if (!d.device_type) {
      d.next_step = "its device type (1000h) could not be read (see its notes); without it no profile can be chosen";
    } else if (!identity_of.empty()) {
      d.profile_reason = identity_words(id) + " is " + identity_of + "'s, but its " + type + ", not what that "
                         "profile expects";
      d.next_step = "its identity is " + identity_of + "'s but its device type (1000h) is not; check the device's "
                    "setup (drive type, firmware) against that profile and scan again";
    } else {
      d.next_step = "add a device profile for it (profiles/devices/README.md) and scan again";
    }
    return;
  }
  const Fit& best = fits.front();
  d.profile = best.profile->name;
  d.drive = true;
  if (best.score > 1) {
    d.profile_reason = identity_words(id) + " is " + d.profile + "'s";
  } else {
    d.profile_reason = identity_words(id) + " matches no profile; " + d.profile + " fits: " + type;
  }
  std::string others;
  for (std::size_t i = 1; i < fits.size() && fits[i].score == best.score; ++i)
    others += (others.empty() ? "" : ", ") + fits[i].profile->name;
  if (!others.empty()) d.profile_reason += " (fits too: " + others + ")";
}

const config::DeviceProfile* profile_named(const std::vector<config::DeviceProfile>& profiles,
                                           const std::string& name) {
  for (const auto& p : profiles)
    if (p.name == name) return &p;
  return nullptr;
}

// What a person reads about a node-ID with more than one device answering: the channel, the two
// causes, and the drive found below it (`earlier`) whose extra SDO channels land on this node-ID
// (stoeber-sd6-canopen.md §5.3, quirk 1).
std::string conflict_words(NodeId node, const std::vector<core::FoundDevice>& earlier,
                           const std::vector<config::DeviceProfile>& profiles) {
  char b[160];
  std::snprintf(b, sizeof b, "node-ID %d: more than one device answers on %03Xh/%03Xh (a node-ID conflict", node,
                cob::sdo_rx(node), cob::sdo_tx(node));
  std::string s = b;
  for (const auto& d : earlier) {
    const int gap = node - d.address.number;
    const auto* p = profile_named(profiles, d.profile);
    if (p == nullptr || gap % 32 != 0 || gap / 32 >= p->section<config::CanopenDeviceSpec>().sdo_channels) continue;
    std::snprintf(b, sizeof b, ", or another drive's extra SDO channel: node %d is a %s whose SDO channel %d is node-ID %d",
                  d.address.number, d.profile.c_str(), gap / 32 + 1, node);
    s += b;
    break;
  }
  return s + "); its identity cannot be trusted";
}

bool same_device(const core::FoundDevice& a, const core::FoundDevice& b) {
  return a.device_type == b.device_type && a.identity.vendor_id == b.identity.vendor_id &&
         a.identity.product_code == b.identity.product_code && a.identity.revision == b.identity.revision &&
         a.identity.serial == b.identity.serial && a.name == b.name && a.hardware_version == b.hardware_version &&
         a.software_version == b.software_version;
}

// A drive with SDO channels 2..4 in the STÖBER scheme answers on 600h + 20h x (k-1) + id as well
// (stoeber-sd6-canopen.md §5.3, quirk 1), which is the default channel of node id + 32 (k-1): the
// probe finds it there again. Such an answer is the drive's channel k, not a node, when the drive's
// profile has that channel, the answers are the same device, and nothing was heard from that
// node-ID itself.
void fold_extra_channels(std::vector<core::FoundDevice>& devices, const std::vector<bool>& heard,
                         const std::vector<config::DeviceProfile>& profiles, std::vector<bool>& taken) {
  std::vector<bool> drop(devices.size(), false);
  for (std::size_t i = 0; i < devices.size(); ++i) {
    for (std::size_t j = 0; j < i; ++j) {
      const int gap = devices[i].address.number - devices[j].address.number;
      const auto* p = profile_named(profiles, devices[j].profile);
      if (heard[i] || !devices[i].conflict.empty() || drop[j] || gap % 32 != 0 || p == nullptr || gap / 32 >= p->section<config::CanopenDeviceSpec>().sdo_channels ||
          !same_device(devices[i], devices[j]))
        continue;
      char b[96];
      std::snprintf(b, sizeof b, "also answers on %03Xh/%03Xh (node-ID %d): its SDO channel %d",
                    cob::kSdoRxBase + static_cast<unsigned>(devices[i].address.number),
                    cob::kSdoTxBase + static_cast<unsigned>(devices[i].address.number), devices[i].address.number,
                    gap / 32 + 1);
      devices[j].notes.emplace_back(b);
      taken[static_cast<std::size_t>(devices[i].address.number)] = false;
      drop[i] = true;
      break;
    }
  }
  std::vector<core::FoundDevice> kept;
  for (std::size_t i = 0; i < devices.size(); ++i)
    if (!drop[i]) kept.push_back(std::move(devices[i]));
  devices = std::move(kept);
}

}  // namespace

core::ScanResult scan_result(const CanopenScan& scan, const config::BusPlan& plan,
                             const std::vector<config::DeviceProfile>& profiles, bool bitrate_given) {
  if (!scan.refusal().empty()) throw core::ScanError(scan.refusal());
  const auto& c = plan.section<config::CanopenBusOptions>();
  core::ScanResult r;
  r.bus_type = "canopen";
  r.bus_options.emplace_back("transport", config::to_string(c.transport));
  r.bus_options.emplace_back("interface", c.interface);
  r.bus_options.emplace_back("bitrate", std::to_string(c.bitrate));
  if (!bitrate_given) {
    r.bus_option_checks.emplace_back("bitrate", "the bus' bit rate (not read from the interface; set it to the "
                                                "interface's)");
    r.assumed = "bit rate not given (" + std::to_string(c.bitrate / 1000) +
                " kbit/s assumed for the answer times and the load estimate)";
  }
  if (c.transport == config::CanTransportKind::UdpMulticast) {
    r.bus_name = "can0";
    r.bus_options.emplace_back("group", c.group);
    r.bus_options.emplace_back("port", std::to_string(c.port));
  } else {
    r.bus_name = c.interface;
  }
  // 4 ms first: room for several drives' PDOs at 500 kbit/s; the SD6 takes 1, 2, 4 or 8 ms
  // (stoeber-sd6-canopen.md §7).
  r.cycle_times = {4ms, 8ms, 2ms, 1ms, 16ms, 32ms};
  std::vector<bool> taken(kMaxNodeId + 1, false);
  std::vector<bool> heard;
  for (const auto& n : scan.nodes()) {
    core::FoundDevice d;
    d.address.number = n.node;
    char addr[16];
    std::snprintf(addr, sizeof addr, "%d (%02Xh)", n.node, n.node);
    d.address.text = addr;
    d.device_type = n.device_type;
    if (n.device_type) d.device_type_text = device_type_text(*n.device_type);
    d.identity = n.identity;
    d.name = n.name;
    d.hardware_version = n.hardware_version;
    d.software_version = n.software_version;
    d.notes = n.notes;
    d.notes.insert(d.notes.end(), n.second_answers.begin(), n.second_answers.end());
    if (n.boot_up) d.notes.insert(d.notes.begin(), "booted during the scan");
    if (!n.second_answers.empty()) {
      d.conflict = conflict_words(n.node, r.devices, profiles);
      d.profile_reason = "its identity cannot be trusted (more than one device answers): no profile chosen";
      r.warnings.push_back(d.conflict);
    } else if (n.answered) {
      match_profile(d, profiles);
    } else {  // listed, so heard
      d.profile_reason = "heard (heartbeat, boot-up, EMCY or PDO) but its SDO server did not answer";
      d.next_step = "its SDO server did not answer; check the device's node-ID and SDO settings and the bus' bit "
                    "rate, and scan again";
    }
    taken[n.node] = true;
    r.devices.push_back(std::move(d));
    heard.push_back(n.heard);
  }
  fold_extra_channels(r.devices, heard, profiles, taken);
  // The gateway's own node-ID (its heartbeat 700h + ID) must be one no drive has: 127 unless taken.
  if (taken[kMaxNodeId]) {
    int free_id = kMaxNodeId;
    while (free_id > 0 && taken[static_cast<std::size_t>(free_id)]) --free_id;
    if (free_id > 0) r.bus_options.emplace_back("gateway_node_id", std::to_string(free_id));
  }
  const auto k = scan.counters();
  if (k.foreign_master > 0)
    r.notes.push_back(std::to_string(k.foreign_master) +
                      " frames of another master (SYNC, NMT, RPDO, SDO requests, guarding): a master runs this bus; "
                      "do not start a gateway on it as well");
  if (k.malformed > 0) r.notes.push_back(std::to_string(k.malformed) + " malformed frames dropped");
  if (k.sdo_unexpected + k.sdo_malformed > 0)
    r.notes.push_back(std::to_string(k.sdo_unexpected + k.sdo_malformed) +
                      " SDO answers that fit no request (wrong length, unknown specifier, toggle) dropped");
  return r;
}

core::ScanResult run_scan(const config::BusPlan& plan, const core::ScanRequest& request,
                          const config::BusTypeRegistry& types) {
  std::vector<std::string> profile_notes;
  const auto profiles = scan_profiles(request.device_dirs, types, profile_notes);
  std::unique_ptr<Transport> transport;
  try {
    transport = make_transport(plan);
    transport->open();
  } catch (const TransportError& e) {
    throw core::ScanError(std::string("cannot open the bus: ") + e.what());
  }
  const core::SteadyClock clock;
  const auto start = clock.now();
  CanopenScanSettings settings;
  settings.listen = request.listen;
  settings.answer_timeout = request.answer_timeout;
  settings.bitrate = plan.section<config::CanopenBusOptions>().bitrate;
  CanopenScan scan(settings, start);
  TxQueue out;
  std::uint64_t not_sent = 0;
  std::array<CanFrame, 64> rx{};
  while (!scan.done()) {
    auto now = clock.now();
    for (std::size_t got; (got = transport->receive(rx, now)) > 0;)
      for (std::size_t i = 0; i < got; ++i) scan.on_frame(rx[i], now);
    scan.poll(now, out);
    not_sent += flush_queue(out, *transport, now).refused;  // a full interface queue: the rest go next round
    // Sleep until the engine has something to do, a frame arrives, or (frames waiting to be sent) 1 ms.
    now = clock.now();
    auto until = scan.next_deadline();
    if (!out.empty()) until = std::min(until, now + 1ms);
    if (scan.done() || until <= now) continue;
    const auto wait = std::chrono::duration_cast<std::chrono::milliseconds>(until - now) + 1ms;
    if (transport->wait_fd() >= 0) {
      pollfd p{transport->wait_fd(), POLLIN, 0};
      ::poll(&p, 1, static_cast<int>(std::min<std::int64_t>(wait.count(), 1000)));
    } else {
      std::this_thread::sleep_for(std::min(wait, std::chrono::milliseconds(1)));
    }
  }
  core::ScanResult r = scan_result(scan, plan, profiles, scan_option_given(request, "bitrate"));
  r.description = transport->describe();
  r.elapsed = clock.now() - start;
  if (not_sent > 0)
    r.notes.push_back(std::to_string(not_sent) + " requests could not be sent (" +
                      to_string(transport->controller_state()) + "): nodes may be missing");
  r.notes.insert(r.notes.end(), profile_notes.begin(), profile_notes.end());
  transport->close();
  return r;
}

}  // namespace drivegate::canopen
