#pragma once
// CoE SDO client of one slave over its mailbox [ETG.1000.6 §5.6.2 SDO, mailbox header and counter;
// ETG.1000.4 §6 SyncManager (1-buffer mode, SM status "mailbox full", repeat request/acknowledge)]:
//
//   drain:    before a request is written (and once after a timeout), FPRD 080Dh; while SM1 is
//             "mailbox full", FPRD of SM1 and drop what it held (a late reply of an earlier request,
//             counted in stale_replies; an emergency there still goes to the EmergencySink), so a
//             late reply is never taken as the answer to the next request.
//   request:  FPWR of the whole SM0 buffer (mailbox out); WKC 0 = the slave has not read the last
//             one yet: written again at the next poll. The counter runs 1..7 per new message; a
//             write sent again keeps its counter.
//   reply:    FPRD 080Dh (SM1 status) at most once per poll_interval until "mailbox full" (bit 3),
//             then FPRD of the whole SM1 buffer (mailbox in).
//   lost reply: the slave freed SM1 when it was read, but the frame did not come back: read SM1's
//             activate and PDI control bytes (080Eh/080Fh), write the activate byte back with the
//             repeat request (bit 1) inverted, poll until the slave's repeat acknowledge (080Fh
//             bit 1) equals it, then read SM1 again: the slave has put the last reply back. The bit
//             is taken from the slave each time (another master or a restart may have left it set).
//   transfers: expedited / normal / segmented upload and download, toggle checked; a server abort
//             fails the request with its code (cia402::sdo_abort_text() for the words).
//   emergencies (CoE service 1) arriving in the mailbox go to the EmergencySink, any time; while
//             no request runs, SM1 status is read every idle_poll_interval for them.
//   SDO Information [ETG.1000.6 §5.6.3]: Get OD List (the indexes of one list type), Get Object
//             Description and Get Entry Description (fixed fields and the name), through the same
//             queue, mailbox handling and timeout as the transfers. A response may come in
//             fragments (§5.6.3.2: "incomplete" bit, fragments left counting down): their data is
//             one byte stream, joined in order; a fragment out of order fails the request
//             (08000000h), an SDO Info Error request (§5.6.3.7) fails it with its abort code. The
//             indexes go into the caller's array (more than it holds: 05040005h); a name longer
//             than the caller's buffer is cut (CoeSdoInfo::name_truncated).
//
// One request in flight per slave, a FIFO of kQueueDepth. Each request has a timeout from its
// start: then it fails with 05040000h (SDO protocol timed out); nothing is sent to the slave (its
// late reply, if any, is read and dropped by the drain, counted in stale_replies). Uploads go into the caller's buffer (or
// the request's 8 inline bytes); a reply longer than the buffer fails with 05040005h (out of
// memory). A normal upload whose response does not state the size fails with 05040001h (ETG.1000.6
// §5.6.2.4 makes the complete size part of it), one whose segments end before (after) the stated
// size with 06070013h (06070012h). Downloads come from the caller's buffer (must stay valid until the result is taken) or
// 1..4 inline bytes (download_value). Nothing allocates.
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "adapters/ethercat/master/transactions.hpp"
#include "adapters/ethercat/wire/mailbox.hpp"
#include "adapters/ethercat/wire/sii.hpp"
#include "core/clock.hpp"

namespace drivegate::ethercat {

class EmergencySink {
 public:
  virtual void on_emergency(std::uint16_t station, const CoeEmergency& e) noexcept = 0;

