#include "adapters/profinet/scan.hpp"

#include <poll.h>

#include <algorithm>
#include <bit>
#include <cstdio>
#include <map>
#include <set>
#include <sstream>

#include "adapters/link/interface.hpp"
#include "adapters/link/raw_socket_link.hpp"
#include "adapters/profinet/link/profinet_link.hpp"
#include "config/profinet/bus_options.hpp"
#include "config/profinet/plan.hpp"
#include "config/scalars.hpp"
#include "config/scan_plan.hpp"
#include "config/text_util.hpp"
#include "profiles/profidrive/profidrive_master.hpp"
#include "profiles/profidrive/telegram.hpp"

namespace drivegate::profinet {

namespace {

using namespace std::chrono_literals;

// The skeleton's send clock: 1 ms, the common one (32 x 31.25 us).
constexpr core::Duration kSkeletonSendClock = 1ms;
// Without a drive that needs more: the option's default update time (16 x 1 ms).
constexpr int kDefaultReductionRatio = 16;
constexpr int kMaxReductionRatio = 512;  // RT class 1 [IEC 61158-6-10, IOCRBlockReq ReductionRatio]

std::string hex4(std::uint32_t v) {
  char b[16];
  std::snprintf(b, sizeof b, "0x%04X", v);
  return b;
}

std::string mac_words(const MacAddress& mac) { return mac_text(mac).data(); }

// DeviceRoleDetails in words [IEC 61158-6-10 §4.3]: "IO device", "IO device + IO controller".
std::string role_words(const DcpStation& s) {
  if (!s.has_device_role) return "role not given";
  std::string out;
  const std::pair<std::uint8_t, const char*> roles[] = {{device_role::kIoDevice, "IO device"},
                                                        {device_role::kIoController, "IO controller"},
                                                        {device_role::kIoMultidevice, "IO multidevice"},
                                                        {device_role::kSupervisor, "IO supervisor"}};
  for (const auto& [bit, words] : roles)
    if ((s.device_role & bit) != 0) out += (out.empty() ? "" : " + ") + std::string(words);
  return out.empty() ? "role " + hex4(s.device_role) : out;
}

std::string ip_block_words(std::uint16_t info) {
  std::string out = (info & 0x7F) == ip_block_info::kSet         ? "set"
                    : (info & 0x7F) == ip_block_info::kSetByDhcp ? "set by DHCP"
                    : (info & 0x7F) == ip_block_info::kNotSet    ? "not set"
                                                                  : "BlockInfo " + hex4(info);
  if ((info & ip_block_info::kConflict) != 0) out += ", address conflict detected by the device";
  return out;
}

std::string suite_words(const DcpStation& s) {
  return config::ipv4_text(ipv4_host(s.ip.address)) + "/" + config::ipv4_text(ipv4_host(s.ip.netmask)) + " gateway " +
         config::ipv4_text(ipv4_host(s.ip.gateway));
}

// Why the configuration cannot name this station ("" when it can).
std::string name_problem(const DcpStation& s) {
  if (!s.has_name || s.name().empty()) return "it answers without a NameOfStation";
  if (const NameError e = validate_name_of_station(s.name()); e != NameError::None)
    return "its NameOfStation \"" + std::string(s.name()) + "\" breaks the NameOfStation rules (" +
           std::string(to_string(e)) + ")";
  return {};
}

// The skeleton's IP suite of a station: its own where the configuration takes it, else a free
// address of the interface's subnet.
struct SkeletonSuite {
  std::uint32_t ip = 0, netmask = 0, gateway = 0;
  std::string check;  // why the address is a suggestion ("" when it is the device's own)
};

class AddressPlanner {
 public:
  AddressPlanner(const ScanInterface& iface, std::span<const DcpStation> stations) : iface_(iface) {
    if (iface.address != 0) used_.insert(iface.address);
    for (const auto& s : stations)
      if (s.has_ip && ipv4_host(s.ip.address) != 0) used_.insert(ipv4_host(s.ip.address));
  }

