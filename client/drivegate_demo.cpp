// drivegate-demo: drives the demo axes through a short sequence so a newcomer sees motion within
// seconds (enable, home, a few moves, a spindle jog, stop, disable), with a live table. Ctrl-C
// stops and disables every axis before exiting.
#include <algorithm>
#include <atomic>
#include <cmath>
#include <map>
#include <chrono>
#include <cstdio>
#include <condition_variable>
#include <deque>
#include <future>
#include <iostream>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "client/cli_args.hpp"
#include "client/client.hpp"
#include "client/discovery.hpp"
#include "client/interrupt.hpp"
#include "client/status_table.hpp"

namespace {

using namespace drivegate::client;
using SteadyClock = std::chrono::steady_clock;

constexpr const char* kUsage =
    "usage: drivegate-demo [--domain N] [--namespace NS] [--gateway G] [--identity DIR] [--timeout S]\n"
    "                      [--x AXIS] [--y AXIS] [--spindle AXIS] [--turntable AXIS]\n"
    "                      [--spindle-speed V] [--jog-seconds S] [--plain]\n"
    "Enables the demo axes, homes the turntable and the PROFINET drive feed, moves x and y, moves the\n"
    "CANopen drives akd, nord and sd6 and the EtherCAT drives esr and servo out and back, streams a\n"
    "stroke to esr (ip) and servo (csp), jogs the spindle and the PROFINET drive akdpn, then stops\n"
    "and disables everything. Axis names default\n"
    "to those of demo.yaml (x, y, spindle, turntable); axes that no gateway offers are skipped.\n"
    "--plain prints step lines without the live table.\n";

// Keep-alive rate for the spindle jog: several times what a typical command timeout needs.
constexpr auto kKeepAlivePeriod = std::chrono::milliseconds(50);
// Streamed set-points (ip, csp): the gateway holds the last one until the next arrives.
constexpr auto kStreamPeriod = std::chrono::milliseconds(10);

class Demo {
 public:
  Demo(Client& client, Millis timeout, std::string gateway, bool plain)
      : client_(client), timeout_(timeout), gateway_(std::move(gateway)), plain_(plain) {}

  void start_display() {
    if (plain_) return;
    display_ = std::thread([this] {
      while (!done_) {
        draw();
        std::unique_lock lock(mutex_);
        wake_.wait_for(lock, std::chrono::milliseconds(100), [this] { return done_.load(); });
      }
      draw();
    });
  }
  void stop_display() {
    done_ = true;
    wake_.notify_all();
    if (display_.joinable()) display_.join();
  }

  void log(const std::string& line) {
    std::lock_guard lock(mutex_);
    if (plain_) std::cout << line << std::endl;
    steps_.push_back(line);
    if (steps_.size() > 12) steps_.pop_front();
  }

  // One command, waited for to its final reply. Returns false on anything but success.
  bool step(const std::string& title, CommandRequest req) {
    if (interrupted()) return false;
    req.gateway = gateway_;
    const auto r = client_.send(req, true, timeout_);
    log(title + ": " + std::string(to_string(r.outcome)) + (r.reason.empty() ? "" : " (" + r.reason + ")"));
    return r.ok();
  }

  bool together(const std::string& title, const std::vector<CommandRequest>& reqs) {
    if (interrupted()) return false;
    std::vector<std::future<bool>> results;
    for (const auto& r : reqs)
      results.push_back(std::async(std::launch::async, [this, title, r] { return step(title + " " + r.axis, r); }));
    bool ok = true;
    for (auto& f : results) ok = f.get() && ok;
    return ok;
  }

  bool jog(const std::string& axis, double speed, double seconds) {
    CommandRequest req;
    req.axis = axis;
    req.gateway = gateway_;
    req.kind = "velocity";
    req.velocity = speed;
    const auto r = client_.send(req, false, timeout_);
    char rate[32];
    std::snprintf(rate, sizeof rate, "%g", speed);
    log("jog " + axis + " at " + rate + ": " + std::string(to_string(r.outcome)) +
        (r.reason.empty() ? "" : " (" + r.reason + ")"));
    if (!r.ok()) return false;
    const auto until = SteadyClock::now() + std::chrono::duration_cast<SteadyClock::duration>(
                                                std::chrono::duration<double>(seconds));
    auto next = SteadyClock::now();
    while (!interrupted() && SteadyClock::now() < until) {
      const auto error = client_.stream_setpoint(axis, r.gateway, 0, speed, 0);
      if (!error.empty()) {
        log("jog " + axis + ": " + error);
        break;
      }
      next += kKeepAlivePeriod;
      std::this_thread::sleep_until(std::min(next, until));
    }
    CommandRequest stop = req;
    stop.kind = "stop";
    stop.gateway = r.gateway;
    const auto s = client_.send(stop, true, timeout_);
    log("stop " + axis + ": " + std::string(to_string(s.outcome)) + (s.reason.empty() ? "" : " (" + s.reason + ")"));
    return s.ok() && !interrupted();
  }

