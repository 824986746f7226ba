#pragma once
// A command-line tool (drivegate-sim) as a child process of a test, with pipes on its stdin,
// stdout and stderr, started in the caller's network namespace (a NetnsScope around the
// constructor puts it into another): its lines read with a time limit, one command line written
// and its answer line read, its exit status after SIGTERM. Killed when the object goes. No
// GoogleTest here: failures to start throw std::runtime_error.
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "tests/support/pipe_lines.hpp"

extern char** environ;

namespace drivegate::test {

class ToolProcess {
 public:
  // Starts `program` with `args`.
  ToolProcess(const std::string& program, const std::vector<std::string>& args) {
    // A tool that ended must fail the test through its missing answers, not kill the test
    // process with SIGPIPE when a command is written to it.
    ::signal(SIGPIPE, SIG_IGN);
    int in[2];
    int out[2];
    int err[2];
    if (::pipe2(in, O_CLOEXEC) != 0 || ::pipe2(out, O_CLOEXEC) != 0 || ::pipe2(err, O_CLOEXEC) != 0) {
      throw std::runtime_error("pipe2 failed");
    }
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_adddup2(&actions, in[0], STDIN_FILENO);
    posix_spawn_file_actions_adddup2(&actions, out[1], STDOUT_FILENO);
    posix_spawn_file_actions_adddup2(&actions, err[1], STDERR_FILENO);
    std::vector<std::string> all{program};
    all.insert(all.end(), args.begin(), args.end());
    std::vector<char*> argv;
    for (auto& a : all) argv.push_back(a.data());
    argv.push_back(nullptr);
    const int spawned = posix_spawn(&pid_, argv[0], &actions, nullptr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    ::close(in[0]);
    ::close(out[1]);
    ::close(err[1]);
    stdin_ = in[1];
    stdout_ = out[0];
    stderr_ = err[0];
    if (spawned != 0) {
      pid_ = -1;
      throw std::runtime_error("cannot start " + program);
    }
  }
  ~ToolProcess() {
    if (pid_ > 0) {
      ::kill(pid_, SIGKILL);
      ::waitpid(pid_, nullptr, 0);
    }
    for (int fd : {stdin_, stdout_, stderr_}) {
      if (fd >= 0) ::close(fd);
    }
  }
  ToolProcess(const ToolProcess&) = delete;
  ToolProcess& operator=(const ToolProcess&) = delete;

  // The next line on stdout; nullopt when none came in time (or the tool ended).
  std::optional<std::string> line(std::chrono::milliseconds timeout = std::chrono::seconds(10)) {
    return out_.next(stdout_, timeout);
  }
  // Everything on stderr until it stays quiet for 2 s (or ends).
  std::string error_text() {
    std::string all;
    while (const auto l = err_.next(stderr_, std::chrono::milliseconds(2000))) all += *l + "\n";
    return all;
  }
  // Writes one command line and returns the next line on stdout (its answer).
  std::string command(const std::string& c) {
    const std::string l = c + "\n";
    if (::write(stdin_, l.data(), l.size()) != static_cast<ssize_t>(l.size())) return "(write failed)";
    return line(std::chrono::seconds(5)).value_or("(no answer)");
  }
  // Exit status after SIGTERM (or after it ended by itself); -1 when it did not end in 5 s.
  int stop(bool signal = true) {
    if (signal) ::kill(pid_, SIGTERM);
    for (const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(5); std::chrono::steady_clock::now() < end;) {
      int status = 0;
      if (::waitpid(pid_, &status, WNOHANG) == pid_) {
        pid_ = -1;
        return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
      }
      ::poll(nullptr, 0, 10);
    }
    return -1;
  }

 private:
  pid_t pid_ = -1;
  int stdin_ = -1;
  int stdout_ = -1;
  int stderr_ = -1;
  PipeLines out_;
  PipeLines err_;
};

}  // namespace drivegate::test