  SkeletonSuite plan(const DcpStation& s) {
    SkeletonSuite out;
    const std::uint32_t ip = s.has_ip ? ipv4_host(s.ip.address) : 0;
    const std::uint32_t mask = s.has_ip ? ipv4_host(s.ip.netmask) : 0;
    std::string why;
    if (ip == 0) {
      why = "the station has no IP address";
    } else if (!config::ipv4_netmask_problem(mask).empty() || !config::ipv4_host_problem(ip, mask).empty()) {
      why = "its address " + config::ipv4_text(ip) + "/" + config::ipv4_text(mask) + " is no unicast host address";
    } else if (iface_.address != 0 && (ip & iface_.netmask) != (iface_.address & iface_.netmask)) {
      why = "its address " + config::ipv4_text(ip) + " is outside " + iface_.name + "'s subnet " +
            config::ipv4_text(iface_.address & iface_.netmask) + "/" + std::to_string(std::popcount(iface_.netmask));
    } else if (!given_.insert(ip).second) {
      why = "its address " + config::ipv4_text(ip) + " is another station's too";
    } else {
      out.ip = ip;
      out.netmask = mask;
      const std::uint32_t gw = ipv4_host(s.ip.gateway);
      // 0.0.0.0 (or the station's own address, as some devices say it) is no gateway.
      if (gw != 0 && gw != ip && (gw & mask) == (ip & mask)) out.gateway = gw;
      return out;
    }
    out.netmask = iface_.address != 0 ? iface_.netmask : 0xFFFFFF00U;
    out.ip = free_address(out.netmask);
    out.check = why + "; a suggested free address of " +
                (iface_.address != 0 ? iface_.name + "'s subnet" : "192.168.0.0/24 (" + iface_.name + " has no IPv4 address)") +
                ", which the controller gives it at start";
    if (out.ip == 0) out.check = why + "; no free address left in the subnet: give it one";
    return out;
  }

 private:
  std::uint32_t free_address(std::uint32_t mask) {
    const std::uint32_t base = (iface_.address != 0 ? iface_.address : 0xC0A80000U) & mask;
    for (std::uint32_t host = 2; host < ~mask; ++host) {
      const std::uint32_t ip = base | host;
      if (used_.contains(ip) || !config::ipv4_host_problem(ip, mask).empty()) continue;
      used_.insert(ip);
      given_.insert(ip);
      return ip;
    }
    return 0;
  }

