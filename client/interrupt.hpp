#pragma once
// Ctrl-C / SIGTERM handling for the command-line tools: the handler only sets a flag; loops poll it
// and then leave the axes in a safe state (stop, disable) before exiting.
namespace drivegate::client {

void install_interrupt_handler();
[[nodiscard]] bool interrupted() noexcept;

}  // namespace drivegate::client
