// What DDS Security costs on the command round trip: the real drivegated on the demo config twice,
// without and with security (certificates from scripts/make-pki.sh), commanded through the client
// library with an operator identity. Blocks of round trips alternate between the two so machine
// noise hits both alike. Prints latency percentiles and CPU per command of the daemon and of the
// client, and the ratios secure / plain.
//
//   bench_security_cost [--commands N]   (default 2000 per configuration)
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "bench/proc_stat.hpp"
#include "client/client.hpp"
#include "tests/daemon/daemon_process.hpp"

using namespace drivegate;
using bench::stat_ticks;
using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

namespace {

// utime + stime of a process in seconds.
double process_cpu(pid_t pid) {
  return static_cast<double>(stat_ticks("/proc/" + std::to_string(pid) + "/stat")) /
         static_cast<double>(::sysconf(_SC_CLK_TCK));
}

double self_cpu() {
  rusage u{};
  ::getrusage(RUSAGE_SELF, &u);
  return static_cast<double>(u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
         static_cast<double>(u.ru_utime.tv_usec + u.ru_stime.tv_usec) / 1e6;
}

struct Side {
  std::string name;
  test::DdsIsolation dds;
  std::unique_ptr<test::NotifySocket> notify;
  std::unique_ptr<test::DaemonProcess> daemon;
  std::unique_ptr<client::Client> client;
  std::vector<double> latency_us;
  double daemon_cpu = 0;
  double client_cpu = 0;
};

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[static_cast<std::size_t>(p * static_cast<double>(v.size() - 1))];
}

}  // namespace

int main(int argc, char** argv) {
  int commands = 2000;
  for (int i = 1; i + 1 < argc; ++i)
    if (std::string(argv[i]) == "--commands") commands = std::max(100, std::atoi(argv[i + 1]));

  const auto pki = std::filesystem::temp_directory_path() / ("drivegate-bench-pki-" + std::to_string(::getpid()));
  Side plain{"plain", test::unique_dds("bench_plain"), {}, {}, {}, {}, 0, 0};
  Side secure{"secure", test::unique_dds("bench_secure"), {}, {}, {}, {}, 0, 0};
  secure.dds.domain = plain.dds.domain;  // the namespaces differ; the PKI covers the one domain
  const std::string make = std::string(DRIVEGATE_MAKE_PKI) + " " + pki.string() + " --domain " +
                           std::to_string(secure.dds.domain) + " --client operator:operator >/dev/null";
  if (std::system(make.c_str()) != 0) {
    std::fprintf(stderr, "bench_security_cost: make-pki.sh failed\n");
    return 1;
  }
  for (Side* s : {&plain, &secure}) {
    const bool sec = s == &secure;
    const auto config = test::write_demo_config("bench_" + s->name, s->dds, [&](YAML::Node& root) {
      if (sec) root["gateway"]["security"]["dir"] = (pki / "gateway").string();
    });
    s->notify = std::make_unique<test::NotifySocket>();
    s->daemon = std::make_unique<test::DaemonProcess>(config, s->notify->path(), "warn");
    if (!s->notify->wait_for("READY=1", 20s)) {
      std::fprintf(stderr, "bench_security_cost: %s daemon did not start:\n%s\n", s->name.c_str(), s->daemon->log().c_str());
      return 1;
    }
    auto o = client::options_for(s->dds.domain, s->dds.ns, "bench-" + s->name);
    if (sec) o.identity = (pki / "operator").string();
    s->client = std::make_unique<client::Client>(o);
    client::CommandRequest en;
    en.axis = "x";
    en.kind = "enable";
    const auto r = s->client->send(en, true, 20s);
    if (r.outcome != client::Outcome::Completed) {
      std::fprintf(stderr, "bench_security_cost: %s: enable: %s\n", s->name.c_str(), r.reason.c_str());
      return 1;
    }
  }

  // A resume completes at once in the gateway: the round trip is DDS both ways and one bus cycle.
  client::CommandRequest resume;
  resume.axis = "x";
  resume.kind = "resume";
  constexpr int kBlock = 100;
  for (int done = 0; done < commands; done += kBlock) {
    for (Side* s : {&plain, &secure}) {
      const double d0 = process_cpu(s->daemon->pid());
      const double c0 = self_cpu();
      for (int i = 0; i < kBlock; ++i) {
        const auto t0 = Clock::now();
        const auto r = s->client->send(resume, true, 5s);
        const auto t1 = Clock::now();
        if (r.outcome != client::Outcome::Completed) {
          std::fprintf(stderr, "bench_security_cost: %s: %s\n", s->name.c_str(), r.reason.c_str());
          return 1;
        }
        s->latency_us.push_back(std::chrono::duration<double, std::micro>(t1 - t0).count());
      }
      s->daemon_cpu += process_cpu(s->daemon->pid()) - d0;
      s->client_cpu += self_cpu() - c0;
    }
  }

  std::printf("command round trip (resume, completed), %d per configuration, alternating blocks of %d\n", commands,
              kBlock);
  std::printf("%-8s %10s %10s %10s %16s %16s\n", "", "p50 us", "p99 us", "max us", "daemon CPU us/cmd",
              "client CPU us/cmd");
  for (Side* s : {&plain, &secure})
    std::printf("%-8s %10.0f %10.0f %10.0f %16.0f %16.0f\n", s->name.c_str(), percentile(s->latency_us, 0.5),
                percentile(s->latency_us, 0.99), percentile(s->latency_us, 1.0), 1e6 * s->daemon_cpu / commands,
                1e6 * s->client_cpu / commands);
  const auto ratio = [](double a, double b) { return b > 0 ? a / b : 0.0; };
  std::printf("%-8s %10.2f %10.2f %10.2f %16.2f %16.2f\n", "ratio", ratio(percentile(secure.latency_us, 0.5), percentile(plain.latency_us, 0.5)),
              ratio(percentile(secure.latency_us, 0.99), percentile(plain.latency_us, 0.99)),
              ratio(percentile(secure.latency_us, 1.0), percentile(plain.latency_us, 1.0)),
              ratio(secure.daemon_cpu, plain.daemon_cpu), ratio(secure.client_cpu, plain.client_cpu));
  for (Side* s : {&plain, &secure}) {
    s->client.reset();
    s->daemon->terminate(SIGTERM, 20s);
  }
  std::filesystem::remove_all(pki);
  return 0;
}
