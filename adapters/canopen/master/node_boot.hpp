#pragma once
// The configuration sequence of one node, run over the SDO client while the node is
// pre-operational: identity check, start-up writes, PDO configuration (written with the
// disable / clear count / entries / count / enable sequence, or only verified), error control.
// NMT (pre-operational before, start after) is the bus' business; this sequencer only walks the
// steps it was given, one SDO transfer at a time, and stops at the first failure with a sentence
// that names the step, the object and the abort text (issue: "reported with the step, object and
// abort text"). The bus retries a failed boot with back-off.
//
// The step list is built once (construction may allocate); start()/step() do not allocate.
#include <cstdint>
#include <string>
#include <vector>

#include "adapters/canopen/master/pdo.hpp"
#include "adapters/canopen/master/sdo_client.hpp"
#include "core/clock.hpp"
#include "core/fixed_string.hpp"
#include "profiles/cia402/objects.hpp"

namespace drivegate::canopen {

struct BootStep {
  enum class Kind : std::uint8_t {
    Write,   // write `value`
    Expect,  // read and compare (value & mask) == (expected & mask)
    Seed,    // read an RPDO-mapped object into the process image, so the first RPDOs carry the
             // drive's own values rather than zeros it may refuse (e.g. a 0 profile acceleration)
    Probe,   // read; the drive has the object: set the `sets` bits of found(). A missing object
             // (06020000h / 06090011h) leaves them clear; another abort fails the boot.
    Fail,    // fail the boot with `why` (a drive lacking what the plan demands, told by probes)
  };
  Kind kind = Kind::Write;
  cia402::ObjectDef def{};
  std::int64_t value = 0;        // Write: value; Expect: expected value
  std::uint32_t mask = 0xFFFFFFFF;
  bool optional = false;         // a missing object (06020000h / 06090011h) is not an error
  std::string stage;             // "identity", "start-up write", "RPDO1 mapping", "error control"
  std::string why;               // shown with a failure ("FBUS.PARAM05: fault reset only via ...")
  // Branches on what earlier Probe steps found: the step runs only when every `if_found` bit is
  // set in found() and every `if_missing` bit is clear; otherwise it is skipped.
  std::uint8_t sets = 0;
  std::uint8_t if_found = 0;
  std::uint8_t if_missing = 0;
  // Write: non-zero makes a refusal (any abort from the drive; a timeout still fails the boot)
  // a finding instead of a failure: found() loses these bits and gains `sets`, and refusal()
  // keeps the abort code. Later steps branch on it (a drive whose 1016h:01 takes no entry is
  // guarded instead).
  std::uint8_t refused = 0;
};

class NodeBoot {
 public:
  enum class Status : std::uint8_t { Idle, Running, Done, Failed };

  NodeBoot(int sdo_channel, std::vector<BootStep> steps);

  // Start (or restart) from the first step.
  void start() noexcept;
  // Drive the sequence: submit the next transfer, check the finished one (Seed steps store into
  // `image`). Returns the status.
  Status step(SdoClient& sdo, ProcessImage& image) noexcept;
  // Stop without a verdict (node lost mid-way): the transfer in flight is cancelled.
  void abandon(SdoClient& sdo) noexcept;

  [[nodiscard]] Status status() const noexcept { return status_; }
  [[nodiscard]] std::size_t position() const noexcept { return next_; }
  [[nodiscard]] std::size_t size() const noexcept { return steps_.size(); }
  [[nodiscard]] const core::FixedString<200>& failure() const noexcept { return failure_; }
  // The bits the Probe steps (and refused Write steps) of this run set: what the drive turned out
  // to have.
  [[nodiscard]] std::uint8_t found() const noexcept { return found_; }
  // The abort code of the last refused Write this run took as a finding (BootStep::refused), 0: none.
  [[nodiscard]] std::uint32_t refusal() const noexcept { return refusal_; }
  [[nodiscard]] const std::vector<BootStep>& steps() const noexcept { return steps_; }

 private:
  void fail_abort(const BootStep& s, std::uint32_t code) noexcept;

  int channel_;
  std::vector<BootStep> steps_;
  Status status_ = Status::Idle;
  std::size_t next_ = 0;
  std::uint8_t found_ = 0;
  std::uint32_t refusal_ = 0;
  SdoRequestId request_ = kNoSdoRequest;
  core::FixedString<200> failure_;
};

}  // namespace drivegate::canopen
