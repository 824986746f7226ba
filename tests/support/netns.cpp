#include "tests/support/netns.hpp"

#include <dirent.h>
#include <fcntl.h>
#include <poll.h>
#include <sched.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <mutex>
#include <stdexcept>
#include <thread>

namespace drivegate::test {
namespace {

using Clock = std::chrono::steady_clock;

constexpr int kCapNetAdmin = 12;  // linux/capability.h
constexpr int kCapSysAdmin = 21;

std::string find_ip() {
  for (const char* dir : {"/usr/sbin", "/sbin", "/usr/bin", "/bin"}) {
    const std::string p = std::string(dir) + "/ip";
    if (::access(p.c_str(), X_OK) == 0) return p;
  }
  return {};
}

const std::string& ip_path() {
  static const std::string path = find_ip();
  return path;
}

bool has_capability(int cap) {
  std::ifstream in("/proc/self/status");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("CapEff:", 0) != 0) continue;
    const unsigned long long mask = std::strtoull(line.c_str() + 7, nullptr, 16);
    return ((mask >> cap) & 1U) != 0;
  }
  return false;
}

void must(const RunResult& r, const std::string& what) {
  if (!r.ok()) throw std::runtime_error(what + " failed: " + r.output);
}

// The pid in "dgt<pid>_...", or -1.
pid_t pid_of(const std::string& name) {
  const std::string prefix = kNetnsPrefix;
  if (name.rfind(prefix, 0) != 0) return -1;
  const auto under = name.find('_', prefix.size());
  if (under == std::string::npos || under == prefix.size()) return -1;
  pid_t pid = 0;
  for (std::size_t i = prefix.size(); i < under; ++i) {
    if (name[i] < '0' || name[i] > '9') return -1;
    pid = pid * 10 + (name[i] - '0');
  }
  return pid;
}

bool stale(const std::string& name) {
  const pid_t pid = pid_of(name);
  return pid > 0 && pid != ::getpid() && ::kill(pid, 0) != 0 && errno == ESRCH;
}

std::vector<std::string> entries(const char* dir) {
  std::vector<std::string> out;
  DIR* d = ::opendir(dir);
  if (d == nullptr) return out;
  while (const dirent* e = ::readdir(d)) out.emplace_back(e->d_name);
  ::closedir(d);
  return out;
}

void clean_stale_once() {
  static std::once_flag once;
  std::call_once(once, [] { remove_stale_net_objects(); });
}

int open_netns(const std::string& name) {
  const std::string path = "/run/netns/" + name;
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw std::runtime_error("open " + path + ": " + std::strerror(errno));
  return fd;
}

}  // namespace

RunResult run_ip(const std::vector<std::string>& args) {
  std::vector<std::string> argv{ip_path()};
  argv.insert(argv.end(), args.begin(), args.end());
  return run_program(argv);
}

const std::string& netns_unavailable() {
  static const std::string reason = [] () -> std::string {
    if (::geteuid() != 0 && !(has_capability(kCapNetAdmin) && has_capability(kCapSysAdmin))) {
      return "needs root (CAP_NET_ADMIN and CAP_SYS_ADMIN) to create network namespaces and veth pairs";
    }
    if (!has_capability(kCapNetAdmin)) return "needs CAP_NET_ADMIN to create veth pairs";
    if (!has_capability(kCapSysAdmin)) return "needs CAP_SYS_ADMIN to create and enter network namespaces";
    if (ip_path().empty()) return "the 'ip' program (iproute2) is missing";
    clean_stale_once();
    const std::string probe = unique_net_name('p');
    const RunResult add = run_ip({"netns", "add", probe});
    if (!add.ok()) return "cannot create a network namespace: " + add.output;
    run_ip({"netns", "del", probe});
    return {};
  }();
  return reason;
}

