#pragma once
// Whole lines read from a pipe with a time limit: what a test reads of a child process's output.
#include <poll.h>
#include <unistd.h>

#include <chrono>
#include <optional>
#include <string>

namespace drivegate::test {

class PipeLines {
 public:
  // The next line from `fd` (without its newline); nullopt when none came within `timeout`, or the
  // writer closed the pipe (the child ended).
  std::optional<std::string> next(int fd, std::chrono::milliseconds timeout) {
    const auto end = std::chrono::steady_clock::now() + timeout;
    for (;;) {
      if (const auto nl = buffer_.find('\n'); nl != std::string::npos) {
        std::string line = buffer_.substr(0, nl);
        buffer_.erase(0, nl + 1);
        return line;
      }
      const auto left =
          std::chrono::duration_cast<std::chrono::milliseconds>(end - std::chrono::steady_clock::now()).count();
      if (left <= 0) return std::nullopt;
      pollfd p{fd, POLLIN, 0};
      if (::poll(&p, 1, static_cast<int>(left)) <= 0) continue;
      char chunk[512];
      const ssize_t n = ::read(fd, chunk, sizeof chunk);
      if (n <= 0) return std::nullopt;
      buffer_.append(chunk, static_cast<std::size_t>(n));
    }
  }

 private:
  std::string buffer_;
};

}  // namespace drivegate::test
