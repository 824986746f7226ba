#pragma once
// The system's words for an errno value ("No such device"), for error lines a person reads.
#include <string>
#include <system_error>

namespace drivegate::core {

inline std::string errno_text(int e) { return std::system_category().message(e); }

}  // namespace drivegate::core