std::string unique_net_name(char kind) {
  static std::atomic<unsigned> counter{0};
  // "dgt" + pid (at most 7 digits, pid_max 4194304) + "_" + 3 digits + kind: 15 characters at most,
  // the limit of an interface name (IFNAMSIZ - 1).
  const unsigned n = counter.fetch_add(1) % 1000;
  return std::string(kNetnsPrefix) + std::to_string(::getpid()) + "_" + std::to_string(n) + kind;
}

int remove_stale_net_objects() {
  int removed = 0;
  for (const auto& name : entries("/run/netns")) {
    if (stale(name) && run_ip({"netns", "del", name}).ok()) ++removed;
  }
  for (const auto& name : entries("/sys/class/net")) {
    if (stale(name) && run_ip({"link", "del", name}).ok()) ++removed;
  }
  return removed;
}

NetNamespace::NetNamespace() {
  if (ip_path().empty()) throw std::runtime_error("the 'ip' program (iproute2) is missing");
  clean_stale_once();
  name_ = unique_net_name('n');
  must(run_ip({"netns", "add", name_}), "ip netns add " + name_);
  const RunResult lo = ip({"link", "set", "lo", "up"});
  if (!lo.ok()) {
    run_ip({"netns", "del", name_});
    throw std::runtime_error("ip -n " + name_ + " link set lo up failed: " + lo.output);
  }
}

NetNamespace::~NetNamespace() {
  // Interfaces inside go with the namespace once nothing holds it; a VethPair deletes its own first.
  run_ip({"netns", "del", name_});
}

RunResult NetNamespace::ip(const std::vector<std::string>& args) const {
  std::vector<std::string> a{"-n", name_};
  a.insert(a.end(), args.begin(), args.end());
  return run_ip(a);
}

NetnsScope::NetnsScope(const NetNamespace& ns) {
  saved_ = ::open("/proc/thread-self/ns/net", O_RDONLY | O_CLOEXEC);
  if (saved_ < 0) throw std::runtime_error(std::string("open /proc/thread-self/ns/net: ") + std::strerror(errno));
  const int target = open_netns(ns.name());
  const int r = ::setns(target, CLONE_NEWNET);
  const int e = errno;
  ::close(target);
  if (r != 0) {
    ::close(saved_);
    throw std::runtime_error("setns into " + ns.name() + ": " + std::strerror(e));
  }
}

NetnsScope::~NetnsScope() {
  if (::setns(saved_, CLONE_NEWNET) != 0) std::abort();  // a thread left in a test namespace would corrupt every later test
  ::close(saved_);
}

VethPair::VethPair(const NetNamespace* ns_a, const NetNamespace* ns_b)
    : ns_a_(ns_a), ns_b_(ns_b), a_(unique_net_name('a')), b_(a_.substr(0, a_.size() - 1) + "b") {
  clean_stale_once();
  create();
}

VethPair::~VethPair() {
  if (exists_) ip_in(End::A, {"link", "del", a_});
}

RunResult VethPair::ip_in(End e, const std::vector<std::string>& args) const {
  const NetNamespace* ns = e == End::A ? ns_a_ : ns_b_;
  return ns != nullptr ? ns->ip(args) : run_ip(args);
}

void VethPair::create() {
  // Both ends are made in this process's namespace and moved at once, so that they are there only
  // for the moment between the two commands (and remove_stale_net_objects() finds them after a crash).
  must(run_ip({"link", "add", a_, "type", "veth", "peer", "name", b_}), "ip link add " + a_);
  exists_ = true;
  if (ns_a_ != nullptr) must(run_ip({"link", "set", a_, "netns", ns_a_->name()}), "ip link set " + a_ + " netns");
  if (ns_b_ != nullptr) must(run_ip({"link", "set", b_, "netns", ns_b_->name()}), "ip link set " + b_ + " netns");
  // No IPv6 link-local address: without it the kernel sends no DAD, router solicitation or MLD
  // frames when the ends come up, so tests that count frames of other EtherTypes see only their
  // own. Best effort: where IPv6 is disabled there is nothing to suppress and `ip` refuses.
  for (const End e : {End::A, End::B}) ip_in(e, {"link", "set", name(e), "addrgenmode", "none"});
  set_up(End::A, true);
  set_up(End::B, true);
  wait_up();
}