  // Streamed set-points: each axis in its cyclic `mode` (ip, csp) follows one raised-cosine stroke
  // of `stroke` (its unit) out and back over `seconds`, a set-point every kStreamPeriod, then
  // stands where it started.
  bool stream(const std::vector<std::pair<std::string, double>>& strokes, const std::string& mode, double seconds) {
    if (interrupted() || strokes.empty()) return !interrupted();
    std::map<std::string, std::string> gateway_of;
    std::map<std::string, double> start;
    for (const auto& [axis, stroke] : strokes) {
      CommandRequest req;
      req.axis = axis;
      req.gateway = gateway_;
      req.kind = "set_mode";
      req.mode = mode;
      const auto r = client_.send(req, true, timeout_);
      log("mode " + mode + " " + axis + ": " + std::string(to_string(r.outcome)) + (r.reason.empty() ? "" : " (" + r.reason + ")"));
      if (!r.ok()) return false;
      gateway_of[axis] = r.gateway;
      for (const auto& st : client_.states())
        if (st.axis == axis && st.gateway == r.gateway) start[axis] = st.position;
    }
    const auto t0 = SteadyClock::now();
    auto next = t0;
    for (;;) {
      if (interrupted()) return false;
      const double t = std::min(std::chrono::duration<double>(SteadyClock::now() - t0).count(), seconds);
      const double shape = 0.5 * (1.0 - std::cos(2.0 * 3.141592653589793 * t / seconds));
      for (const auto& [axis, stroke] : strokes) {
        const auto error = client_.stream_setpoint(axis, gateway_of[axis], start[axis] + stroke * shape, 0, 0);
        if (!error.empty()) {
          log("stream " + axis + ": " + error);
          return false;
        }
      }
      if (t >= seconds) break;
      next += kStreamPeriod;
      std::this_thread::sleep_until(next);
    }
    // Stopped and back in profile position before the stream falls silent: a cyclic mode without
    // set-points runs into the axis' command timeout (a quick stop), and a set-point still on its
    // way when the stop was taken would restart the stream.
    bool ok = true;
    for (const auto& [axis, stroke] : strokes) {
      CommandRequest req;
      req.axis = axis;
      req.gateway = gateway_of[axis];
      req.kind = "stop";
      ok = step(mode + " stroke done, stop " + axis, req) && ok;
      // The drive settles on its last interpolation period; profile position is taken at rest.
      client_.wait_until(
          [&] {
            for (const auto& st : client_.states())
              if (st.axis == req.axis && st.gateway == req.gateway) return st.velocity == 0.0;
            return false;
          },
          timeout_);
      req.kind = "set_mode";
      req.mode = "pp";
      ok = ok && step("mode pp " + axis, req);
    }
    return ok;
  }

  // Safe end, also after Ctrl-C: stop and disable every axis we touched, whatever happened before.
  void shut_down(const std::vector<std::string>& axes) {
    for (const auto& a : axes) {
      CommandRequest req;
      req.axis = a;
      req.gateway = gateway_;
      req.kind = "disable";
      const auto r = client_.send(req, true, timeout_);
      log("disable " + a + ": " + std::string(to_string(r.outcome)) + (r.reason.empty() ? "" : " (" + r.reason + ")"));
    }
    // The final table should show what the replies said: wait for the published states to agree.
    client_.wait_until(
        [&] {
          for (const auto& a : axes) {
            const auto st = client_.state(a, gateway_);
            if (st && st->state == "operation_enabled") return false;
          }
          return true;
        },
        Millis(2000));
  }

 private:
  void draw() {
    auto states = client_.states();
    std::lock_guard lock(mutex_);
    std::string out = kAnsiClearHome;
    out += format_status_table(states, client_.links(), SteadyClock::now());
    out += "\nsteps:\n";
    for (const auto& s : steps_) out += "  " + s + "\n";
    std::cout << out << std::flush;
  }

