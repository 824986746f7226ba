#include "tests/canopen_e2e/sim_process.hpp"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace drivegate::test {

BusAddress unique_bus_address(unsigned slot) {
  // RTPS puts a DDS domain's ports at 7400 + 250 x domain + 0..~60 (participants of parallel tests
  // on domains 20..99: unique_dds()), bound without SO_REUSEADDR. The bus ports sit in the gaps
  // between those bands, at +120..+239, in 16270..19889: clear of the simulator process tests'
  // block (12000..15999) and the UDP transport tests' (20000..31999). Two tests may share a port:
  // the group differs per process (the transport turns IP_MULTICAST_ALL off).
  constexpr unsigned kFirstBand = 35;  // 7400 + 250 x 35 = 16150
  constexpr unsigned kBands = 15;
  constexpr unsigned kGap = 120;
  const auto pid = static_cast<unsigned>(::getpid());
  const unsigned index = (pid * 16 + slot) % (kBands * kGap);
  BusAddress a;
  a.port = static_cast<std::uint16_t>(7400 + 250 * (kFirstBand + index / kGap) + 120 + index % kGap);
  a.group = "239.201." + std::to_string((pid >> 8) & 0xFF) + "." + std::to_string(pid & 0xFF);
  return a;
}

using Clock = std::chrono::steady_clock;

SimProcess::SimProcess(const std::string& config) : log_path_(config + ".sim.log") {
  // A simulator that ended must fail the test through its missing answers, not kill the test
  // process with SIGPIPE when a command is written to it.
  ::signal(SIGPIPE, SIG_IGN);
  int in[2];
  int out[2];
  if (::pipe2(in, O_CLOEXEC) != 0) throw std::runtime_error(std::string("pipe2: ") + std::strerror(errno));
  if (::pipe2(out, O_CLOEXEC) != 0) {
    ::close(in[0]);
    ::close(in[1]);
    throw std::runtime_error(std::string("pipe2: ") + std::strerror(errno));
  }
  const pid_t parent = ::getpid();
  pid_ = ::fork();
  if (pid_ < 0) {
    for (int fd : {in[0], in[1], out[0], out[1]}) ::close(fd);
    throw std::runtime_error("fork failed");
  }
  if (pid_ == 0) {
    // See DaemonProcess: the simulator goes with the test that started it.
    ::prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (::getppid() != parent) ::_exit(127);
    const int log = ::open(log_path_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    ::dup2(in[0], STDIN_FILENO);
    ::dup2(out[1], STDOUT_FILENO);
    ::dup2(log, STDERR_FILENO);
    ::execl(DRIVEGATE_SIM_PATH, DRIVEGATE_SIM_PATH, config.c_str(), static_cast<char*>(nullptr));
    ::_exit(127);
  }
  ::close(in[0]);
  ::close(out[1]);
  stdin_ = in[1];
  stdout_ = out[0];
}

SimProcess::~SimProcess() {
  if (pid_ > 0) {
    ::kill(pid_, SIGKILL);
    ::waitpid(pid_, nullptr, 0);
  }
  ::close(stdin_);
  ::close(stdout_);
}

std::optional<std::string> SimProcess::next_line(std::chrono::milliseconds timeout) {
  return lines_.next(stdout_, timeout);
}

std::optional<std::string> SimProcess::wait_ready(std::chrono::milliseconds timeout) {
  return next_line(timeout);
}

std::string SimProcess::command(const std::string& line, std::chrono::milliseconds timeout) {
  const std::string l = line + "\n";
  if (::write(stdin_, l.data(), l.size()) != static_cast<ssize_t>(l.size())) return {};
  return next_line(timeout).value_or("");
}

bool SimProcess::wait_answer(const std::string& line, const std::function<bool(const std::string&)>& done,
                             std::chrono::milliseconds timeout, std::string& last) {
  for (const auto end = Clock::now() + timeout;;) {
    last = command(line, std::chrono::seconds(5));
    if (done(last)) return true;
    if (Clock::now() >= end) return false;
    ::poll(nullptr, 0, 20);  // the pace of the requests; each answer is the condition
  }
}

std::string SimProcess::log() const {
  std::ifstream in(log_path_);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

std::string node_status(const std::string& status, const std::string& bus, int node) {
  const std::string key = " " + bus + ":" + std::to_string(node) + " ";
  const auto at = status.find(key);
  if (at == std::string::npos) return {};
  const auto end = status.find(';', at);
  return status.substr(at + 1, end == std::string::npos ? std::string::npos : end - at - 1);
}

}  // namespace drivegate::test
