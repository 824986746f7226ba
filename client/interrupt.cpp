#include "client/interrupt.hpp"

#include <csignal>

namespace drivegate::client {

namespace {
volatile std::sig_atomic_t g_interrupted = 0;
extern "C" void on_signal(int /*signal*/) { g_interrupted = 1; }
}  // namespace

void install_interrupt_handler() {
  struct sigaction sa {};
  sa.sa_handler = on_signal;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
}

bool interrupted() noexcept { return g_interrupted != 0; }

}  // namespace drivegate::client
