#pragma once
// The acyclic parameter channel of one PROFIdrive drive object: a base-mode parameter request
// written to record 47 of slot 1 and its response read back from the same record, repeated until
// the drive has it ready [akd-profinet-profidrive.md §5.1, §24 step 8]. The PROFINET adapter
// implements it with IODWriteReq/IODReadReq; the PROFIdrive master builds and reads the bytes
// (param_access.hpp). Called only from the bus' cycle thread; nothing here may allocate or block.
#include <cstdint>
#include <span>
#include <string_view>

namespace drivegate::profidrive {

using ParamTicket = std::uint32_t;
inline constexpr ParamTicket kNoTicket = 0;

enum class ParamState : std::uint8_t {
  Pending,
  Done,     // `response` holds the record the drive answered with
  Failed,   // the exchange itself failed (RPC error, no answer); `error` says why
  Unknown,  // not a ticket the channel knows (never issued, already reported, cancelled)
};

struct ParamResult {
  ParamState state = ParamState::Unknown;
  std::span<const std::uint8_t> response;  // valid until the next call on the channel
  std::string_view error;                  // valid until the next call on the channel
};

class ParamChannel {
 public:
  // Start the write of `request` (copied before the call returns) and the read of its response.
  // kNoTicket when the channel is busy with another exchange (one at a time is enough) or down.
  virtual ParamTicket submit(std::span<const std::uint8_t> request) noexcept = 0;
  // Done and Failed are reported once; later polls of the ticket say Unknown.
  virtual ParamResult poll(ParamTicket ticket) noexcept = 0;
  // The result is no longer wanted (link lost, timeout): the channel frees itself for the next
  // request. A write already sent may still take effect. Unknown tickets are ignored.
  virtual void cancel(ParamTicket ticket) noexcept = 0;

 protected:
  ~ParamChannel() = default;
};

}  // namespace drivegate::profidrive
