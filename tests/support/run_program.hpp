#pragma once
// Runs a program to completion without a shell and hands back its exit status and output, for
// tests and benchmarks that call tools (ip, tshark, ...). No GoogleTest here.
#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <string>
#include <vector>

namespace drivegate::test {

struct RunResult {
  int status = -1;  // exit status, or -1 when the program did not end normally
  std::string output;  // stdout and stderr
  [[nodiscard]] bool ok() const noexcept { return status == 0; }
};

// Runs argv[0] (looked up in PATH when it has no slash; 127 when it cannot be started) with
// argv[1..] and waits for it.
inline RunResult run_program(const std::vector<std::string>& argv) {
  RunResult result;
  if (argv.empty() || argv[0].empty()) {
    result.output = "no program";
    return result;
  }
  int pipefd[2];
  if (::pipe2(pipefd, O_CLOEXEC) != 0) {
    result.output = std::string("pipe2: ") + std::strerror(errno);
    return result;
  }
  std::vector<char*> args;
  for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  const pid_t pid = ::fork();
  if (pid < 0) {
    ::close(pipefd[0]);
    ::close(pipefd[1]);
    result.output = "fork failed";
    return result;
  }
  if (pid == 0) {
    ::dup2(pipefd[1], STDOUT_FILENO);
    ::dup2(pipefd[1], STDERR_FILENO);
    ::execvp(args[0], args.data());
    ::_exit(127);
  }
  ::close(pipefd[1]);
  char chunk[512];
  for (;;) {
    const ssize_t n = ::read(pipefd[0], chunk, sizeof chunk);
    if (n > 0) {
      result.output.append(chunk, static_cast<std::size_t>(n));
      continue;
    }
    if (n < 0 && errno == EINTR) continue;
    break;
  }
  ::close(pipefd[0]);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  result.status = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return result;
}

}  // namespace drivegate::test
