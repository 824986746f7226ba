#include "daemon/realtime.hpp"

#include <pthread.h>
#include <sched.h>
#include <sys/mman.h>
#include <sys/resource.h>

#include <cerrno>
#include <cstring>

namespace drivegate::daemon {
namespace {

std::string rlimit_text(int resource) {
  rlimit lim{};
  if (getrlimit(resource, &lim) != 0) return "unknown";
  if (lim.rlim_cur == RLIM_INFINITY) return "infinity";
  return std::to_string(lim.rlim_cur);
}

std::string allowed_cpus() {
  cpu_set_t set;
  CPU_ZERO(&set);
  if (sched_getaffinity(0, sizeof(set), &set) != 0) return "unknown";
  std::string out;
  for (std::size_t cpu = 0; cpu < CPU_SETSIZE; ++cpu) {
    if (!CPU_ISSET(cpu, &set)) continue;
    if (!out.empty()) out += ',';
    out += std::to_string(cpu);
  }
  return out;
}

void append(std::string& out, const std::string& message) {
  if (!out.empty()) out += "; ";
  out += message;
}

std::string set_affinity(int cpu) {
  if (cpu >= CPU_SETSIZE) {
    return "CPU " + std::to_string(cpu) + " does not exist (allowed CPUs: " + allowed_cpus() + ")";
  }
  cpu_set_t set;
  CPU_ZERO(&set);
  CPU_SET(static_cast<std::size_t>(cpu), &set);
  const int rc = pthread_setaffinity_np(pthread_self(), sizeof(set), &set);
  if (rc == 0) return {};
  if (rc == EINVAL) {
    return "CPU " + std::to_string(cpu) + " is not available to this process (allowed CPUs: " +
           allowed_cpus() + "; check CPUAffinity=/AllowedCPUs= of the service)";
  }
  return "cannot pin thread to CPU " + std::to_string(cpu) + ": " + std::strerror(rc);
}

std::string set_fifo(int priority) {
  if (priority > 99) return "SCHED_FIFO priority " + std::to_string(priority) + " is out of range 1..99";
  sched_param param{};
  param.sched_priority = priority;
  const int rc = pthread_setschedparam(pthread_self(), SCHED_FIFO, &param);
  if (rc == 0) return {};
  const std::string what = "cannot use SCHED_FIFO priority " + std::to_string(priority) + ": ";
  if (rc == EPERM) {
    // Without CAP_SYS_NICE the kernel allows RT priorities up to RLIMIT_RTPRIO only. As root
    // this can still fail when the cgroup has no RT runtime (CONFIG_RT_GROUP_SCHED).
    return what + "not permitted; needs CAP_SYS_NICE or RLIMIT_RTPRIO >= " + std::to_string(priority) +
           " (systemd: AmbientCapabilities=CAP_SYS_NICE or LimitRTPRIO=" + std::to_string(priority) +
           "; current RLIMIT_RTPRIO=" + rlimit_text(RLIMIT_RTPRIO) + "); running with normal scheduling";
  }
  return what + std::strerror(rc) + "; running with normal scheduling";
}

}  // namespace

std::string lock_memory() {
  if (mlockall(MCL_CURRENT | MCL_FUTURE) == 0) return {};
  const int err = errno;
  std::string message = std::string("cannot lock memory (mlockall: ") + std::strerror(err) + ")";
  if (err == EPERM || err == ENOMEM) {
    message += "; needs CAP_IPC_LOCK or a large enough RLIMIT_MEMLOCK (systemd: LimitMEMLOCK=infinity; "
               "current RLIMIT_MEMLOCK=" + rlimit_text(RLIMIT_MEMLOCK) + " bytes)";
  }
  return message + "; page faults may delay cycles";
}

std::string apply_thread_scheduling(int priority, int cpu) {
  std::string out;
  if (priority < 0) append(out, "SCHED_FIFO priority " + std::to_string(priority) + " is out of range 1..99");
  if (cpu >= 0) append(out, set_affinity(cpu));
  if (priority > 0) append(out, set_fifo(priority));
  return out;
}

void prefault_stack() noexcept {
  unsigned char stack[kPrefaultStackBytes];
  std::memset(stack, 0, sizeof(stack));
  // The array is never read: tell the compiler the memory escapes so the writes stay.
  asm volatile("" : : "r"(stack) : "memory");
}

}  // namespace drivegate::daemon