  const ScanInterface& iface_;
  std::set<std::uint32_t> used_;   // every address on the network (and the interface's)
  std::set<std::uint32_t> given_;  // the skeleton's so far
};

std::string devices_item(const std::string& station, const SkeletonSuite& suite, const DcpStation& s) {
  std::string item = "{ station: " + station + ", ip: " + config::ipv4_text(suite.ip) +
                     ", netmask: " + config::ipv4_text(suite.netmask);
  if (suite.gateway != 0) item += ", gateway: " + config::ipv4_text(suite.gateway);
  if (s.has_device_id) item += ", vendor_id: " + hex4(s.vendor_id) + ", device_id: " + hex4(s.device_id);
  item += " }";
  if (!suite.check.empty()) item += "    # CHECK: " + suite.check;
  return item;
}

const config::DeviceProfile* match(const DcpStation& s, const std::vector<config::DeviceProfile>& profiles,
                                   std::string& reason) {
  if (!s.has_device_id) {
    reason = "its answer has no DeviceID block: no profile can be chosen";
    return nullptr;
  }
  const std::string id = "vendor " + hex4(s.vendor_id) + " device " + hex4(s.device_id);
  for (const auto& p : profiles) {
    const auto& spec = p.section<config::ProfidriveDeviceSpec>();
    if (spec.vendor_id == s.vendor_id && spec.device_id == s.device_id) {
      reason = id + " is its profidrive identity";
      return &p;
    }
  }
  reason = id + " matches no device profile (profidrive: vendor_id, device_id)";
  return nullptr;
}

}  // namespace

std::vector<config::DeviceProfile> profinet_scan_profiles(const std::vector<std::filesystem::path>& dirs,
                                                          const config::BusTypeRegistry& types,
                                                          std::vector<std::string>& notes) {
  return config::scan_device_profiles(
      dirs, types, [](const config::DeviceProfile& p) { return p.has_section<config::ProfidriveDeviceSpec>(); }, notes);
}

std::uint16_t skeleton_telegram(const config::DeviceProfile& profile) {
  std::uint16_t best = 0;
  int best_score = -1;
  for (const std::uint16_t t : profile.section<config::ProfidriveDeviceSpec>().telegrams) {
    // Telegram 0 the configuration refuses; 400's layout is read from the drive (few modes known).
    const auto layout = profidrive::standard_layout(t);
    if (t == 0 || !layout) continue;
    const profidrive::TelegramCapabilities c = profidrive::capabilities_of(*layout);
    // As config/profinet/axis_section.cpp: the modes a telegram carries.
    int modes = 0;
    modes += (c.speed || c.mdi) && profile.modes.contains(core::Mode::ProfileVelocity) ? 1 : 0;
    modes += c.mdi && profile.modes.contains(core::Mode::ProfilePosition) ? 1 : 0;
    modes += c.position && profile.modes.contains(core::Mode::Homing) ? 1 : 0;
    modes += c.position && profile.modes.contains(core::Mode::TraversingBlock) ? 1 : 0;
    const int score = modes * 4 + (c.home_dist ? 2 : 0) + (c.home_mode ? 0 : 1);
    if (score > best_score) {  // ties: the first, the lowest number in the profile's order
      best = t;
      best_score = score;
    }
  }
  return best;
}

core::ScanResult profinet_scan_result(std::span<const DcpStation> stations, const ScanInterface& iface,
                                      const std::vector<config::DeviceProfile>& profiles) {
  core::ScanResult r;
  r.bus_type = "profinet";
  r.bus_name = config::is_valid_name(iface.name) ? iface.name : "pn0";
  r.description = "on " + iface.name;
  r.cycle_times = {kSkeletonSendClock};

  // Named stations first, by name, then by MAC.
  std::vector<const DcpStation*> order;
  for (const auto& s : stations) order.push_back(&s);
  std::sort(order.begin(), order.end(), [](const DcpStation* a, const DcpStation* b) {
    const bool an = a->has_name && a->name_length > 0, bn = b->has_name && b->name_length > 0;
    if (an != bn) return an;
    if (a->name() != b->name()) return a->name() < b->name();
    return a->mac < b->mac;
  });
  std::map<std::string, std::vector<std::string>> macs_of;  // station name -> the MACs answering with it
  for (const auto* s : order)
    if (s->has_name && s->name_length > 0) macs_of[std::string(s->name())].push_back(mac_words(s->mac));

  AddressPlanner addresses(iface, stations);
  std::vector<std::string> devices, io;
  core::Duration update{};
  std::string slowest;
  for (const auto* sp : order) {
    const DcpStation& s = *sp;
    core::FoundDevice d;
    d.address.number = static_cast<int>(r.devices.size()) + 1;
    const std::string station = s.has_name && s.name_length > 0 ? std::string(s.name()) : "(no name)";
    const bool has_ip = s.has_ip && ipv4_host(s.ip.address) != 0;
    d.address.text = station + " " + (has_ip ? config::ipv4_text(ipv4_host(s.ip.address)) : std::string("(no IP)")) + " " +
                     mac_words(s.mac);
    d.device_type_text = role_words(s);
    if (s.has_device_id) {
      d.identity.vendor_id = s.vendor_id;
      d.identity.product_code = s.device_id;
    }
    if (s.has_type_of_station)
      d.name = std::string(s.type_of_station()) + (s.type_truncated ? "..." : "");
    d.notes.push_back("MAC " + mac_words(s.mac) + ", role " + role_words(s));
    d.notes.push_back(s.has_ip ? "IP " + suite_words(s) + " (" + ip_block_words(s.ip_block_info) + ")"
                               : std::string("no IP parameter in its answer"));
    const config::DeviceProfile* p = match(s, profiles, d.profile_reason);
    if (p != nullptr) d.profile = p->name;

    const std::string unnamed = name_problem(s);
    const auto& twins = macs_of[station];
    if (!unnamed.empty()) {
      d.next_step = unnamed + ": no configuration can address it; give it a NameOfStation (DCP Set, e.g. from the "
                              "vendor's tool) and scan again";
      r.warnings.push_back(mac_words(s.mac) + ": " + unnamed + "; it needs a name before use");
    } else if (twins.size() > 1) {
      d.conflict = "station \"" + station + "\" is answered by " + std::to_string(twins.size()) + " devices (" +
                   config::join(twins) + ")";
      d.profile.clear();
      d.profile_reason = "its name is not its own (more than one device answers with it): no profile chosen";
      d.next_step = "give each of them a NameOfStation of its own and scan again";
      if (twins.front() == mac_words(s.mac)) r.warnings.push_back(d.conflict + "; each needs a name of its own");
    }
    const bool addressable = unnamed.empty() && d.conflict.empty();
    if (addressable) {
      const SkeletonSuite suite = addresses.plan(s);
      devices.push_back(devices_item(station, suite, s));
      if (!suite.check.empty()) d.notes.push_back("skeleton: " + suite.check);
    }
    if (addressable && p != nullptr) {
      if (const std::uint16_t t = skeleton_telegram(*p); t != 0) {
        d.drive = true;
        d.axis_keys.push_back("profinet: { station: " + station + ", telegram: " + std::to_string(t) + " }");
        const core::Duration need = p->section<config::ProfidriveDeviceSpec>().min_update_time;
        if (need > update) {
          update = need;
          slowest = p->name;
        }
      } else {
        d.next_step = "its profile offers no telegram a configuration can use";
      }
    } else if (addressable) {
      d.next_step = "not a known drive: as an IO device its bytes go on the I/O topic once its slots are given "
                    "(an `io:` entry with slots, or a gsdml: file, config/README.md \"PROFINET buses\")";
      std::string item = "# - { name: io-" + std::to_string(d.address.number) + ", station: " + station +
                         ", gsdml: FILE }    # CHECK: give its slots (slot, module_ident, submodule_ident, inputs, "
                         "outputs) or the vendor's GSDML file";
      io.push_back(std::move(item));
    }
    r.devices.push_back(std::move(d));
  }

  r.bus_options.emplace_back("interface", iface.name);
  int ratio = kDefaultReductionRatio;
  if (update > core::Duration::zero()) {
    ratio = 1;
    while (ratio < kMaxReductionRatio && kSkeletonSendClock * ratio < update) ratio *= 2;
    r.bus_option_checks.emplace_back(
        "reduction_ratio", "update time " + config::format_duration(kSkeletonSendClock * ratio) + " = cycle_time x this; " +
                               slowest + " needs at least " + config::format_duration(update));
  }
  r.bus_options.emplace_back("reduction_ratio", std::to_string(ratio));
  r.bus_lists.emplace_back("devices", std::move(devices));
  if (!io.empty()) r.bus_lists.emplace_back("io", std::move(io));
  return r;
}

// --- the request ---------------------------------------------------------------------------------

config::BusPlan profinet_scan_plan(const core::ScanRequest& request, const config::BusTypeRegistry& types) {
  const std::string& where = request.where;
  const std::string interface = where.substr(0, where.find('?'));
  if (interface.empty()) throw core::ScanError("name the Ethernet interface the PROFINET network is on: profinet:eth1");
  if (!config::scan_plain_value(interface))
    throw core::ScanError("\"" + interface + "\": an interface name is letters, digits, '.', '_', '-' and '@'");
  for (const auto& [key, value] : config::scan_where_options(where)) {
    if (key != "response_delay")
      throw core::ScanError("\"" + key + "\" is not a scan option of profinet; it takes response_delay");
    const auto v = config::parse_integer(value);
    // ResponseDelayFactor 1..1900h [IEC 61158-6-10 §4.3]; DcpClient::identify_all takes that range.
    if (!v || *v < 1 || *v > 0x1900)
      throw core::ScanError("response_delay=\"" + value +
                            "\": the DCP ResponseDelayFactor, 1..6400 (the answers spread over N x 10 ms)");
  }
  (void)profinet_scan_actions(request);
  std::ostringstream y;
  y << "gateway: { name: scan }\nbuses:\n  - name: scan\n    type: profinet\n    cycle_time: 1ms\n"
    << "    options:\n      interface: " << interface << "\naxes: []\n";
  return config::scan_bus_plan(y.str(), request, types);
}

std::uint16_t profinet_scan_response_delay(const core::ScanRequest& request) {
  for (const auto& [key, value] : config::scan_where_options(request.where))
    if (key == "response_delay")
      if (const auto v = config::parse_integer(value); v && *v >= 1 && *v <= 0x1900) return static_cast<std::uint16_t>(*v);
  return kScanResponseDelayFactor;
}

// --- the write actions ----------------------------------------------------------------------------

namespace {

MacAddress action_mac(const std::string& text, std::string_view value) {
  const auto mac = parse_mac(value);
  if (!mac)
    throw core::ScanUsageError(text + ": " + config::in_quotes(value) +
                               " is no MAC address (six hex octets such as 00:1b:1b:00:0a:04)");
  if (((*mac)[0] & 0x01) != 0)  // the I/G bit [IEEE 802]: a group address is no device's
    throw core::ScanUsageError(text + ": " + mac_words(*mac) + " is a multicast address, not a device's");
  return *mac;
}

void check_name(const std::string& text, std::string_view name) {
  if (const NameError e = validate_name_of_station(name); e != NameError::None)
    throw core::ScanUsageError(text + ": " + config::in_quotes(name) + " is no NameOfStation: " +
                               std::string(to_string(e)));
}

// "A.B.C.D/MASK[/GATEWAY]", MASK dotted or a prefix length.
IpSuite action_suite(const std::string& text, std::string_view value) {
  const auto usage = [&] {
    return core::ScanUsageError(text + ": expected MAC=A.B.C.D/MASK[/GATEWAY] (MASK dotted or a prefix length), "
                                       "e.g. 00:1b:1b:00:0a:04=192.168.0.14/24");
  };
  std::vector<std::string_view> parts;
  for (std::size_t from = 0;;) {
    const std::size_t slash = value.find('/', from);
    parts.push_back(value.substr(from, slash - from));
    if (slash == std::string_view::npos) break;
    from = slash + 1;
  }
  if (parts.size() < 2 || parts.size() > 3) throw usage();
  IpSuite ip;
  const auto address = config::parse_ipv4_host(parts[0]);
  if (!address) throw usage();
  ip.address = ipv4_octets(*address);
  if (const auto mask = config::parse_ipv4_host(parts[1])) {
    ip.netmask = ipv4_octets(*mask);
  } else if (const auto prefix = config::parse_integer(parts[1]); prefix && *prefix >= 0 && *prefix <= 32) {
    ip.netmask = ipv4_octets(*prefix == 0 ? 0U : ~std::uint32_t{0} << static_cast<int>(32 - *prefix));
  } else {
    throw usage();
  }
  if (parts.size() == 3) {
    const auto gateway = config::parse_ipv4_host(parts[2]);
    if (!gateway) throw usage();
    ip.gateway = ipv4_octets(*gateway);
  }
  if (ipv4_host(ip.address) == 0) throw core::ScanUsageError(text + ": 0.0.0.0 is no address to give a device");
  if (const std::string_view problem = ip_suite_problem(ip); !problem.empty())
    throw core::ScanUsageError(text + ": the IP suite is not usable: " + std::string(problem));
  return ip;
}

// "MAC=VALUE" of --set-name and --set-ip: the MAC, and VALUE.
std::pair<MacAddress, std::string_view> mac_and_value(const std::string& text, std::string_view value,
                                                      const char* example) {
  const std::size_t eq = value.find('=');
  if (eq == std::string_view::npos) throw core::ScanUsageError(text + ": expected " + example);
  return {action_mac(text, value.substr(0, eq)), value.substr(eq + 1)};
}

}  // namespace

std::vector<DcpAction> profinet_scan_actions(const core::ScanRequest& request) {
  std::vector<DcpAction> out;
  bool sets = false;
  for (const auto& [option, value] : request.actions) {
    DcpAction a;
    a.text = option + " " + config::clipped(value);
    if (option == "--set-name") {
      const auto [mac, name] = mac_and_value(a.text, value, "MAC=NAME, e.g. 00:1b:1b:00:0a:04=drive-d");
      check_name(a.text, name);
      a.mac = mac;
      a.name = name;
      for (const auto& b : out) {
        if (b.kind != DcpAction::Kind::SetName) continue;
        if (b.mac == a.mac) throw core::ScanUsageError(a.text + ": " + mac_words(a.mac) + " is given a name twice");
        if (b.name == a.name)
          throw core::ScanUsageError(a.text + ": \"" + a.name + "\" is given to " + mac_words(b.mac) + " too");
      }
    } else if (option == "--set-ip") {
      a.kind = DcpAction::Kind::SetIp;
      const auto [mac, suite] =
          mac_and_value(a.text, value, "MAC=A.B.C.D/MASK[/GATEWAY], e.g. 00:1b:1b:00:0a:04=192.168.0.14/24");
      a.mac = mac;
      a.ip = action_suite(a.text, suite);
      for (const auto& b : out) {
        if (b.kind != DcpAction::Kind::SetIp) continue;
        if (b.mac == a.mac)
          throw core::ScanUsageError(a.text + ": " + mac_words(a.mac) + " is given an IP suite twice");
        if (b.ip.address == a.ip.address)
          throw core::ScanUsageError(a.text + ": " + config::ipv4_text(ipv4_host(a.ip.address)) + " is given to " +
                                     mac_words(b.mac) + " too");
      }
    } else if (option == "--signal") {
      a.kind = DcpAction::Kind::Signal;
      if (parse_mac(value)) {
        a.mac = action_mac(a.text, value);
      } else if (validate_name_of_station(value) == NameError::None) {
        a.by_name = true;
        a.name = value;
      } else {
        throw core::ScanUsageError(a.text + ": " + config::in_quotes(value) +
                                   " is neither a MAC address (00:1b:1b:00:0a:04) nor a NameOfStation");
      }
    } else {
      throw core::ScanUsageError(option + " is not a profinet scan action (--set-name, --set-ip, --signal)");
    }
    sets = sets || a.kind != DcpAction::Kind::Signal;
    out.push_back(std::move(a));
  }
  if (request.permanent && !sets)
    throw core::ScanUsageError("--permanent goes with --set-name or --set-ip (it makes the values they set survive a "
                               "power loss)");
  return out;
}

namespace {

// A DcpClient on the open link in real time.
class DcpSession {
 public:
  DcpSession(link::RawSocketLink& link, const MacAddress& own, std::string interface)
      : link_(link), client_(own), interface_(std::move(interface)) {}

