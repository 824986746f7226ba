#pragma once
// How the PROFIdrive master reaches the cyclic telegram of its axis, whatever the bus underneath
// (DESIGN.md §2 rule 3). The PROFINET adapter implements it over the IO data of the telegram
// submodule in slot 1 [akd-profinet-profidrive.md §4.1]; tests implement it with plain buffers.
// Called only from the bus' cycle thread; nothing here may allocate or block.
#include <cstdint>
#include <span>
#include <string_view>

namespace drivegate::profidrive {

class TelegramPort {
 public:
  // The actual-value image (drive -> controller) as last received, exactly the telegram's size, or
  // an empty span while there is none that may be used: no data exchange, the provider reports
  // the data invalid or STOP, or the data-hold time ran out.
  [[nodiscard]] virtual std::span<const std::uint8_t> actual() const noexcept = 0;
  // True when actual() was refreshed by the drive since the previous cycle.
  [[nodiscard]] virtual bool actual_fresh() const noexcept = 0;
  // The setpoint image (controller -> drive) the bus sends next, exactly the telegram's size. The
  // master rewrites all of it every cycle.
  [[nodiscard]] virtual std::span<std::uint8_t> setpoint() noexcept = 0;
  // The drive does not follow the STW1 the master sends (it stays in more power than STW1 allows):
  // the bus takes over, stops it over the acyclic channel and reconfigures it, so the axis comes
  // back disabled (DESIGN.md §4). Called once per loss.
  virtual void control_lost(std::string_view /*why*/) noexcept {}

 protected:
  ~TelegramPort() = default;
};

}  // namespace drivegate::profidrive
