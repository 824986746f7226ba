// drivegated: loads a deployment, brings its buses and axes up, and serves them over DDS.
#include <signal.h>
#include <string.h>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>
#include <sys/signalfd.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <optional>
#include <string>
#include <thread>

#include "config/config_error.hpp"
#include "config/describe.hpp"
#include "config/loader.hpp"
#include "config/scalars.hpp"
#include "core/bus.hpp"
#include "daemon/dds_bridge.hpp"
#include "daemon/gateway.hpp"
#include "daemon/realtime.hpp"
#include "daemon/scan.hpp"
#include "daemon/systemd_notify.hpp"

#ifndef DRIVEGATE_VERSION
#define DRIVEGATE_VERSION "unknown"
#endif

namespace {

using namespace drivegate;
using namespace std::chrono_literals;

// A second stop signal within this time after the first is taken as a duplicate, not as "exit now".
constexpr std::chrono::milliseconds kSecondSignalGrace{2000};

constexpr const char* kUsage = R"(usage: drivegated --config FILE [--log-level LEVEL]
       drivegated --check-config FILE
       drivegated --scan TYPE:WHERE [--scan-timeout D] [--device-dir DIR]... [--write-config FILE [--force]]
       drivegated --scan profinet:IFACE [--set-name MAC=NAME]... [--set-ip MAC=A.B.C.D/MASK[/GATEWAY]]...
                  [--permanent] [--signal MAC|NAME]... [--write-config FILE [--force]]
       drivegated --version | --help

Runs the gateway described by FILE: brings up every bus and axis, runs one cycle thread per bus
and serves the axes over DDS. SIGTERM, SIGINT and every other signal that would end the process
stop and disable every axis, then exit 0; a second such signal at least 2 s after the first, or
SIGQUIT, exits at once. SIGHUP re-reads and checks FILE and logs what a restart would change;
SIGPIPE, SIGTSTP, SIGTTIN and SIGTTOU are ignored.

  --config FILE        the deployment (YAML); see config/README.md
  --check-config FILE  validate FILE and print the compiled plan without touching any bus
  --log-level LEVEL    trace|debug|info|warn|error|critical|off (overrides gateway.log_level)

  --scan TYPE:WHERE    list the devices on a bus and the device profile that fits each; only reads,
                       but for the profinet actions below.
                       canopen:can0 (SocketCAN interface), or canopen:udp-multicast?group=G&port=P&interface=A
                       (quote it in a shell); options: interface, bitrate, group, port
                       ethercat:eth1 (the line on an Ethernet port); options: sdo_timeout, transition_timeout, objects
                       profinet:eth1 (DCP Identify all on an Ethernet port); option: response_delay (1..6400,
                       the DCP ResponseDelayFactor, default 16: answers within 2 s)
  --scan-timeout D     how long a device has to answer each request (default 100ms; canopen, ethercat)
  --device-dir DIR     also look for device profiles in DIR (before the built-in ones)
  --write-config FILE  write a configuration skeleton for what was found (--check-config accepts it)
  --force              replace FILE if it exists (otherwise it is kept and the command fails)

  profinet only, run in the order given before the listing (which then shows their result); every
  argument is checked before anything is sent, and the first action that fails ends them (exit 1):
  --set-name MAC=NAME  give the device at MAC (00:1b:1b:00:0a:04) the NameOfStation NAME (DCP Set);
                       refused unsent when another device answers with NAME
  --set-ip MAC=SUITE   give it the IP suite A.B.C.D/MASK[/GATEWAY] (MASK dotted or a prefix length)
  --permanent          the device keeps the name and IP suite over a power loss (a replaced drive
                       needs that); without it they are temporary: forgotten at a power loss (the
                       controller gives the configured address at start, but finds stations by name)
  --signal MAC|NAME    flash the LED of the device at MAC or with the NameOfStation NAME
)";

struct Args {
  std::string config;
  bool check_only = false;
  std::optional<std::string> log_level;
  std::optional<daemon::ScanCommand> scan;
};