  DcpClient& client() noexcept { return client_; }

  // Runs the request to its end (Done or Failed) and returns its result.
  DcpResult run(DcpRequestId id) {
    if (id == kNoDcpRequest) throw core::ScanError("the DCP client refused the request");
    for (;;) {
      const core::TimePoint now = clock_.now();
      while (const std::size_t n = client_.poll(now, out_))
        if (link_.send(std::span<const std::uint8_t>(out_).first(n)).status != link::SendStatus::Sent)
          throw core::ScanError("cannot send a DCP request on " + interface_ +
                                ": the link is down or its transmit queue full");
      while (const std::size_t n = link_.receive(in_))
        for (std::size_t i = 0; i < n; ++i) (void)client_.on_frame(in_[i].view(), now);
      const DcpRequestStatus status = client_.result(id).status;
      if (status == DcpRequestStatus::Done || status == DcpRequestStatus::Failed) return client_.result(id);
      // Until the window closes, a Set times out or a frame arrives, at most 100 ms at a time.
      const core::TimePoint deadline = client_.next_deadline();
      const core::TimePoint after = clock_.now();
      const int ms = deadline <= after ? 0
                     : deadline - after >= 100ms
                         ? 100
                         : static_cast<int>(std::chrono::ceil<std::chrono::milliseconds>(deadline - after).count());
      pollfd p{link_.wait_fd(), POLLIN, 0};
      (void)::poll(&p, 1, ms);
    }
  }

