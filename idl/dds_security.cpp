#include "idl/dds_security.hpp"

#include <array>
#include <filesystem>
#include <fstream>
#include <string_view>
#include <system_error>
#include <utility>

#include <fastdds/dds/domain/qos/DomainParticipantQos.hpp>

namespace drivegate::msg {

namespace fs = std::filesystem;

namespace {

// Field name (as in SecurityFiles, so a message points at the setting to fix) and path.
std::array<std::pair<std::string_view, const std::string*>, 6> fields_of(const SecurityFiles& f) {
  return {{{"identity_ca", &f.identity_ca},
           {"certificate", &f.certificate},
           {"private_key", &f.private_key},
           {"permissions_ca", &f.permissions_ca},
           {"governance", &f.governance},
           {"permissions", &f.permissions}}};
}

std::string problem_with(const std::string& path) {
  if (path.empty()) return "no path given";
  std::error_code ec;
  const fs::file_status st = fs::status(path, ec);  // follows symlinks: the target must be a file
  if (st.type() == fs::file_type::not_found) return "does not exist";
  if (ec) return "cannot be examined: " + ec.message();
  if (!fs::is_regular_file(st)) return "is not a regular file";
  // Opening is the only check that honours permissions, ACLs and the caller's uid as Fast DDS will
  // meet them.
  std::ifstream in(path, std::ios::binary);
  if (!in.is_open()) return "cannot be read";
  return {};
}

// Fast DDS only understands "file://" followed by the path, which it hands to the C library as is:
// no percent-decoding, so the path is not percent-encoded either. An absolute path gives the usual
// "file:///..." form.
std::string file_uri(const std::string& path) {
  std::error_code ec;
  fs::path p = fs::absolute(path, ec);
  if (ec) p = path;  // only if the current directory is gone; Fast DDS then reports the file
  return "file://" + p.lexically_normal().string();
}

void set_property(eprosima::fastdds::dds::DomainParticipantQos& qos, const std::string& name,
                  const std::string& value) {
  auto& props = qos.properties().properties();
  for (auto& p : props) {
    if (p.name() == name) {
      // Replace rather than append: Fast DDS uses the first property with a name, so an appended
      // duplicate would be ignored silently.
      p.value(value);
      return;
    }
  }
  props.emplace_back(name, value);
}

}  // namespace

SecurityFiles security_files_in(const std::string& dir) {
  const fs::path d(dir);
  return {(d / "identity_ca.pem").string(),    (d / "cert.pem").string(),
          (d / "key.pem").string(),            (d / "permissions_ca.pem").string(),
          (d / "governance.p7s").string(),     (d / "permissions.p7s").string()};
}

std::string check_security_files(const SecurityFiles& f) {
  std::string out;
  for (const auto& [field, path] : fields_of(f)) {
    const std::string problem = problem_with(*path);
    if (problem.empty()) continue;
    if (!out.empty()) out += "; ";
    out += "security file ";
    out += field;
    if (!path->empty()) out += " (" + *path + ")";
    out += ": " + problem;
  }
  return out;
}

void apply_security(eprosima::fastdds::dds::DomainParticipantQos& qos, const SecurityFiles& f) {
  // Property names of the DDS Security builtin plugins as Fast DDS 2.9 reads them.
  set_property(qos, "dds.sec.auth.plugin", "builtin.PKI-DH");
  set_property(qos, "dds.sec.auth.builtin.PKI-DH.identity_ca", file_uri(f.identity_ca));
  set_property(qos, "dds.sec.auth.builtin.PKI-DH.identity_certificate", file_uri(f.certificate));
  set_property(qos, "dds.sec.auth.builtin.PKI-DH.private_key", file_uri(f.private_key));
  set_property(qos, "dds.sec.access.plugin", "builtin.Access-Permissions");
  set_property(qos, "dds.sec.access.builtin.Access-Permissions.permissions_ca", file_uri(f.permissions_ca));
  set_property(qos, "dds.sec.access.builtin.Access-Permissions.governance", file_uri(f.governance));
  set_property(qos, "dds.sec.access.builtin.Access-Permissions.permissions", file_uri(f.permissions));
  set_property(qos, "dds.sec.crypto.plugin", "builtin.AES-GCM-GMAC");
}

}  // namespace drivegate::msg