std::optional<Args> parse_args(int argc, char** argv, int& exit_code) {
  Args a;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    auto value = [&](const char* what) -> std::optional<std::string> {
      if (i + 1 >= argc) {
        std::cerr << "drivegated: " << arg << " needs " << what << "\n" << kUsage;
        return std::nullopt;
      }
      return std::string(argv[++i]);
    };
    if (arg == "--help" || arg == "-h") {
      std::cout << kUsage;
      exit_code = 0;
      return std::nullopt;
    }
    if (arg == "--version") {
      std::cout << "drivegated " << DRIVEGATE_VERSION << "\n";
      exit_code = 0;
      return std::nullopt;
    }
    if (arg == "--config" || arg == "--check-config") {
      auto v = value("a file");
      if (!v) return std::nullopt;
      a.config = *v;
      a.check_only = a.check_only || arg == "--check-config";
    } else if (arg == "--scan") {
      auto v = value("TYPE:WHERE");
      if (!v) return std::nullopt;
      if (!a.scan) a.scan.emplace();
      a.scan->target = *v;
    } else if (arg == "--scan-timeout" || arg == "--device-dir" || arg == "--write-config") {
      auto v = value(arg == "--scan-timeout" ? "a duration" : arg == "--device-dir" ? "a directory" : "a file");
      if (!v) return std::nullopt;
      if (!a.scan) a.scan.emplace();
      if (arg == "--device-dir") {
        a.scan->device_dirs.emplace_back(*v);
      } else if (arg == "--write-config") {
        a.scan->write_config = *v;
      } else {
        const auto d = config::parse_duration(*v);
        if (!d || *d <= core::Duration::zero() || *d > std::chrono::seconds(10)) {
          std::cerr << "drivegated: --scan-timeout takes a duration above 0 and at most 10s such as 250ms, got '"
                    << *v << "'\n";
          return std::nullopt;
        }
        a.scan->answer_timeout = *d;
      }
    } else if (arg == "--set-name" || arg == "--set-ip" || arg == "--signal") {
      auto v = value(arg == "--set-name" ? "MAC=NAME" : arg == "--set-ip" ? "MAC=A.B.C.D/MASK[/GATEWAY]" : "MAC or NAME");
      if (!v) return std::nullopt;
      if (!a.scan) a.scan.emplace();
      a.scan->actions.push_back({arg, *v});  // checked by the scanner before it sends anything
    } else if (arg == "--force" || arg == "--permanent") {
      if (!a.scan) a.scan.emplace();
      (arg == "--force" ? a.scan->force : a.scan->permanent) = true;
    } else if (arg == "--log-level") {
      auto v = value("a level");
      if (!v) return std::nullopt;
      a.log_level = *v;
    } else {
      std::cerr << "drivegated: unknown argument '" << arg << "'\n" << kUsage;
      return std::nullopt;
    }
  }
  if (a.scan && a.scan->target.empty()) {
    std::cerr << "drivegated: --scan-timeout, --device-dir, --write-config, --force, --set-name, --set-ip, "
                 "--permanent and --signal go with --scan\n"
              << kUsage;
    return std::nullopt;
  }
  if (a.scan && !a.config.empty()) {
    std::cerr << "drivegated: --scan runs on its own, without --config or --check-config\n" << kUsage;
    return std::nullopt;
  }
  if (a.scan && a.scan->force && a.scan->write_config.empty()) {
    std::cerr << "drivegated: --force goes with --write-config\n" << kUsage;
    return std::nullopt;
  }
  if (a.config.empty() && !a.scan) {
    std::cerr << "drivegated: no configuration given\n" << kUsage;
    return std::nullopt;
  }
  return a;
}

void setup_logging(const std::string& level) {
  auto logger = spdlog::stderr_color_mt("drivegated");
  // Under systemd the journal adds time and process; on a terminal we add the time ourselves.
  if (std::getenv("JOURNAL_STREAM") != nullptr)
    logger->set_pattern("<%l> %v");
  else
    logger->set_pattern("%H:%M:%S.%e %^%-5l%$ %v");
  spdlog::set_default_logger(logger);
  spdlog::set_level(spdlog::level::from_str(level));
}

