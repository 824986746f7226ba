#pragma once
// The names of one slave's objects, read from the slave itself over CoE SDO Information
// [ETG.1000.6 §5.6.3]: Get OD List (all objects), then per object Get Object Description (name,
// object code, data type, highest sub-index) and, for arrays and records, Get Entry Description of
// each sub-index (name, data type, bit length). The table lets a client name a parameter of an axis
// that has no ESI file.
//
// Threads. The bus thread reads (start() when the slave reached OP, step() every cycle while it is
// in OP, stop() after its CoE client was reset); the control plane looks names up (find(), any
// thread, concurrently). The reading runs in the bus' cyclic path: everything it fills is
// allocated by the constructor (objects, entries, a name arena); the names are written straight
// into the arena by the CoE client. Records are appended and published by a release store of
// their count; a published record never changes until the next start(). start() empties the
// table only while no find() is reading it (a reader count and a "resetting" flag, both seq_cst:
// a reader that sees the flag reports the table as being read; the bus thread that sees a reader
// tries again next cycle), so a reader never sees a record rewritten under it.
//
// Client requests go first: a request is started only when the slave's CoE client has none queued
// or running, so a client's SDO waits at most for the one dictionary request in flight.
#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>

#include "adapters/ethercat/master/coe_sdo_client.hpp"
#include "core/param_value.hpp"

namespace drivegate::ethercat {

// Which of a multi-axis slave's objects belong to one axis (ETG.6010: the profile area 6000h..67FFh
// of axis n at + n x axis_offset); a single-axis slave: axes = 1.
struct DictionaryAxis {
  int slave_axis = 0;
  int axes = 1;
  std::uint16_t axis_offset = 0x800;
};

// A name looked up: found (the object as the axis numbers it, its type), or why not in words.
struct DictionaryMatch {
  bool found = false;
  std::uint16_t index = 0;
  std::uint8_t sub = 0;
  core::ParamType type = core::ParamType::Unknown;
  std::string error;
};

class SlaveDictionary {
 public:
  static constexpr std::size_t kMaxObjects = 2048;
  static constexpr std::size_t kMaxEntries = 4096;
  static constexpr std::size_t kNameBytes = 64 * 1024;
  static constexpr std::size_t kMaxName = 255;  // bytes asked for per name

  enum class State : std::uint8_t {
    NotYet,       // the slave has not been in OP yet
    Unsupported,  // its SII offers no SDO Information (or no CoE mailbox)
    Reading,
    Done,
    Full,         // more names than the table holds: the first ones are kept
    Failed,       // the OD list could not be read
  };

  // `position`: 1-based, for the sentences.
  explicit SlaveDictionary(std::uint16_t position);

  // --- bus thread ---
  // The slave reached OP: read it again from the start (`sdo_info`: its SII's CoE details offer
  // SDO Information). Returns false while a reader holds the table: call again next cycle.
  bool start(bool sdo_info) noexcept;
  // In OP, once per cycle: the next request when the client is otherwise idle.
  void step(CoeSdoClient& coe) noexcept;
  // The client was reset (the slave restarts or was lost): the request in flight is taken back.
  // The table stays readable until the next start().
  void stop(CoeSdoClient* coe) noexcept;

  // --- any thread ---
  [[nodiscard]] State state() const noexcept { return state_.load(std::memory_order_acquire); }
  // Objects of the OD list done (named or skipped) and listed, for "37 of 120 objects".
  [[nodiscard]] std::size_t progress() const noexcept { return progress_.load(std::memory_order_acquire); }
  [[nodiscard]] std::size_t listed() const noexcept { return listed_.load(std::memory_order_acquire); }
  // `name`: an object's name (a variable), or OBJECT:SUB (a sub-index of an array or record by its
  // entry name); letters compared without case, spaces and underscores alike, runs of them as one.
  [[nodiscard]] DictionaryMatch find(std::string_view name, const DictionaryAxis& axis) const;

 private:
  struct Object {
    std::uint16_t index = 0;
    std::uint16_t data_type = 0;
    std::uint8_t object_code = 0;
    std::uint8_t max_sub = 0;
    std::uint32_t first_entry = 0;
    std::uint32_t entry_count = 0;
    std::uint32_t name_at = 0;
    std::uint16_t name_size = 0;
  };
  struct Entry {
    std::uint8_t sub = 0;
    std::uint16_t data_type = 0;
    std::uint32_t name_at = 0;
    std::uint16_t name_size = 0;
  };
  enum class Step : std::uint8_t { List, Object, Entry };

  void take_result(CoeSdoClient& coe) noexcept;
  void next_object() noexcept;
  void finish(State s) noexcept;
  [[nodiscard]] std::span<char> name_room() noexcept;
  [[nodiscard]] std::string_view name_of(std::uint32_t at, std::uint16_t size) const noexcept {
    return {names_.get() + at, size};
  }
  // Under the reader guard: the published records.
  [[nodiscard]] DictionaryMatch lookup(std::string_view name, const DictionaryAxis& axis) const;

  std::uint16_t position_;
  std::unique_ptr<std::uint16_t[]> list_;
  std::unique_ptr<Object[]> object_;
  std::unique_ptr<Entry[]> entry_;
  std::unique_ptr<char[]> names_;

  // Bus thread only.
  Step step_ = Step::List;
  CoeSdoId id_ = 0;
  std::size_t listed_count_ = 0;  // indexes in list_
  std::size_t next_ = 0;          // list_ position of the object being read
  std::uint8_t sub_ = 0;          // the entry being read
  std::size_t entries_used_ = 0;
  std::size_t names_used_ = 0;
  Object building_{};

  // Shared.
  std::atomic<State> state_{State::NotYet};
  std::atomic<std::size_t> objects_{0};  // published objects (their entries and names too)
  std::atomic<std::size_t> listed_{0};
  std::atomic<std::size_t> progress_{0};
  std::atomic<std::uint32_t> failure_{0};  // the OD list's abort code (State::Failed)
  mutable std::atomic<int> readers_{0};
  std::atomic<bool> resetting_{false};
};

}  // namespace drivegate::ethercat
