#pragma once
// A device's identity as a bus names it at the end of an axis' link detail, so that clients can
// show it without a topic of its own: "<state>; I&M0 order ORDER-ID serial SERIAL hw N sw V1.2.3"
// (the PROFINET bus, from the device's I&M0 read at connect [IEC 61158-6-10 I&M0]). Order ID and
// serial number may hold blanks: the keywords delimit them. Control plane only: allocates.
#include <optional>
#include <string>
#include <string_view>

namespace drivegate::core {

struct DeviceIdentity {
  std::string order_id;
  std::string serial_number;
  std::string hardware_revision;
  std::string software_revision;
};

// nullopt when the detail names no identity (another bus, or the device not read yet).
[[nodiscard]] std::optional<DeviceIdentity> identity_in_link_detail(std::string_view detail);

}  // namespace drivegate::core
