#pragma once
// CPU time of a process or thread from /proc (proc(5): fields 14 utime and 15 stime of
// /proc/PID/stat or /proc/PID/task/TID/stat), for the benchmarks that measure other processes.
#include <fstream>
#include <sstream>
#include <string>

namespace drivegate::bench {

// Clock ticks (sysconf(_SC_CLK_TCK) a second) of utime + stime in the stat file `path`; the name
// between the parentheses to `name`. 0 when the file cannot be read.
inline unsigned long long stat_ticks(const std::string& path, std::string* name = nullptr) {
  std::ifstream in(path);
  std::string text;
  std::getline(in, text);
  const auto open = text.find('(');
  const auto close = text.rfind(')');
  if (open == std::string::npos || close == std::string::npos) return 0;
  if (name != nullptr) *name = text.substr(open + 1, close - open - 1);
  std::istringstream rest(text.substr(close + 2));
  std::string field;
  unsigned long long utime = 0, stime = 0;
  for (int i = 3; i <= 15 && rest >> field; ++i) {
    if (i == 14) utime = std::stoull(field);
    if (i == 15) stime = std::stoull(field);
  }
  return utime + stime;
}

}  // namespace drivegate::bench