  Client& client_;
  Millis timeout_;
  std::string gateway_;
  bool plain_;
  std::mutex mutex_;
  std::condition_variable wake_;
  std::deque<std::string> steps_;
  std::atomic<bool> done_{false};
  std::thread display_;
};

CommandRequest command(const std::string& axis, const char* kind) {
  CommandRequest r;
  r.axis = axis;
  r.kind = kind;
  return r;
}

CommandRequest move(const std::string& axis, double position) {
  CommandRequest r = command(axis, "move");
  r.position = position;
  return r;
}

int run(int argc, char** argv) {
  const Args args(argc, argv, {"help", "plain"});
  if (args.flag("help")) {
    std::cout << kUsage;
    return 0;
  }
  args.reject_unknown({"domain", "namespace", "gateway", "identity", "timeout", "x", "y", "spindle", "turntable", "spindle-speed",
                       "jog-seconds", "help", "plain"});
  if (!args.positional().empty()) throw UsageError("unexpected argument '" + args.positional().front() + "'");
  ClientOptions opts;
  opts.domain = static_cast<std::uint32_t>(parse_integer("--domain", args.option_or("domain", "0"), 0, 232));
  opts.ns = args.option_or("namespace", "drivegate");
  opts.identity = args.option_or("identity", "");
  const double timeout_s = args.number("timeout").value_or(15.0);
  const double speed = args.number("spindle-speed").value_or(10.0);
  const double jog_seconds = args.number("jog-seconds").value_or(3.0);
  if (timeout_s <= 0 || jog_seconds <= 0) throw UsageError("--timeout and --jog-seconds must be positive");
  const std::string gateway = args.option_or("gateway", "");
  const Millis timeout(static_cast<std::int64_t>(timeout_s * 1000));

  install_interrupt_handler();
  Client client(opts);
  std::cout << "drivegate-demo: looking for gateways on domain " << opts.domain << ", namespace '" << opts.ns
            << "' ..." << std::endl;
  if (!discover_gateways(client, gateway, Millis(std::min<std::int64_t>(timeout.count(), 10000)))) {
    std::cerr << "drivegate-demo: no gateway answered; is drivegated running with the demo config?\n";
    return 1;
  }

  // Use the demo names that some gateway actually offers.
  auto offered = [&](const std::string& name) { return client.route(name, gateway).error.empty(); };
  const std::string x = args.option_or("x", "x");
  const std::string y = args.option_or("y", "y");
  const std::string spindle = args.option_or("spindle", "spindle");
  const std::string turntable = args.option_or("turntable", "turntable");
  std::vector<std::string> axes;
  for (const auto& a : {x, y, spindle, turntable}) {
    if (offered(a)) {
      axes.push_back(a);
    } else {
      std::cerr << "drivegate-demo: skipping axis '" << a << "': " << client.route(a, gateway).error << "\n";
    }
  }
  // The CANopen and EtherCAT drives of the demo config, each moved out and back (in its own unit);
  // the PROFINET AKDs: feed is homed and moved like them (MDI), akdpn (speed mode) jogged.
  const std::vector<std::pair<std::string, double>> fieldbus_moves{
      {"akd", 20}, {"nord", 3}, {"sd6", 2}, {"esr", 5}, {"servo", 30}, {"feed", 3}};
  for (const auto& [a, distance] : fieldbus_moves)
    if (offered(a)) axes.push_back(a);
  if (offered("akdpn")) axes.push_back("akdpn");
  if (axes.empty()) {
    std::cerr << "drivegate-demo: none of the demo axes is available\n";
    return 1;
  }
  auto has = [&](const std::string& a) { return std::find(axes.begin(), axes.end(), a) != axes.end(); };

  Demo demo(client, timeout, gateway, args.flag("plain"));
  demo.start_display();
  bool ok = true;
  std::vector<CommandRequest> enables;
  for (const auto& a : axes) enables.push_back(command(a, "enable"));
  ok = demo.together("enable", enables);
  if (ok && has(turntable)) ok = demo.step("home " + turntable, command(turntable, "home"));
  if (ok && has("feed")) ok = demo.step("home feed", command("feed", "home"));
  const std::vector<std::pair<double, double>> path{{50, 20}, {100, 60}, {20, 80}, {0, 0}};
  for (const auto& [px, py] : path) {
    if (!ok) break;
    std::vector<CommandRequest> moves;
    if (has(x)) moves.push_back(move(x, px));
    if (has(y)) moves.push_back(move(y, py));
    if (!moves.empty()) ok = demo.together("move", moves);
  }
  for (const double scale : {1.0, 0.0}) {
    std::vector<CommandRequest> moves;
    for (const auto& [a, distance] : fieldbus_moves)
      if (has(a)) moves.push_back(move(a, scale * distance));
    if (ok && !moves.empty()) ok = demo.together("move", moves);
  }
  // The EtherCAT drives on streamed set-points: the ESR in interpolated position (its only cyclic
  // position mode), the generic servo in cyclic synchronous position.
  if (ok && has("esr")) ok = demo.stream({{"esr", 3}}, "ip", 2.0);
  if (ok && has("servo")) ok = demo.stream({{"servo", 20}}, "csp", 2.0);
  if (ok && has(spindle)) ok = demo.jog(spindle, speed, jog_seconds);
  if (ok && has("akdpn")) ok = demo.jog("akdpn", speed, jog_seconds);
  if (interrupted()) demo.log("interrupted: disabling all axes");
  demo.shut_down(axes);
  demo.stop_display();
  if (interrupted()) return 130;
  std::cout << (ok ? "drivegate-demo: done\n" : "drivegate-demo: a step failed, see above\n");
  return ok ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const UsageError& e) {
    std::cerr << "drivegate-demo: " << e.what() << "\n" << kUsage;
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "drivegate-demo: " << e.what() << "\n";
    return 1;
  }
}