// Signals are taken synchronously through a signalfd so that shutdown runs on the main thread.
// Every signal whose default action would end or stop the process and that can be caught is in
// this set: none may leave an axis moving (DESIGN.md §4). Synchronous fault signals (SIGSEGV,
// SIGBUS, SIGILL, SIGFPE, SIGABRT, SIGSYS, SIGTRAP) are left alone: they cannot be deferred, and
// the drives' own communication watchdogs stop them when the process dies.
sigset_t watched_signals() {
  sigset_t set;
  sigemptyset(&set);
  for (const int s : {SIGTERM, SIGINT, SIGHUP, SIGQUIT, SIGUSR1, SIGUSR2, SIGALRM, SIGVTALRM, SIGPROF, SIGXCPU,
                      SIGXFSZ, SIGIO, SIGPWR, SIGSTKFLT, SIGTSTP, SIGTTIN, SIGTTOU})
    sigaddset(&set, s);
  for (int s = SIGRTMIN; s <= SIGRTMAX; ++s) sigaddset(&set, s);
  return set;
}

// What the daemon does with a signal from the watched set.
enum class SignalAction { Stop, Reload, Ignore };
SignalAction action_of(int sig) noexcept {
  switch (sig) {
    case SIGHUP: return SignalAction::Reload;
    // A daemon must not be frozen from a terminal: its cycle threads would stop with axes moving.
    case SIGTSTP:
    case SIGTTIN:
    case SIGTTOU: return SignalAction::Ignore;
    default: return SignalAction::Stop;
  }
}

int make_signal_fd() {
  // A write to a closed socket or pipe is an error return (EPIPE), not a reason to die.
  std::signal(SIGPIPE, SIG_IGN);
  const sigset_t set = watched_signals();
  pthread_sigmask(SIG_BLOCK, &set, nullptr);  // before any thread starts, so all inherit it
  return signalfd(-1, &set, SFD_CLOEXEC | SFD_NONBLOCK);
}

int wait_signal(int fd, std::chrono::milliseconds timeout) {
  fd_set fds;
  FD_ZERO(&fds);
  FD_SET(fd, &fds);
  timeval tv{static_cast<time_t>(timeout.count() / 1000), static_cast<suseconds_t>((timeout.count() % 1000) * 1000)};
  if (select(fd + 1, &fds, nullptr, nullptr, &tv) <= 0) return 0;
  signalfd_siginfo info{};
  if (read(fd, &info, sizeof info) != static_cast<ssize_t>(sizeof info)) return 0;
  return static_cast<int>(info.ssi_signo);
}

const char* signal_name(int sig) {
  const char* abbrev = sigabbrev_np(sig);
  static thread_local char buf[16];
  if (abbrev != nullptr) {
    std::snprintf(buf, sizeof buf, "SIG%s", abbrev);
  } else if (sig >= SIGRTMIN && sig <= SIGRTMAX) {
    std::snprintf(buf, sizeof buf, "SIGRTMIN+%d", sig - SIGRTMIN);
  } else {
    std::snprintf(buf, sizeof buf, "signal %d", sig);
  }
  return buf;
}

// SIGHUP: re-read and check the configuration, say what a restart would change, change nothing.
void reload_check(const Args& args, const config::Plan& running, daemon::SystemdNotifier& notifier) {
  notifier.reloading();
  try {
    const config::Plan next = config::load_plan(args.config);
    const auto changes = config::describe_changes(running, next);
    for (const auto& w : next.warnings) spdlog::warn("configuration reload: {}", w);
    if (changes.empty()) {
      spdlog::info("SIGHUP: {} re-read and checked: no changes", args.config);
    } else {
      spdlog::warn("SIGHUP: {} re-read and checked: {} change(s), not applied while running; restart drivegated "
                   "to apply them:",
                   args.config, changes.size());
      for (const auto& c : changes) spdlog::warn("  would change {}", c);
    }
  } catch (const config::ConfigError& e) {
    spdlog::error("SIGHUP: {} has errors; the running configuration stays:\n{}", args.config, e.what());
  } catch (const std::exception& e) {
    spdlog::error("SIGHUP: cannot re-read {}: {}; the running configuration stays", args.config, e.what());
  }
  notifier.ready();
}

