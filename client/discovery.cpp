#include "client/discovery.hpp"

#include <algorithm>
#include <chrono>

#include "client/settled.hpp"

namespace drivegate::client {

bool discover_gateways(const Client& client, std::string_view gateway, Millis timeout) {
  const auto start = std::chrono::steady_clock::now();
  const bool found = client.wait_until(
      [&] {
        const auto gws = client.gateways();
        if (gateway.empty()) return !gws.empty();
        return std::any_of(gws.begin(), gws.end(), [&](const GatewayInfo& g) { return g.name == gateway; });
      },
      timeout);
  if (!found) return false;
  const auto spent = std::chrono::duration_cast<Millis>(std::chrono::steady_clock::now() - start);
  // Gateways on the same domain show up within a few hundred ms of each other.
  wait_settled(client, [&] { return client.gateways().size(); }, Millis(400),
               std::clamp(timeout - spent, Millis(0), Millis(1500)));
  return true;
}

void wait_settled(const Client& client, const std::function<std::size_t()>& count, Millis quiet, Millis timeout) {
  Settled settled(quiet);
  client.wait_until([&] { return settled(count()); }, timeout);
}

}  // namespace drivegate::client
