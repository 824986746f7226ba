// Every command gets exactly one final reply, also in a burst (DESIGN.md §4): several clients
// write 10,000 commands and 10,000 parameter requests at the real drivegated as fast as DDS takes
// them, on the raw topics as a client of any DDS vendor would, and every reply is counted.
#include <gtest/gtest.h>
#include <signal.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <map>
#include <mutex>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include <fastdds/dds/core/status/PublicationMatchedStatus.hpp>
#include <fastdds/dds/core/status/SubscriptionMatchedStatus.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>

#include "client/client.hpp"
#include "drivegate.h"
#include "idl/dds_node.hpp"
#include "tests/daemon/daemon_process.hpp"

using namespace drivegate;
using namespace std::chrono_literals;
namespace fdds = eprosima::fastdds::dds;
using Clock = std::chrono::steady_clock;

namespace {

constexpr auto kStartUp = 15s;
const int kClients = std::getenv("BURST_CLIENTS") ? std::atoi(std::getenv("BURST_CLIENTS")) : 4;
constexpr int kCommandsPerClient = 2500;  // 10,000 in all
constexpr int kParamsPerClient = 2500;    // 10,000 in all

// One client on the raw topics: writes as fast as the writer takes samples (keep-all: write()
// waits while the gateway's history is full) and counts every reply addressed to it. It has no
// window of its own, so its replies are taken as they arrive (a listener on the readers): with the
// table's keep-last readers a client that lets more than 1024 of its replies pile up loses the
// oldest (README "DDS topics"), which a test thread starved on a loaded machine did.
class RawClient final : private fdds::DataReaderListener {
 public:
  RawClient(const test::DdsIsolation& iso, std::string name) : name_(std::move(name)), node_(options(iso, name_)) {
    cmd_w_ = &node_.writer(msg::TopicId::AxisCommand);
    param_w_ = &node_.writer(msg::TopicId::ParamRequest);
    reply_r_ = &node_.reader(msg::TopicId::CommandReply, this, fdds::StatusMask::data_available());
    param_r_ = &node_.reader(msg::TopicId::ParamReply, this, fdds::StatusMask::data_available());
  }

  bool wait_matched(std::chrono::milliseconds timeout) {
    const auto until = Clock::now() + timeout;
    while (Clock::now() < until) {
      fdds::PublicationMatchedStatus c{}, p{};
      fdds::SubscriptionMatchedStatus r{}, q{};
      cmd_w_->get_publication_matched_status(c);
      param_w_->get_publication_matched_status(p);
      reply_r_->get_subscription_matched_status(r);
      param_r_->get_subscription_matched_status(q);
      if (c.current_count > 0 && p.current_count > 0 && r.current_count > 0 && q.current_count > 0) return true;
      std::this_thread::sleep_for(10ms);
    }
    return false;
  }

  // Commands and parameter requests interleaved; a write that times out (flow control) is repeated.
  void send_all(const std::string& gateway) {
    for (int i = 0; i < kCommandsPerClient; ++i) {
      msg::AxisCommand c;
      c.gateway(gateway);
      c.axis(i % 2 == 0 ? "x" : "y");
      c.client(name_);
      c.id(static_cast<std::uint64_t>(i + 1));
      c.kind("move");
      // Every 50th is invalid: its rejection counts as its final reply like any other.
      c.position(i % 50 == 49 ? std::numeric_limits<double>::quiet_NaN() : 1.0 + (i % 7));
      c.velocity(20);
      c.immediate(true);
      while (cmd_w_->write(&c, fdds::HANDLE_NIL) == ReturnCode_t::RETCODE_TIMEOUT) ++write_waits_;
      msg::ParameterRequest p;
      p.gateway(gateway);
      p.axis(i % 2 == 0 ? "x" : "y");
      p.client(name_);
      p.id(static_cast<std::uint64_t>(i + 1));
      p.index(0x6064);
      if (i < kParamsPerClient)
        while (param_w_->write(&p, fdds::HANDLE_NIL) == ReturnCode_t::RETCODE_TIMEOUT) ++write_waits_;
    }
  }

  // Takes what arrived (the readers' listener: the only caller, so that no other thread takes
  // from the readers while holding mutex_ as the listener may be called holding a reader's lock).
  void collect() {
    const std::lock_guard lock(mutex_);
    msg::CommandReply r;
    fdds::SampleInfo info;
    while (reply_r_->take_next_sample(&r, &info) == ReturnCode_t::RETCODE_OK) {
      if (!info.valid_data || r.client() != name_) continue;
      if (r.status() == "accepted") {
        ++accepted_[r.id()];
        continue;
      }
      ++finals_[r.id()];
      ++by_status_[r.status()];
      if (r.reason().rfind("busy", 0) == 0) ++busy_;
    }
    msg::ParameterReply p;
    while (param_r_->take_next_sample(&p, &info) == ReturnCode_t::RETCODE_OK) {
      if (!info.valid_data || p.client() != name_) continue;
      ++param_finals_[p.id()];
      if (!p.ok() && p.error().rfind("busy", 0) == 0) ++param_busy_;
      else if (!p.ok()) ++param_errors_;
    }
  }

