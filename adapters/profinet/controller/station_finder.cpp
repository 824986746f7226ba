#include "adapters/profinet/controller/station_finder.hpp"

#include <cstdio>
#include <utility>

namespace drivegate::profinet {

namespace {

std::string address_text(const std::array<std::uint8_t, 4>& a) {
  return std::to_string(a[0]) + "." + std::to_string(a[1]) + "." + std::to_string(a[2]) + "." + std::to_string(a[3]);
}

std::string suite_text(const IpSuite& ip) {
  if (ip == IpSuite{}) return "no IP address";
  std::string t = address_text(ip.address) + "/" + address_text(ip.netmask);
  const bool gateway = ip.gateway != std::array<std::uint8_t, 4>{} && ip.gateway != ip.address;
  return t + (gateway ? " gateway " + address_text(ip.gateway) : " no gateway");
}

std::string hex4(std::uint16_t v) {
  std::array<char, 8> b{};
  std::snprintf(b.data(), b.size(), "0x%04x", v);
  return b.data();
}

std::string ids_text(std::uint16_t vendor, std::uint16_t device) {
  return "vendor " + hex4(vendor) + " device " + hex4(device);
}

std::string mac_string(const MacAddress& mac) { return mac_text(mac).data(); }

}  // namespace

std::string_view to_string(StationOutcome o) noexcept {
  switch (o) {
    case StationOutcome::Pending: return "pending";
    case StationOutcome::Ready: return "ready";
    case StationOutcome::IpAssigned: return "IP assigned";
    case StationOutcome::Missing: return "missing";
    case StationOutcome::Duplicate: return "duplicate name";
    case StationOutcome::WrongDevice: return "wrong device";
    case StationOutcome::IpSetFailed: return "IP assignment failed";
    case StationOutcome::InvalidConfig: return "invalid configuration";
  }
  return "?";
}

StationFinder::StationFinder(DcpClient& client, std::vector<StationConfig> stations, StationFinderOptions options)
    : client_(client), stations_(std::move(stations)), options_(options), reports_(stations_.size()) {
  for (std::size_t i = 0; i < stations_.size(); ++i) reports_[i].name = stations_[i].name;
}

bool StationFinder::all_ok() const noexcept {
  for (const StationReport& r : reports_) {
    if (!r.ok()) return false;
  }
  return true;
}

void StationFinder::conclude(std::size_t index, StationOutcome outcome, std::string text) {
  reports_[index].outcome = outcome;
  reports_[index].text = "station \"" + stations_[index].name + "\": " + std::move(text);
}

bool StationFinder::start(std::size_t i) {
  const StationConfig& c = stations_[i];
  if (const NameError e = validate_name_of_station(c.name); e != NameError::None) {
    conclude(i, StationOutcome::InvalidConfig, "the name is not a valid NameOfStation: " + std::string(to_string(e)));
    return true;
  }
  if (c.ip == IpSuite{}) {
    conclude(i, StationOutcome::InvalidConfig, "no IP address configured");
    return true;
  }
  if (const std::string_view p = ip_suite_problem(c.ip); !p.empty()) {
    conclude(i, StationOutcome::InvalidConfig, "the configured IP suite " + suite_text(c.ip) + " is unusable: " + std::string(p));
    return true;
  }
  for (std::size_t j = 0; j < i; ++j) {
    if (stations_[j].name == c.name) {
      conclude(i, StationOutcome::InvalidConfig, "the name is configured twice (station " + std::to_string(j + 1) + ")");
      return true;
    }
    if (stations_[j].ip.address == c.ip.address) {
      conclude(i, StationOutcome::InvalidConfig, "the address " + address_text(c.ip.address) +
                                                     " is also configured for \"" + stations_[j].name + "\"");
      return true;
    }
  }
  request_ = client_.identify_name(c.name, answers_, options_.response_delay_factor);
  if (request_ == kNoDcpRequest) return false;  // the client's queue is full: again at the next poll
  current_ = i;
  setting_ip_ = false;
  return true;
}

void StationFinder::identified(std::size_t i, const DcpResult& r) {
  const StationConfig& c = stations_[i];
  StationReport& rep = reports_[i];
  if (r.status == DcpRequestStatus::Failed) {  // never sent: nobody could answer
    conclude(i, StationOutcome::Missing, "DCP Identify failed: " + std::string(to_string(r.failure)));
    return;
  }
  const std::size_t answered = r.stations + r.stations_lost;
  if (answered == 0) {
    conclude(i, StationOutcome::Missing, "no device answers to this name (DCP Identify)");
    return;
  }
  if (answered > 1) {
    std::string macs;
    for (std::size_t k = 0; k < r.stations; ++k) {
      rep.macs.push_back(answers_[k].mac);
      macs += (k == 0 ? "" : ", ") + mac_string(answers_[k].mac);
    }
    if (r.stations_lost > 0) macs += " and " + std::to_string(r.stations_lost) + " more";
    conclude(i, StationOutcome::Duplicate, std::to_string(answered) + " devices answer to this name (" + macs +
                                               "); none is used until only one has it");
    return;
  }
  const DcpStation& found = answers_[0];
  rep.mac = found.mac;
  rep.ip = found.ip;
  rep.has_device_id = found.has_device_id;
  rep.vendor_id = found.vendor_id;
  rep.device_id = found.device_id;
  const std::string who = mac_string(found.mac);
  const bool check_ids = c.vendor_id.has_value() || c.device_id.has_value();
  if (check_ids) {
    const bool vendor_ok = !c.vendor_id || (found.has_device_id && found.vendor_id == *c.vendor_id);
    const bool device_ok = !c.device_id || (found.has_device_id && found.device_id == *c.device_id);
    if (!vendor_ok || !device_ok) {
      const std::string expected = (c.vendor_id ? "vendor " + hex4(*c.vendor_id) : std::string()) +
                                   (c.vendor_id && c.device_id ? " " : "") +
                                   (c.device_id ? "device " + hex4(*c.device_id) : std::string());
      const std::string has = found.has_device_id ? ids_text(found.vendor_id, found.device_id) : "no DeviceID";
      conclude(i, StationOutcome::WrongDevice, who + " reports " + has + ", the config expects " + expected);
      return;
    }
  }
  if (found.has_ip && found.ip == c.ip) {
    conclude(i, StationOutcome::Ready, who + " at " + suite_text(found.ip) +
                                           (found.has_device_id ? ", " + ids_text(found.vendor_id, found.device_id) : ""));
    return;
  }
  request_ = client_.set_ip(found.mac, c.ip, options_.ip_qualifier);
  if (request_ == kNoDcpRequest) {
    conclude(i, StationOutcome::IpSetFailed, who + ": the DCP client's queue is full, IP not set");
    return;
  }
  current_ = i;
  setting_ip_ = true;
}

void StationFinder::ip_set(std::size_t i, const DcpResult& r) {
  StationReport& rep = reports_[i];
  const StationConfig& c = stations_[i];
  const std::string who = mac_string(rep.mac);
  if (r.status == DcpRequestStatus::Done) {
    rep.previous_ip = rep.ip;
    rep.ip = c.ip;
    conclude(i, StationOutcome::IpAssigned,
             who + " at " + suite_text(c.ip) + " (set " +
                 (options_.ip_qualifier == DcpQualifier::Permanent ? "permanently" : "temporarily") + ", was " +
                 suite_text(rep.previous_ip) + ")" +
                 (rep.has_device_id ? ", " + ids_text(rep.vendor_id, rep.device_id) : ""));
    return;
  }
  std::string why(to_string(r.failure));
  if (r.failure == DcpFailure::BlockError) why += ": " + std::string(to_string(r.block_error));
  if (r.failure == DcpFailure::Timeout) why += " after " + std::to_string(r.frames_sent) + " frames";
  conclude(i, StationOutcome::IpSetFailed, who + ": setting " + suite_text(c.ip) + " failed: " + why);
}

bool StationFinder::request_ended() const noexcept {
  const DcpRequestStatus s = client_.result(request_).status;
  return s != DcpRequestStatus::Queued && s != DcpRequestStatus::InFlight;
}

void StationFinder::step() {
  if (request_ != kNoDcpRequest) {
    if (!request_ended()) return;
    const DcpResult r = client_.take(request_);
    request_ = kNoDcpRequest;
    if (setting_ip_) {
      ip_set(current_, r);
    } else {
      identified(current_, r);
    }
  }
  while (request_ == kNoDcpRequest && next_ < stations_.size()) {
    if (!start(next_)) return;
    ++next_;
  }
}

std::size_t StationFinder::poll(core::TimePoint now, std::span<std::uint8_t> out) {
  for (;;) {
    step();
    const std::size_t n = client_.poll(now, out);
    if (n != 0 || request_ == kNoDcpRequest || !request_ended()) return n;
  }
}

core::TimePoint StationFinder::next_deadline() const noexcept {
  if (request_ != kNoDcpRequest && request_ended()) return core::TimePoint::min();
  // A station to start: at once, unless the client's queue is busy with the caller's requests.
  if (request_ == kNoDcpRequest && next_ < stations_.size() && client_.idle()) return core::TimePoint::min();
  return client_.next_deadline();
}

}  // namespace drivegate::profinet