 protected:
  EmergencySink() = default;
  EmergencySink(const EmergencySink&) = default;
  EmergencySink& operator=(const EmergencySink&) = default;
  ~EmergencySink() = default;
};

struct CoeSdoTiming {
  core::Duration timeout = std::chrono::seconds(1);             // per request
  core::Duration poll_interval = std::chrono::milliseconds(1);  // SM1 status reads at most this often
  // While nothing is asked, SM1 is read only for emergencies: this often, on a grid staggered by
  // station address so that a line's slaves spread their reads over the interval instead of
  // adding one datagram per slave to every cycle. A drive's fault shows in its statusword at
  // once; the emergency only adds the code, so 10 ms is soon enough (IgH and SOEM read
  // emergencies only when they read the mailbox for something else).
  core::Duration idle_poll_interval = std::chrono::milliseconds(10);
};

using CoeSdoId = std::uint32_t;  // 0 = refused
enum class CoeSdoStatus : std::uint8_t { Unknown, Queued, InFlight, Done, Failed };
std::string_view to_string(CoeSdoStatus s) noexcept;

// SDO Information fields of a finished object or entry description request.
struct CoeSdoInfo {
  std::uint16_t data_type = 0;      // object: of the variable / of the elements; entry: its own
  std::uint8_t max_subindex = 0;    // object
  std::uint8_t object_code = 0;     // object: 7 variable, 8 array, 9 record (object_code::)
  std::uint16_t bit_length = 0;     // entry
  std::uint16_t object_access = 0;  // entry (object_access::)
  std::uint8_t value_info = 0;      // entry: what the response holds (value_info::)
  std::uint32_t unit_type = 0;      // entry, with value_info::kUnitType
  bool name_truncated = false;      // the name did not fit the caller's buffer
};

struct CoeSdoResult {
  CoeSdoStatus status = CoeSdoStatus::Unknown;
  std::uint32_t abort_code = 0;      // Failed: the server's code, 05040000h timeout, 05030000h toggle, ...
  std::uint16_t mailbox_error = 0;   // Failed by a mailbox error reply (its detail code), else 0
  std::size_t size = 0;              // uploads: bytes received
  std::uint32_t value = 0;           // uploads of 1..4 bytes: little-endian value
  // SDO Information: od_list() the number of indexes in `size`; object/entry descriptions the
  // name's bytes in `size` and the fields here.
  CoeSdoInfo info{};
};

struct CoeSdoCounters {
  std::uint64_t requests = 0, completed = 0, failed = 0, timeouts = 0, aborts = 0;
  std::uint64_t mailbox_writes = 0, mailbox_busy = 0;  // writes, and those the slave refused (WKC 0)
  std::uint64_t repeats = 0;                            // repeat requests after a lost reply
  std::uint64_t emergencies = 0, unexpected = 0, malformed = 0, queue_full = 0;
  std::uint64_t stale_replies = 0;  // found in SM1 before a request (or while idle) and dropped
};

class CoeSdoClient final : public DatagramOwner {
 public:
  static constexpr std::size_t kQueueDepth = 8;
  static constexpr std::size_t kMaxMailbox = 1024;  // SM0/SM1 sizes beyond this are refused (valid() false)
  static constexpr std::size_t kInline = 8;

  CoeSdoClient(std::uint16_t station, const SiiMailbox& mailbox, CoeSdoTiming timing = {},
               EmergencySink* emergencies = nullptr) noexcept;
  // The mailbox sizes can carry an SDO (at least 16 bytes each) and fit kMaxMailbox.
  [[nodiscard]] bool valid() const noexcept { return valid_; }

  CoeSdoId upload(std::uint16_t index, std::uint8_t subindex, std::span<std::uint8_t> into) noexcept;
  CoeSdoId upload_value(std::uint16_t index, std::uint8_t subindex) noexcept;  // up to 8 bytes inline
  CoeSdoId download(std::uint16_t index, std::uint8_t subindex, std::span<const std::uint8_t> data) noexcept;
  CoeSdoId download_value(std::uint16_t index, std::uint8_t subindex, std::uint32_t value, std::size_t size) noexcept;

  // SDO Information [ETG.1000.6 §5.6.3.3-§5.6.3.6]. The buffers must stay valid until the result
  // is taken. od_list: the indexes of `type` (not Lengths) into `into`, result.size of them.
  CoeSdoId od_list(OdListType type, std::span<std::uint16_t> into) noexcept;
  // The object's name into `name` (result.size bytes, not terminated), its fields in result.info.
  CoeSdoId object_description(std::uint16_t index, std::span<char> name) noexcept;
  // The entry's name and fields; `value_info` asks for unit type (kept), default/min/max (read
  // past, not kept).
  CoeSdoId entry_description(std::uint16_t index, std::uint8_t subindex, std::span<char> name,
                             std::uint8_t value_info = 0) noexcept;

  [[nodiscard]] CoeSdoResult result(CoeSdoId id) const noexcept;
  [[nodiscard]] std::span<const std::uint8_t> data(CoeSdoId id) const noexcept;  // upload bytes
  CoeSdoResult take(CoeSdoId id) noexcept;  // frees a finished request

  // The slave was re-initialised (LineBoot took it through INIT again, or it lost power): every
  // queued or running request fails with 08000022h (present device state), the mailbox state is
  // dropped (reply counter memory, repeat bit, a datagram in flight is ignored when it comes).
  // Finished results stay until taken. Callers that re-run LineBoot (start() or a transition
  // through INIT) call this for each of the slave's clients.
  void reset() noexcept;

  void poll(core::TimePoint now, Transactions& tx) noexcept;
  void on_result(std::uint32_t tag, const DatagramAnswer& answer) noexcept override;

  [[nodiscard]] const CoeSdoCounters& counters() const noexcept { return counters_; }
  [[nodiscard]] bool idle() const noexcept { return phase_ == Phase::Idle; }
  // Requests queued or running (a background reader waits for 0 so that others go first).
  [[nodiscard]] std::size_t pending() const noexcept;