  // Exactly one final reply per command and per request, and nothing for ids never sent.
  void expect_exactly_one_each() const {
    const std::lock_guard lock(mutex_);
    EXPECT_EQ(finals_.size(), static_cast<std::size_t>(kCommandsPerClient)) << name_;
    EXPECT_EQ(param_finals_.size(), static_cast<std::size_t>(kParamsPerClient)) << name_;
    for (const auto& [id, n] : finals_) {
      EXPECT_EQ(n, 1) << name_ << " command " << id << " got " << n << " final replies";
      EXPECT_TRUE(id >= 1 && id <= kCommandsPerClient) << id;
    }
    for (const auto& [id, n] : accepted_) EXPECT_EQ(n, 1) << name_ << " command " << id << " accepted " << n << " times";
    for (const auto& [id, n] : param_finals_) EXPECT_EQ(n, 1) << name_ << " request " << id << ": " << n << " replies";
  }

  void print_missing() const {
    const std::lock_guard lock(mutex_);
    int shown = 0;
    for (std::uint64_t id = 1; id <= kCommandsPerClient && shown < 10; ++id)
      if (!finals_.count(id)) {
        std::printf("%s: no final for command %llu (accepted %d)\n", name_.c_str(), static_cast<unsigned long long>(id),
                    accepted_.count(id) ? accepted_.at(id) : 0);
        ++shown;
      }
    for (std::uint64_t id = 1; id <= kParamsPerClient && shown < 20; ++id)
      if (!param_finals_.count(id)) {
        std::printf("%s: no reply for parameter request %llu\n", name_.c_str(), static_cast<unsigned long long>(id));
        ++shown;
      }
  }
  std::map<std::string, int> by_status_;
  std::uint64_t busy_ = 0;
  std::uint64_t param_errors_ = 0;  // errors other than "busy"
  std::uint64_t param_busy_ = 0;
  std::uint64_t write_waits_ = 0;
  std::size_t finals() const {
    const std::lock_guard lock(mutex_);
    return finals_.size();
  }
  std::size_t param_finals() const {
    const std::lock_guard lock(mutex_);
    return param_finals_.size();
  }

 private:
  void on_data_available(fdds::DataReader* /*reader*/) override { collect(); }

