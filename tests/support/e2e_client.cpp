#include "tests/support/e2e_client.hpp"

#include <fstream>
#include <sstream>
#include <thread>

namespace drivegate::test {

std::string tail(const std::string& text, std::size_t lines) {
  std::size_t at = text.size();
  for (std::size_t n = 0; n <= lines; ++n) {  // one more: the text ends with a newline
    if (at == 0) return text;
    at = text.rfind('\n', at - 1);
    if (at == std::string::npos) return text;
  }
  return text.substr(at + 1);
}

std::string read_file(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

void expect_no_sanitizer_report(const std::string& log) {
  const std::string text = read_file(log);
  EXPECT_EQ(text.find("Sanitizer"), std::string::npos) << log << ":\n" << text;
  EXPECT_EQ(text.find("runtime error:"), std::string::npos) << log << ":\n" << text;
}

void E2eClientTest::open_client(const client::ClientOptions& options) {
  client_.reset();
  events_.clear();
  event_cursor_ = 0;
  client_ = std::make_unique<client::Client>(options);
}

client::CommandRequest E2eClientTest::request(const std::string& axis, const std::string& kind) const {
  client::CommandRequest r;
  r.axis = axis;
  r.kind = kind;
  return r;
}

client::CommandResult E2eClientTest::send(const client::CommandRequest& r, std::chrono::milliseconds timeout) {
  return client_->send(r, true, timeout);
}

client::CommandResult E2eClientTest::send(const std::string& axis, const std::string& kind,
                                          std::chrono::milliseconds timeout) {
  return send(request(axis, kind), timeout);
}

client::CommandResult E2eClientTest::start(const client::CommandRequest& r, std::chrono::milliseconds timeout) {
  return client_->send(r, false, timeout);
}

client::AxisState E2eClientTest::state(const std::string& axis) const {
  return client_->state(axis).value_or(client::AxisState{});
}

bool E2eClientTest::wait_axis(const std::string& axis, const std::function<bool(const client::AxisState&)>& done,
                              std::chrono::milliseconds timeout) {
  return client_->wait_until([&] {
    const auto s = client_->state(axis);
    return s && done(*s);
  }, timeout);
}

double E2eClientTest::stream_ramp(const std::string& axis, double speed, std::chrono::milliseconds duration) {
  constexpr auto kPeriod = 10ms;
  double target = state(axis).position;
  auto next = std::chrono::steady_clock::now();
  for (auto left = duration; left > 0ms; left -= kPeriod) {
    target += speed * std::chrono::duration<double>(kPeriod).count();
    const std::string error = client_->stream_setpoint(axis, {}, target, 0, 0);
    EXPECT_TRUE(error.empty()) << error;
    // The set-point generator's period (a controller's own clock), not a wait for the gateway.
    next += kPeriod;
    std::this_thread::sleep_until(next);
  }
  return target;
}

const std::vector<client::AxisEvent>& E2eClientTest::events() {
  for (auto& e : client_->events_since(event_cursor_)) events_.push_back(std::move(e));
  return events_;
}

bool E2eClientTest::wait_event(const std::string& axis, const std::string& kind, const std::string& what,
                               std::chrono::milliseconds timeout) {
  return client_->wait_until([&] {
    for (const auto& e : events()) {
      if (e.axis == axis && e.kind == kind &&
          (e.text.find(what) != std::string::npos || e.state.find(what) != std::string::npos))
        return true;
    }
    return false;
  }, timeout);
}

std::optional<client::BusStatus> E2eClientTest::bus_status(const std::string& bus) const {
  for (const auto& b : client_->buses())
    if (b.bus == bus) return b;
  return std::nullopt;
}

}  // namespace drivegate::test
