#pragma once
// Process data (CiA 301 §7.2.2): the byte layout of a mapped PDO, the per-node process image the
// CiA 402 profile reads and writes, and the master's PDO exchange: RPDOs sent right after each
// SYNC (or on change/event timer for event-driven ones), TPDOs received with their time stamp and
// a length check.
//
// Length rules for received TPDOs [CiA 301 §7.2.2.2; EMCY 8210h/8220h]: a frame shorter than its
// mapping is dropped and counted (short); a longer one is used and counted (long), because some
// drives pad to 8 bytes (NORD: RxPDO1 sent with DLC 8 although 5 bytes are mapped,
// nord-sk500p-ds402.md §8.1).
#include <array>
#include <cstdint>
#include <optional>
#include <span>

#include "adapters/canopen/master/tx_queue.hpp"
#include "adapters/canopen/wire/can_frame.hpp"
#include "adapters/canopen/wire/cob_id.hpp"
#include "adapters/canopen/wire/pdo_mapping.hpp"
#include "core/clock.hpp"
#include "profiles/cia402/objects.hpp"

namespace drivegate::canopen {

inline constexpr std::size_t kMaxPdoEntries = 8;
inline constexpr std::size_t kPdosPerDirection = 4;

// One mapped object inside a PDO.
struct PdoField {
  cia402::ObjectDef def{};
  std::uint8_t offset = 0;  // byte offset in the frame
};

// A PDO's layout, built from its mapping entries. Only byte-granular objects of 8, 16 or 32 bits.
struct PdoLayout {
  std::array<PdoField, kMaxPdoEntries> fields{};
  std::uint8_t count = 0;
  std::uint8_t bytes = 0;  // mapped length

  enum class Error : std::uint8_t { None, TooManyEntries, TooLong, BadLength };
  // Appends an object; fails (and leaves the layout unchanged) past 8 entries or 8 bytes, or for a
  // bit length that is not 8/16/32 or does not match the type's size.
  Error add(cia402::ObjectDef def, std::uint8_t bits) noexcept;
};
const char* to_string(PdoLayout::Error e) noexcept;

// Values of the objects a node exchanges cyclically, by ObjectId (linear search over <= 64
// entries; the image is small and the search cache-friendly) or by the entry's index, which
// index_of() gives and which stays put until the image is replaced.
class ProcessImage {
 public:
  static constexpr std::size_t kCapacity = 2 * kPdosPerDirection * kMaxPdoEntries;
  static constexpr std::size_t kNotFound = kCapacity;

  // Registers an object (construction phase); false when full, or when the object is already
  // registered with another type. Duplicates are merged.
  bool add(cia402::ObjectDef def) noexcept;
  [[nodiscard]] std::size_t index_of(cia402::ObjectId id) const noexcept;  // kNotFound when absent
  [[nodiscard]] bool contains(cia402::ObjectId id) const noexcept { return index_of(id) != kNotFound; }
  [[nodiscard]] std::int64_t get(cia402::ObjectId id) const noexcept { return get_at(index_of(id)); }
  void set(cia402::ObjectId id, std::int64_t value) noexcept { set_at(index_of(id), value); }
  // By index (0 / ignored past the registered entries).
  [[nodiscard]] std::int64_t get_at(std::size_t index) const noexcept {  // sign-extended per type
    return index < size_ ? entries_[index].value : 0;
  }
  void set_at(std::size_t index, std::int64_t value) noexcept;  // truncated to the type

  // Encode the fields of `layout` into `out` (little-endian); decode them from `in`.
  void pack(const PdoLayout& layout, std::span<std::uint8_t, 8> out) const noexcept;
  void unpack(const PdoLayout& layout, std::span<const std::uint8_t> in) noexcept;