 private:
  enum class SlotState : std::uint8_t { Free, Queued, InFlight, Done, Failed };
  enum class Kind : std::uint8_t { Sdo, OdList, Object, Entry };
  struct Slot {
    SlotState state = SlotState::Free;
    Kind kind = Kind::Sdo;
    bool upload = true;
    std::uint16_t generation = 0;
    std::uint64_t order = 0;
    std::uint16_t index = 0;
    std::uint8_t subindex = 0;
    std::uint8_t* into = nullptr;          // upload target (caller's or inline)
    const std::uint8_t* from = nullptr;    // download source (caller's or inline)
    std::size_t capacity = 0;              // of into / size of from
    std::size_t done = 0;                  // bytes received / sent
    std::size_t total = 0;                 // uploads: the size the server stated
    std::array<std::uint8_t, kInline> inline_bytes{};
    // SDO Information: the caller's index array or name buffer (capacity is its length), the list
    // type or value info asked for, and the fragment state.
    std::uint16_t* indexes = nullptr;
    char* name = nullptr;
    std::uint16_t list_type = 0;
    std::uint8_t value_info = 0;
    bool first_fragment = true;
    std::uint16_t fragments_left = 0;  // as the last fragment said
    bool odd = false;                  // an index byte waits for its high byte (next fragment)
    std::uint8_t odd_byte = 0;
    CoeSdoResult result{};
  };
  enum class Phase : std::uint8_t { Idle, Drain, DrainRead, Write, Wait, Read, RepeatRead, RepeatWrite, RepeatWait };
  enum class Expect : std::uint8_t { Initiate, Segment };

  CoeSdoId submit(bool upload, std::uint16_t index, std::uint8_t subindex, std::uint8_t* into,
                  const std::uint8_t* from, std::size_t size) noexcept;
  [[nodiscard]] const Slot* find(CoeSdoId id) const noexcept;
  void start_next(core::TimePoint now) noexcept;
  // Writes the next request into out_ (zeroed, the SM0 mailbox size) with `encode(out)`, which
  // returns the bytes encoded (0: failed, the transfer fails at the next poll), and moves to Write.
  template <class Encode>
  void prepare(Expect expect, Encode&& encode) noexcept;
  void prepare_initiate(Slot& s) noexcept;
  void prepare_download_segment(Slot& s) noexcept;
  void prepare_upload_segment() noexcept;
  // `stale`: read by the drain; only emergencies are taken from it.
  void on_mailbox(std::span<const std::uint8_t> mb, bool stale) noexcept;
  void on_status(const DatagramAnswer& a) noexcept;  // an SM1 status read while idle or draining
  void on_sdo(Slot& s, const CoeSdo& sdo) noexcept;
  CoeSdoId submit_info(Kind kind, std::uint16_t index, std::uint8_t subindex, std::size_t capacity) noexcept;
  // An SDO Information message for the active request: `mb` the whole mailbox, `body` its CoE data.
  void on_info(Slot& s, std::span<const std::uint8_t> mb, std::span<const std::uint8_t> body) noexcept;
  void take_indexes(Slot& s, std::span<const std::uint8_t> bytes) noexcept;
  void take_name(Slot& s, std::span<const std::uint8_t> bytes) noexcept;
  void finish(Slot& s, SlotState state, std::uint32_t abort_code) noexcept;
  bool queue(Transactions& tx, Command c, std::uint16_t ado, std::uint16_t length,
             std::span<const std::uint8_t> data = {}) noexcept;

  [[nodiscard]] core::TimePoint next_idle_poll(core::TimePoint now) const noexcept;

  std::uint16_t station_;
  SiiMailbox mailbox_;
  CoeSdoTiming timing_;
  EmergencySink* emergencies_;
  bool valid_ = false;

  // The state poll() reads every cycle first, the request slots and buffers after it.
  std::size_t queued_ = 0;  // slots Queued: start_next() looks for the oldest only then
  std::uint64_t next_order_ = 0;
  Slot* active_ = nullptr;
  Phase phase_ = Phase::Idle;
  Expect expect_ = Expect::Initiate;
  bool toggle_ = false;
  bool waiting_ = false;        // a datagram of ours is in flight
  std::uint16_t seq_ = 0;
  bool write_due_ = false;
  std::uint8_t counter_ = 0;    // mailbox counter of the last message written
  std::uint8_t last_reply_counter_ = 0;
  std::uint8_t repeat_activate_ = 0;  // SM1 activate byte written for the repeat request
  bool drain_due_ = false;      // empty SM1 once while idle (after a timeout)
  core::TimePoint deadline_{};
  core::TimePoint next_status_poll_{};
  core::TimePoint now_{};
  std::array<Slot, kQueueDepth> slots_{};
  std::array<std::uint8_t, kMaxMailbox> out_{};   // the request written to SM0
  std::size_t out_size_ = 0;
  CoeSdoCounters counters_{};
};

}  // namespace drivegate::ethercat
