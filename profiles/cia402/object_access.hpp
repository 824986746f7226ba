#pragma once
// How the CiA 402 profile reaches a drive's objects, whatever the bus (DESIGN.md §2 rule 3):
// a cyclic process image (CANopen PDOs, EtherCAT PDOs) and acyclic requests (CANopen SDO, CoE
// mailbox). The bus adapter implements it; the profile never sees frames.
//
// All calls happen on the bus' cycle thread and must not allocate or block.
#include <cstdint>
#include <span>
#include <string_view>

#include "profiles/cia402/objects.hpp"

namespace drivegate::cia402 {

using RequestId = std::uint32_t;
inline constexpr RequestId kNoRequest = 0;

enum class RequestState : std::uint8_t { Pending, Done, Failed, Unknown };

// A fault as the drive itself reported it outside the object dictionary (CANopen EMCY), with the
// text already resolved from the device profile's tables and vendor bytes.
struct DriveFaultReport {
  bool valid = false;
  std::uint16_t code = 0;
  std::string_view text;  // valid until the next cycle
};

struct RequestResult {
  RequestState state = RequestState::Unknown;
  std::int64_t value = 0;        // read result (sign-extended per the object's type)
  std::uint32_t abort_code = 0;  // CiA 301 SDO abort code or CoE equivalent when Failed
  std::uint32_t size = 0;        // submit_upload(): bytes the drive sent into the caller's buffer
  bool size_known = true;        // false: the drive did not say how many of them are the object's
                                 // (CANopen expedited upload without size, and no expected size)
};

// An object of the cyclic image resolved once (ObjectAccess::resolve()): the adapter's own index of
// it, so that an access in the cycle costs no lookup by object id. A reference belongs to the
// mapping it was resolved under: when the adapter lays its image out anew (a reconfiguration with
// another PDO mapping), mapping_generation() changes, read() of an older reference gives 0 and
// write() drops the value, and the user resolves its references again.
class ImageRef {
 public:
  constexpr ImageRef() noexcept = default;  // not mapped
  // What an adapter's resolve() hands out: its index of the object and its mapping_generation().
  [[nodiscard]] static constexpr ImageRef at(std::uint16_t slot, std::uint32_t generation) noexcept {
    ImageRef r;
    r.slot_ = slot;
    r.generation_ = generation;
    return r;
  }

  [[nodiscard]] constexpr std::uint16_t slot() const noexcept { return slot_; }
  [[nodiscard]] constexpr std::uint32_t generation() const noexcept { return generation_; }
  [[nodiscard]] constexpr bool mapped() const noexcept { return slot_ != kUnmapped; }
  // Mapped, and resolved under the adapter's present mapping.
  [[nodiscard]] constexpr bool current(std::uint32_t mapping_generation) const noexcept {
    return mapped() && generation_ == mapping_generation;
  }

 private:
  // Not an aggregate: a braced {index, sub} stays an ObjectId in read({0x6041, 0}).
  static constexpr std::uint16_t kUnmapped = 0xFFFF;
  std::uint16_t slot_ = kUnmapped;
  std::uint32_t generation_ = 0;
};

class ObjectAccess {
 public:
  virtual ~ObjectAccess() = default;

  // --- Cyclic process image ---
  // Where the object travels in the cyclic image (either direction); !mapped() when it does not.
  [[nodiscard]] virtual ImageRef resolve(ObjectId id) const noexcept = 0;
  // Changes whenever references resolved before stop being valid (see ImageRef).
  [[nodiscard]] virtual std::uint32_t mapping_generation() const noexcept = 0;
  // Latest value received from the drive for a mapped input object (statusword, actuals, ...); an
  // output reads back as last written. 0 for a reference that is not mapped or not current.
  [[nodiscard]] virtual std::int64_t read(ImageRef ref) const noexcept = 0;
  // Value for a mapped output object; sent with the next cycle's outputs. Dropped for a reference
  // that is not mapped or not current.
  virtual void write(ImageRef ref, std::int64_t value) noexcept = 0;
  // The same by object id, one lookup each: for objects the caller does not access every cycle.
  [[nodiscard]] bool mapped(ObjectId id) const noexcept { return resolve(id).mapped(); }
  [[nodiscard]] std::int64_t read(ObjectId id) const noexcept { return read(resolve(id)); }
  void write(ObjectId id, std::int64_t value) noexcept { write(resolve(id), value); }
  // True when the inputs were refreshed by the drive during the current cycle.
  [[nodiscard]] virtual bool inputs_fresh() const noexcept = 0;

  // --- Acyclic requests ---
  // Returns kNoRequest when the adapter's request queue is full (try again next cycle).
  virtual RequestId submit_read(ObjectDef def) noexcept = 0;
  virtual RequestId submit_write(ObjectDef def, std::int64_t value) noexcept = 0;
  // Objects of any size as bytes (parameters: strings, domains, 64-bit values). The upload puts
  // the drive's bytes into `into` (a longer object fails: CiA 301 abort 05040005h, out of memory);
  // `expected_size` (1..4, or 0) is the object's size when the caller knows it, for drives that
  // answer an expedited upload without a size (stoeber-sd6-canopen.md §6.4). The download sends
  // `data` as it is. The caller's buffer stays in use until poll() reports Done or Failed, or until
  // cancel(); a cancelled transfer in the middle of a segmented exchange is aborted on the bus.
  virtual RequestId submit_upload(ObjectId id, std::span<std::uint8_t> into, std::uint8_t expected_size) noexcept = 0;
  virtual RequestId submit_download(ObjectId id, std::span<const std::uint8_t> data) noexcept = 0;
  // Done/Failed results are reported once and then forgotten (later polls say Unknown).
  virtual RequestResult poll(RequestId id) noexcept = 0;
  // The caller no longer wants the result of `id` (command superseded or failed, link lost): the
  // adapter frees the request's slot at once. A write already sent to the drive may still take
  // effect. Unknown ids and kNoRequest are ignored; later polls of `id` say Unknown.
  virtual void cancel(RequestId id) noexcept = 0;

  // --- What the bus owns ---
  // Non-empty when the adapter configured `id` itself and depends on it (CANopen: PDO
  // communication and mapping, SYNC, EMCY, error control, the start-up writes; EtherCAT and
  // PROFINET: their equivalents): what it is and who owns it, for a refusal of a client's write.
  // A write there would take the drive out of the gateway's control (DESIGN.md §4).
  [[nodiscard]] virtual std::string_view owner_of(ObjectId /*id*/) const noexcept { return {}; }
  // The drive does not follow the controlword the gateway sends (the profile's supervision found
  // it). The adapter takes over: it marks the link degraded, stops the drive over the acyclic
  // channel and then reconfigures it, so the axis comes back disabled. Called once per loss.
  virtual void control_lost(std::string_view /*why*/) noexcept {}

  // --- Diagnostics ---
  // The drive's present fault as it announced it (EMCY), if the bus has such a channel. The
  // master prefers it to reading 603Fh, which some drives lack (NORD digest §9).
  [[nodiscard]] virtual DriveFaultReport fault_report() const noexcept { return {}; }
};

}  // namespace drivegate::cia402
