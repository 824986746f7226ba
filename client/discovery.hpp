#pragma once
// Bounded discovery waits for the command-line tools: poll the condition, never a fixed sleep.
#include <cstddef>
#include <functional>
#include <string_view>

#include "client/client.hpp"

namespace drivegate::client {

// Waits until `gateway` (or, when empty, at least one gateway) is discovered, then until the set of
// gateways stops growing for a moment, so that a listing shows every gateway that is up.
// Returns false when no (or not the named) gateway appeared within `timeout`.
bool discover_gateways(const Client& client, std::string_view gateway, Millis timeout);

// Waits until `count()` has not changed for `quiet` (bounded by `timeout`).
void wait_settled(const Client& client, const std::function<std::size_t()>& count, Millis quiet, Millis timeout);

}  // namespace drivegate::client