 private:
  link::RawSocketLink& link_;
  DcpClient client_;
  std::string interface_;
  const core::SteadyClock clock_;
  std::array<std::uint8_t, kMaxFrameSize> out_{};
  std::vector<link::FrameBuffer> in_ = std::vector<link::FrameBuffer>(16);
};

std::string set_failure(const DcpResult& r) {
  std::string words(to_string(r.failure));
  if (r.failure == DcpFailure::BlockError) words += ": " + std::string(to_string(r.block_error));
  if (r.block_error == DcpBlockError::InOperation) words += " (a controller is connected to it: stop that first)";
  return words;
}

std::string station_words(const DcpStation& s) {
  return mac_words(s.mac) + (s.has_name && s.name_length > 0 ? " (\"" + std::string(s.name()) + "\")" : "");
}

// Runs the actions in order against the devices that answer an Identify all first: a line per
// action done into r.actions_done, the first failure into r.action_failed (the rest not run).
void run_actions(DcpSession& dcp, std::span<const DcpAction> actions, const core::ScanRequest& request,
                 const std::string& interface, core::ScanResult& r) {
  std::vector<DcpStation> found(kMaxScanStations);
  const DcpResult identified = dcp.run(dcp.client().identify_all(found, profinet_scan_response_delay(request)));
  if (identified.status != DcpRequestStatus::Done) {
    r.action_failed = "the DCP Identify before the actions failed: " + std::string(to_string(identified.failure));
    return;
  }
  found.resize(identified.stations);
  const DcpQualifier qualifier = request.permanent ? DcpQualifier::Permanent : DcpQualifier::Temporary;
  // What the Set's BlockQualifier means for the device; `then`: what follows from temporary.
  const auto kept = [&](std::string_view then) {
    return request.permanent ? std::string("permanent (kept over a power loss)")
                             : "temporary (forgotten at a power loss; " + std::string(then) + ")";
  };
  for (const DcpAction& a : actions) {
    const auto fail = [&](const std::string& why) { r.action_failed = a.text + ": " + why; };
    std::vector<DcpStation*> targets;
    for (auto& s : found)
      if (a.by_name ? s.has_name && s.name() == a.name : s.mac == a.mac) targets.push_back(&s);
    if (targets.empty()) {
      fail((a.by_name ? "no device answers with the name \"" + a.name + "\""
                      : "no device answers at " + mac_words(a.mac)) +
           " (DCP Identify all on " + interface + "); nothing sent");
      return;
    }
    if (targets.size() > 1) {
      std::vector<std::string> macs;
      for (const auto* s : targets) macs.push_back(mac_words(s->mac));
      fail(std::to_string(targets.size()) + " devices answer with the name \"" + a.name + "\" (" + config::join(macs) +
           "); give the MAC; nothing sent");
      return;
    }
    DcpStation& s = *targets.front();
    if (a.kind == DcpAction::Kind::SetName) {
      for (const auto& other : found)
        if (other.mac != s.mac && other.has_name && other.name() == a.name) {
          fail("\"" + a.name + "\" is the name of " + mac_words(other.mac) +
               " already (two devices with one name: the controller would use neither); nothing sent");
          return;
        }
      const std::string was = s.has_name && s.name_length > 0 ? "\"" + std::string(s.name()) + "\"" : "none";
      const DcpResult done = dcp.run(dcp.client().set_name(s.mac, a.name, qualifier));
      if (done.status != DcpRequestStatus::Done) return fail(set_failure(done));
      s.has_name = true;
      s.name_length = static_cast<std::uint8_t>(std::min(a.name.size(), s.name_chars.size()));
      std::copy_n(a.name.begin(), s.name_length, s.name_chars.begin());
      r.actions_done.push_back(mac_words(s.mac) + ": NameOfStation set to \"" + a.name + "\" (was " + was + "), " +
                               kept("the controller finds its stations by name: --permanent keeps it"));
    } else if (a.kind == DcpAction::Kind::SetIp) {
      const std::string was = s.has_ip && ipv4_host(s.ip.address) != 0 ? suite_words(s) : "none";
      const DcpResult done = dcp.run(dcp.client().set_ip(s.mac, a.ip, qualifier));
      if (done.status != DcpRequestStatus::Done) return fail(set_failure(done));
      s.has_ip = true;
      s.ip = a.ip;
      r.actions_done.push_back(station_words(s) + ": IP suite set to " + suite_words(s) + " (was " + was + "), " +
                               kept("the controller gives a station its configured address at start"));
    } else {
      const DcpResult done = dcp.run(dcp.client().signal(s.mac));
      if (done.status != DcpRequestStatus::Done) return fail(set_failure(done));
      r.actions_done.push_back(station_words(s) + ": Signal sent, its LED flashes");
    }
  }
}

}  // namespace

core::ScanResult run_profinet_scan(const config::BusPlan& plan, const core::ScanRequest& request,
                                   const config::BusTypeRegistry& types) {
  std::vector<std::string> profile_notes;
  const auto profiles = profinet_scan_profiles(request.device_dirs, types, profile_notes);
  const auto& o = plan.section<config::ProfinetBusOptions>();
  link::RawSocketOptions ro;
  ro.interface = o.interface;
  link::RawSocketLink link(kFrameRules, std::move(ro));
  try {
    link.open();
  } catch (const link::LinkError& e) {
    throw core::ScanError(std::string("cannot open the network: ") + e.what());
  }
  const link::InterfaceAddresses a = link::interface_addresses(o.interface);
  if (!a.has_mac) throw core::ScanError("profinet: interface '" + o.interface + "' has no Ethernet address");
  ScanInterface iface{o.interface, 0, 0};
  if (!a.ipv4.empty()) {
    iface.address = a.ipv4.front().address;
    iface.netmask = a.ipv4.front().netmask;
  }
  MacAddress own{};
  std::copy(a.mac.begin(), a.mac.end(), own.begin());

  const std::uint16_t factor = profinet_scan_response_delay(request);
  DcpSession dcp(link, own, o.interface);
  core::ScanResult before;
  if (const auto actions = profinet_scan_actions(request); !actions.empty())
    run_actions(dcp, actions, request, o.interface, before);
  std::vector<DcpStation> found(kMaxScanStations);
  const core::SteadyClock clock;
  const core::TimePoint start = clock.now();
  const DcpRequestId id = dcp.client().identify_all(found, factor);
  const DcpResult result = dcp.run(id);
  if (result.status != DcpRequestStatus::Done)
    throw core::ScanError("the DCP Identify failed: " + std::string(to_string(result.failure)));
  core::ScanResult r = profinet_scan_result(dcp.client().stations(id), iface, profiles);
  r.actions_done = std::move(before.actions_done);
  r.action_failed = std::move(before.action_failed);
  r.description = link.describe() + ", " + mac_words(own) +
                  (iface.address != 0 ? " " + config::ipv4_text(iface.address) + "/" +
                                            std::to_string(std::popcount(iface.netmask))
                                      : std::string(" (no IPv4 address)"));
  r.assumed = "DCP Identify all, ResponseDelayFactor " + std::to_string(factor) + " (answers within " +
              config::format_duration(identify_window(factor)) + ")";
  r.elapsed = clock.now() - start;
  const DcpClientCounters& c = dcp.client().counters();
  if (result.stations_lost > 0)
    r.notes.push_back(std::to_string(result.stations_lost) + " more devices answered than the scan keeps (" +
                      std::to_string(kMaxScanStations) + ")");
  if (c.duplicate_answers > 0)
    r.notes.push_back(std::to_string(c.duplicate_answers) + " second answers from a MAC already listed, dropped");
  if (c.malformed > 0) r.notes.push_back(std::to_string(c.malformed) + " DCP frames that do not decode, dropped");
  if (c.foreign_xid + c.unsolicited + c.not_for_us > 0)
    r.notes.push_back(std::to_string(c.foreign_xid + c.unsolicited + c.not_for_us) +
                      " DCP answers to another request or controller, dropped");
  if (c.requests_seen > 0)
    r.notes.push_back(std::to_string(c.requests_seen) + " DCP requests or Hellos of other stations seen");
  const link::LinkCounters lc = link.counters();
  if (lc.rx_overflow > 0)
    r.notes.push_back(std::to_string(lc.rx_overflow) + " frames dropped by the kernel (receive queue full)");
  r.notes.insert(r.notes.end(), profile_notes.begin(), profile_notes.end());
  link.close();
  return r;
}

}  // namespace drivegate::profinet