  static msg::DdsOptions options(const test::DdsIsolation& iso, const std::string& name) {
    msg::DdsOptions o;
    o.domain = iso.domain;
    o.ns = iso.ns;
    o.participant_name = name;
    return o;
  }
  std::string name_;
  msg::DdsNode node_;
  fdds::DataWriter* cmd_w_ = nullptr;
  fdds::DataWriter* param_w_ = nullptr;
  fdds::DataReader* reply_r_ = nullptr;
  fdds::DataReader* param_r_ = nullptr;
  mutable std::mutex mutex_;  // the readers' listener thread and the test's thread
  std::map<std::uint64_t, int> accepted_;
  std::map<std::uint64_t, int> finals_;
  std::map<std::uint64_t, int> param_finals_;
};

std::size_t count_lines(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (auto at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

TEST(Burst, TenThousandCommandsAndParameterRequestsFromSeveralClientsGetOneReplyEach) {
  const auto dds_iso = test::unique_dds("burst");
  const auto config = test::write_demo_config("burst", dds_iso);
  test::NotifySocket notify;
  test::DaemonProcess daemon(config, notify.path(), std::getenv("BURST_LOG") ? std::getenv("BURST_LOG") : "info");
  ASSERT_TRUE(notify.wait_for("READY=1", kStartUp)) << daemon.log();
  {
    client::Client c(client::options_for(dds_iso.domain, dds_iso.ns, "burst-setup"));
    for (const char* axis : {"x", "y"}) {
      client::CommandRequest en;
      en.axis = axis;
      en.kind = "enable";
      const auto r = c.send(en, true, 20s);
      ASSERT_EQ(r.outcome, client::Outcome::Completed) << r.reason << daemon.log();
    }
  }

  std::vector<std::unique_ptr<RawClient>> clients;
  for (int i = 0; i < kClients; ++i)
    clients.push_back(std::make_unique<RawClient>(dds_iso, "burst-" + std::to_string(i)));
  for (auto& c : clients) ASSERT_TRUE(c->wait_matched(kStartUp)) << daemon.log();

  const auto start = Clock::now();
  std::vector<std::thread> writers;
  for (auto& c : clients)
    writers.emplace_back([&c] { c->send_all("burst"); });
  for (auto& t : writers) t.join();
  const auto written = Clock::now();
  const auto deadline = written + 120s;
  bool all = false;
  while (!all && Clock::now() < deadline) {
    all = true;
    for (auto& c : clients) all = all && c->finals() == kCommandsPerClient && c->param_finals() == kParamsPerClient;
    if (!all) std::this_thread::sleep_for(20ms);
  }
  const auto finished = Clock::now();

  std::map<std::string, int> statuses;
  std::uint64_t busy = 0, waits = 0, param_errors = 0, param_busy = 0;
  for (auto& c : clients) {
    c->expect_exactly_one_each();
    for (const auto& [s, n] : c->by_status_) statuses[s] += n;
    busy += c->busy_;
    waits += c->write_waits_;
    param_errors += c->param_errors_;
    param_busy += c->param_busy_;
  }
  const auto ms = [](Clock::duration d) { return std::chrono::duration_cast<std::chrono::milliseconds>(d).count(); };
  std::printf("burst: %d commands and %d parameter requests from %d clients: written in %lld ms, every reply in "
              "%lld ms; finals: completed %d, failed %d, rejected %d (busy %llu); parameter replies busy %llu, other "
              "errors %llu; writes that waited for flow control %llu\n",
              kClients * kCommandsPerClient, kClients * kParamsPerClient, kClients, static_cast<long long>(ms(written - start)),
              static_cast<long long>(ms(finished - start)), statuses["completed"], statuses["failed"],
              statuses["rejected"], static_cast<unsigned long long>(busy), static_cast<unsigned long long>(param_busy),
              static_cast<unsigned long long>(param_errors),
              static_cast<unsigned long long>(waits));
  EXPECT_TRUE(all) << daemon.log().substr(0, 4000);
  for (auto& c : clients) c->print_missing();
  // Every 50th command was invalid; the others were taken (moves supersede each other) or, when a
  // client had too many unanswered, answered "busy" (these clients have no window of their own).
  EXPECT_GE(statuses["rejected"], kClients * kCommandsPerClient / 50);
  EXPECT_LE(static_cast<std::uint64_t>(statuses["rejected"]),
            static_cast<std::uint64_t>(kClients * kCommandsPerClient / 50) + busy);
  EXPECT_EQ(param_errors, 0u);

  // The journal gets a summary, not a line per command: 20,000 requests, a few dozen lines.
  const std::string log = daemon.log();
  EXPECT_LT(count_lines(log, "\n"), 200u) << log.substr(0, 4000);
  EXPECT_LE(count_lines(log, "dds: rejected"), 10u) << log.substr(0, 4000);
  EXPECT_EQ(daemon.terminate(SIGTERM, 20s), 0) << daemon.log().substr(0, 4000);
}

// The client library: many threads of one client send at once; its window keeps at most 64 in
// flight, and every send gets its reply (no timeouts, no busy).
TEST(Burst, OneClientManyThreadsStayWithinItsWindow) {
  const auto dds_iso = test::unique_dds("burst_lib");
  test::NotifySocket notify;
  test::DaemonProcess daemon(test::write_demo_config("burstlib", dds_iso), notify.path());
  ASSERT_TRUE(notify.wait_for("READY=1", kStartUp)) << daemon.log();
  auto opts = client::options_for(dds_iso.domain, dds_iso.ns, "burst-lib");
  opts.window = 16;
  client::Client c(opts);
  client::CommandRequest en;
  en.axis = "x";
  en.kind = "enable";
  ASSERT_EQ(c.send(en, true, 20s).outcome, client::Outcome::Completed);
  std::atomic<int> accepted{0}, other{0};
  std::vector<std::thread> threads;
  for (int t = 0; t < 8; ++t)
    threads.emplace_back([&, t] {
      for (int i = 0; i < 125; ++i) {
        client::CommandRequest mv;
        mv.axis = "x";
        mv.kind = "move";
        mv.position = 1.0 + ((t + i) % 5);
        const auto r = c.send(mv, false, 30s);
        (r.outcome == client::Outcome::Accepted ? accepted : other)++;
        if (r.outcome != client::Outcome::Accepted) std::fprintf(stderr, "%s: %s\n", client::to_string(r.outcome).data(), r.reason.c_str());
      }
    });
  for (auto& t : threads) t.join();
  EXPECT_EQ(accepted.load(), 1000);
  EXPECT_EQ(other.load(), 0);
  EXPECT_EQ(daemon.terminate(SIGTERM, 20s), 0);
}

}  // namespace
