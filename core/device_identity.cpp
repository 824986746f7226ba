#include "core/device_identity.hpp"

namespace drivegate::core {

std::optional<DeviceIdentity> identity_in_link_detail(std::string_view detail) {
  static constexpr std::string_view kStart = "; I&M0 order ";
  const auto start = detail.find(kStart);
  if (start == std::string_view::npos) return std::nullopt;
  std::string_view rest = detail.substr(start + kStart.size());
  // Each field runs up to the next keyword; the software revision to the end.
  const auto take = [&rest](std::string_view next) -> std::optional<std::string> {
    const auto at = rest.find(next);
    if (at == std::string_view::npos) return std::nullopt;
    std::string field(rest.substr(0, at));
    rest.remove_prefix(at + next.size());
    return field;
  };
  DeviceIdentity id;
  const auto order = take(" serial ");
  const auto serial = order ? take(" hw ") : std::nullopt;
  const auto hw = serial ? take(" sw ") : std::nullopt;
  if (!hw || rest.empty()) return std::nullopt;
  id.order_id = *order;
  id.serial_number = *serial;
  id.hardware_revision = *hw;
  id.software_revision = std::string(rest);
  return id;
}

}  // namespace drivegate::core