 private:
  struct Entry {
    cia402::ObjectDef def{};
    std::int64_t value = 0;
  };
  std::array<Entry, kCapacity> entries_{};
  std::size_t size_ = 0;
};

struct RpdoConfig {  // master -> drive
  std::uint32_t cob_id = 0;
  PdoLayout layout;
  std::uint8_t transmission_type = 1;  // 0..240: sent after a SYNC; 254/255: on change / event timer
  core::Duration event_timer{};        // 254/255: resend at least this often (0 = only on change)
  std::uint8_t dlc = 0;                // frame length to send (0 = the mapped length; NORD pads to 8)
  // 0..240: zero sends the RPDO after every SYNC. Above zero, after a SYNC only when its bytes
  // changed, and unchanged at least this often. A drive acts on a synchronous RPDO at the SYNC
  // after it arrives and keeps the last one it had [CiA 301, RPDO communication parameter
  // 1400h:02: for an RPDO, types 0..240 all mean "synchronous"; type 0 is the producer's
  // "acyclic: only when changed"]; the bounded refresh repairs a lost frame and feeds drives
  // that watch RPDO arrival (1400h:05).
  core::Duration refresh{};
};

struct TpdoConfig {  // drive -> master
  std::uint32_t cob_id = 0;
  PdoLayout layout;
  std::uint8_t transmission_type = 1;  // 1..240: expected every n-th SYNC; 254/255: event-driven
  core::Duration event_timer{};        // event-driven: the drive sends at least this often
};

struct PdoCounters {
  std::uint64_t rpdos_sent = 0;
  std::uint64_t tpdos_received = 0;
  std::uint64_t short_frames = 0;  // dropped
  std::uint64_t long_frames = 0;   // used, counted
  std::uint64_t missed = 0;        // synchronous TPDO that did not arrive in its cycle
  std::uint64_t tx_full = 0;
  std::uint64_t ignored = 0;       // on a TPDO COB-ID while not enabled, RTRs, DLC > 8 (dropped)
};

// The PDOs of one node.
class NodePdos {
 public:
  // Replace the configuration (construction or after a reboot). Registers every mapped object in
  // the image; objects mapped before and after keep their value. Returns false (and keeps the old
  // configuration) when the image is full, or for more than kPdosPerDirection PDOs per direction, a
  // COB-ID that is not an 11-bit id, a transmission type 241..253 (RTR-only TPDOs: no reference
  // drive answers RTRs, AKD part 1 quirk 7), or an RPDO dlc shorter than its mapping or above 8.
  bool configure(std::span<const RpdoConfig> rpdos, std::span<const TpdoConfig> tpdos) noexcept;
  void enable(bool on, core::TimePoint now) noexcept;  // PDOs flow only while the node is operational
  [[nodiscard]] bool enabled() const noexcept { return enabled_; }

  ProcessImage& image() noexcept { return image_; }
  [[nodiscard]] const ProcessImage& image() const noexcept { return image_; }
  // Counts the images configure() put in place: an index into an older one is meaningless.
  [[nodiscard]] std::uint32_t image_generation() const noexcept { return image_generation_; }

  // After a SYNC: queue the synchronous RPDOs (each unless its refresh lets an unchanged one wait)
  // and the due event-driven ones. Until the drive's first TPDO since enable() (it may not be
  // operational yet and drop what it gets), every synchronous RPDO goes after every SYNC.
  void after_sync(core::TimePoint now, TxQueue& tx) noexcept;
  // Without SYNC (or between SYNCs): event-driven RPDOs whose data changed or whose timer ran out.
  void poll(core::TimePoint now, TxQueue& tx) noexcept;
  // When an event-driven RPDO is due: at once when it was not sent since enable(), else when its
  // event timer runs out (TimePoint::max() when none is running). Changed data is found by poll()
  // itself, so the bus polls at least once per cycle anyway.
  [[nodiscard]] core::TimePoint next_deadline() const noexcept;
  // A TPDO of this node (returns false for other COB-IDs). `now` is the frame's reception time.
  bool on_frame(const CanFrame& frame, core::TimePoint now) noexcept;

  // False while not enabled. Else true when every synchronous TPDO arrived since the last
  // after_sync() and every event-driven one within twice its event timer (or at all, when it has
  // none). A TPDO of type n > 1 counts as arrived in the n - 1 cycles after its frame, when it is
  // not due; type 0 (sent on SYNC only when the drive's data changed) counts like an event-driven
  // one without a timer.
  [[nodiscard]] bool inputs_fresh(core::TimePoint now) const noexcept;
  [[nodiscard]] core::TimePoint last_received() const noexcept { return last_rx_; }
  // Reception time of TPDO `index` (0..tpdo count-1), TimePoint{} before the first one.
  [[nodiscard]] core::TimePoint last_received(std::size_t index) const noexcept;

  [[nodiscard]] const PdoCounters& counters() const noexcept { return counters_; }

 private:
  struct RpdoState {
    RpdoConfig config;
    std::array<std::uint8_t, 8> sent{};  // bytes of the last frame sent (change detection)
    core::TimePoint sent_at{};
    bool ever_sent = false;
  };
  struct TpdoState {
    TpdoConfig config;
    core::TimePoint received_at{};
    bool seen = false;        // a frame arrived since enable()
    bool due = false;         // synchronous: a frame is expected before the next SYNC
    bool stale = false;       // synchronous: no frame since the last SYNC at which one was due
    std::uint8_t countdown = 0;  // synchronous: SYNCs until the next one is due
  };

  void restart() noexcept;
  void send_event_driven(core::TimePoint now, TxQueue& tx) noexcept;
  void send(RpdoState& r, const std::array<std::uint8_t, 8>& bytes, core::TimePoint now, TxQueue& tx) noexcept;

  ProcessImage image_;
  std::uint32_t image_generation_ = 0;
  bool enabled_ = false;
  core::TimePoint last_rx_{};
  PdoCounters counters_;
  std::array<RpdoState, kPdosPerDirection> rpdos_{};
  std::array<TpdoState, kPdosPerDirection> tpdos_{};
  std::size_t rpdo_count_ = 0;
  std::size_t tpdo_count_ = 0;
};

}  // namespace drivegate::canopen