int run(const Args& args) {
  config::Plan plan;
  try {
    plan = config::load_plan(args.config);
  } catch (const config::ConfigError& e) {
    std::cerr << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "drivegated: " << args.config << ": " << e.what() << "\n";
    return 2;
  }
  if (args.check_only) {
    std::cout << config::describe_plan(plan);
    return 0;
  }
  setup_logging(args.log_level.value_or(plan.gateway.log_level));
  for (const auto& w : plan.warnings) spdlog::warn("{}", w);

  const int sigfd = make_signal_fd();
  if (sigfd < 0) {
    spdlog::critical("cannot watch for signals: {}", std::strerror(errno));
    return 1;
  }
  daemon::SystemdNotifier notifier;

  bool realtime = false;
  for (const auto& b : plan.buses) realtime = realtime || b.priority > 0;
  if (realtime) {
    // Page faults are the largest source of jitter once SCHED_FIFO is in use; without real-time
    // scheduling locking memory would only cost RAM.
    const auto note = daemon::lock_memory();
    if (note.empty())
      spdlog::info("memory locked");
    else
      spdlog::warn("{}", note);
  }

  std::unique_ptr<daemon::Gateway> gateway;
  try {
    gateway = std::make_unique<daemon::Gateway>(plan);
  } catch (const std::exception& e) {
    spdlog::critical("start-up failed: {}", e.what());
    notifier.status(std::string("start-up failed: ") + e.what());
    return 1;
  }

  // DDS first: before any bus is opened, make sure no other instance of this gateway runs on the
  // domain (two masters commanding the same drives).
  daemon::DdsBridgeOptions dds;
  dds.domain = static_cast<std::uint32_t>(plan.gateway.domain);
  dds.ns = plan.gateway.ns;
  dds.status_rate_hz = plan.gateway.status_rate_hz;
  dds.status_keepalive = plan.gateway.status_keepalive;
  dds.profiles_file = plan.gateway.dds_profiles_file;
  dds.profile = plan.gateway.dds_profile;
  dds.interfaces = plan.gateway.dds_interfaces;
  if (const auto& sec = plan.gateway.security)
    dds.security = msg::SecurityFiles{sec->identity_ca,    sec->certificate, sec->private_key,
                                      sec->permissions_ca, sec->governance,  sec->permissions};
  daemon::DdsBridge bridge(*gateway, dds);
  try {
    bridge.start();
  } catch (const std::exception& e) {
    spdlog::critical("DDS start-up failed: {}", e.what());
    notifier.status(std::string("DDS start-up failed: ") + e.what());
    return 1;
  }
  if (const auto dup = bridge.wait_for_duplicate(
          std::chrono::duration_cast<std::chrono::milliseconds>(plan.gateway.duplicate_check));
      dup.seen) {
    spdlog::critical("refusing to start: {}", dup.text);
    notifier.status("refused to start: " + dup.text);
    bridge.let_others_see_us(2s);
    bridge.stop();
    return 1;
  }

  try {
    gateway->start();
  } catch (const std::exception& e) {
    spdlog::critical("start-up failed: {}", e.what());
    notifier.status(std::string("start-up failed: ") + e.what());
    bridge.stop();
    gateway->shutdown(2s);
    return 1;
  }
  for (const auto& n : gateway->scheduling_notes()) spdlog::warn("{}", n);

  spdlog::info("gateway {} running: {} (DDS domain {}, namespace '{}')", plan.gateway.name, gateway->status_line(),
               plan.gateway.domain, plan.gateway.ns);
  notifier.ready();
  notifier.status(gateway->status_line());

  const auto wd = notifier.watchdog_interval();
  auto last_status = std::chrono::steady_clock::now();
  auto last_ping = last_status;
  bool was_healthy = true;
  int sig = 0;
  bool duplicate = false;
  for (;;) {
    if (bridge.duplicate().this_one_stops) {
      duplicate = true;  // logged by the bridge; the later instance stops, the earlier goes on
      break;
    }
    sig = wait_signal(sigfd, 100ms);
    if (sig != 0) {
      const SignalAction action = action_of(sig);
      if (action == SignalAction::Stop) break;
      if (action == SignalAction::Reload)
        reload_check(args, plan, notifier);
      else
        spdlog::warn("{} ignored: a gateway with axes must not be stopped from a terminal", signal_name(sig));
    }
    const auto now = std::chrono::steady_clock::now();
    const bool ok = gateway->healthy();
    if (ok != was_healthy) {
      if (ok)
        spdlog::info("all cycle threads keep their schedule again");
      else
        spdlog::error("a cycle thread stopped keeping its schedule; withholding the watchdog ping");
      was_healthy = ok;
    }
    // WATCHDOG=1 only while every cycle thread is healthy: a stuck bus makes systemd restart us.
    if (wd && ok && now - last_ping >= *wd / 2) {
      notifier.watchdog();
      last_ping = now;
    }
    if (now - last_status >= 1s) {
      notifier.status(gateway->status_line());
      last_status = now;
    }
  }

  if (duplicate)
    spdlog::critical("another instance of gateway {} started first: stopping and disabling every axis", plan.gateway.name);
  else
    spdlog::info("{} received: stopping and disabling every axis", signal_name(sig));
  notifier.stopping();
  notifier.status("stopping: disabling axes");
  // A second stop signal skips the orderly stop only when it is meant as one: SIGQUIT, or any stop
  // signal at least kSecondSignalGrace after the first. GNU timeout and a kill of the process
  // group deliver one SIGTERM twice within milliseconds; those repeats are ignored.
  const auto first = std::chrono::steady_clock::now();
  std::thread second([sigfd, first] {
    for (;;) {
      const int again = wait_signal(sigfd, 1000ms);
      if (again == 0 || action_of(again) != SignalAction::Stop) continue;
      const auto since = std::chrono::steady_clock::now() - first;
      if (again == SIGQUIT || since >= kSecondSignalGrace) break;
      std::fprintf(stderr, "drivegated: %s ignored %lld ms after the first: still stopping the axes (send it again "
                   "after %lld ms, or SIGQUIT, to exit at once)\n",
                   signal_name(again),
                   static_cast<long long>(std::chrono::duration_cast<std::chrono::milliseconds>(since).count()),
                   static_cast<long long>(kSecondSignalGrace.count()));
    }
    std::fputs("drivegated: second signal, exiting at once without stopping the axes\n", stderr);
    std::_Exit(130);
  });
  second.detach();

  const auto report = gateway->shutdown(3s);
  spdlog::info("{} axes quick-stopped, {} disabled", report.stopped, report.disabled);
  int rc = duplicate ? 1 : 0;
  for (const auto& a : report.unconfirmed) {
    spdlog::error("axis {} did not confirm it is disabled", a);
    rc = 1;
  }
  // Let the bridge publish one more round of axis states, taken after the axes were disabled,
  // before it goes (bounded, in case DDS is stuck).
  const auto published = bridge.stats().states_published;
  const auto until = std::chrono::steady_clock::now() + 1s;
  while (bridge.stats().states_published < published + 2 * gateway->axes().size() &&
         std::chrono::steady_clock::now() < until)
    std::this_thread::sleep_for(5ms);
  if (bridge.stats().states_published < published + 2 * gateway->axes().size())
    spdlog::warn("the axis states after the stop were not all published within 1 s: clients may not see them");
  bridge.stop();
  gateway.reset();
  spdlog::info("stopped");
  return rc;
}

}  // namespace

int main(int argc, char** argv) {
  int exit_code = 2;
  const auto args = parse_args(argc, argv, exit_code);
  if (!args) return exit_code;
  if (args->scan) return daemon::run_scan_command(*args->scan, std::cout, std::cerr);
  return run(*args);
}
