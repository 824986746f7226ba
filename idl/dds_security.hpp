#pragma once
// DDS Security for drivegate participants: the six files of one identity (made by
// scripts/make-pki.sh) and the Fast DDS builtin plugins that use them (PKI-DH authentication,
// Access-Permissions access control, AES-GCM-GMAC cryptography). Kept apart from DdsNode so the
// daemon and the client can check the files and report a missing one by name before Fast DDS
// fails participant creation with a less specific log line.
#include <string>

namespace eprosima::fastdds::dds {
class DomainParticipantQos;
}  // namespace eprosima::fastdds::dds

namespace drivegate::msg {

// Paths of one participant's security files.
struct SecurityFiles {
  std::string identity_ca;     // CA that signs every participant's identity certificate (PEM)
  std::string certificate;     // this participant's identity certificate (PEM)
  std::string private_key;     // its private key (PEM, unencrypted: keep it mode 0600)
  std::string permissions_ca;  // CA that signs governance and permissions (PEM)
  std::string governance;      // signed governance document (S/MIME, .p7s)
  std::string permissions;     // signed permissions document with this participant's grant (.p7s)
};

// The layout scripts/make-pki.sh writes: dir/identity_ca.pem, cert.pem, key.pem,
// permissions_ca.pem, governance.p7s, permissions.p7s.
SecurityFiles security_files_in(const std::string& dir);

// "" when every file exists and is a readable regular file; otherwise one message that names each
// offending field and path, e.g. "security file private_key (/etc/x/key.pem): cannot be read".
std::string check_security_files(const SecurityFiles& f);

// Turns the builtin security plugins on in `qos`, pointing them at `f` as file: URIs with absolute
// paths (relative paths are resolved against the current directory now, because Fast DDS reads the
// files when the participant is created, possibly after a chdir). Setting a property that is
// already in `qos` replaces its value. Does not check the files; call check_security_files first.
void apply_security(eprosima::fastdds::dds::DomainParticipantQos& qos, const SecurityFiles& f);

}  // namespace drivegate::msg