void VethPair::wait_up(std::chrono::milliseconds timeout) const {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  for (;;) {
    bool up = true;
    for (const End e : {End::A, End::B}) {
      const RunResult r = ip_in(e, {"-o", "link", "show", "dev", name(e)});
      up = up && r.ok() && r.output.find("state UP") != std::string::npos;
    }
    if (up) return;
    if (std::chrono::steady_clock::now() >= deadline)
      throw std::runtime_error("veth pair " + a_ + "/" + b_ + " not operationally up after " +
                               std::to_string(timeout.count()) + " ms");
    // The operational state comes from the kernel's link watch: there is nothing to wait on.
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
}

void VethPair::remove() {
  if (!exists_) return;
  must(ip_in(End::A, {"link", "del", a_}), "ip link del " + a_);
  exists_ = false;
}

void VethPair::set_up(End e, bool up) const { set(e, {up ? "up" : "down"}); }

void VethPair::set(End e, const std::vector<std::string>& args) const {
  std::vector<std::string> a{"link", "set", name(e)};
  a.insert(a.end(), args.begin(), args.end());
  must(ip_in(e, a), "ip link set " + name(e));
}

ChildProcess::ChildProcess(const NetNamespace* ns, const std::function<int(int out)>& body) {
  int pipefd[2];
  if (::pipe2(pipefd, O_CLOEXEC) != 0) throw std::runtime_error(std::string("pipe2: ") + std::strerror(errno));
  // Opened before the fork so the child does not allocate for it.
  const int target = ns != nullptr ? open_netns(ns->name()) : -1;
  const pid_t parent = ::getpid();
  pid_ = ::fork();
  if (pid_ < 0) {
    ::close(pipefd[0]);
    ::close(pipefd[1]);
    if (target >= 0) ::close(target);
    throw std::runtime_error("fork failed");
  }
  if (pid_ == 0) {
    ::prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (::getppid() != parent) ::_exit(127);
    ::close(pipefd[0]);
    if (target >= 0 && ::setns(target, CLONE_NEWNET) != 0) {
      write_line(pipefd[1], std::string("setns: ") + std::strerror(errno));
      ::_exit(126);
    }
    ::_exit(body(pipefd[1]));
  }
  if (target >= 0) ::close(target);
  ::close(pipefd[1]);
  out_ = pipefd[0];
}

ChildProcess::~ChildProcess() {
  if (pid_ > 0 && !status_) {
    ::kill(pid_, SIGKILL);
    ::waitpid(pid_, nullptr, 0);
  }
  if (out_ >= 0) ::close(out_);
}

std::optional<std::string> ChildProcess::read_line(std::chrono::milliseconds timeout) {
  return out_ >= 0 ? lines_.next(out_, timeout) : std::nullopt;
}

std::optional<int> ChildProcess::wait(std::chrono::milliseconds timeout) {
  if (status_) return status_;
  // A pidfd would let poll() wait for the exit; waitpid(WNOHANG) paced at 5 ms keeps this portable.
  for (const auto end = Clock::now() + timeout;;) {
    int status = 0;
    const pid_t r = ::waitpid(pid_, &status, WNOHANG);
    if (r == pid_) {
      status_ = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
      return status_;
    }
    if (Clock::now() >= end) return std::nullopt;
    ::poll(nullptr, 0, 5);
  }
}

void write_line(int fd, const std::string& line) {
  const std::string l = line + "\n";
  std::size_t done = 0;
  while (done < l.size()) {
    const ssize_t n = ::write(fd, l.data() + done, l.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return;
    done += static_cast<std::size_t>(n);
  }
}

}  // namespace drivegate::test
