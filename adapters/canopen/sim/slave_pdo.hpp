#pragma once
// The slave side of PDOs for simulated drives (CiA 301 §7.2.2, §7.5.2.35/36): four RPDOs and four
// TPDOs with their communication (1400h../1800h..) and mapping (1600h../1A00h..) parameters as an
// object store the slave's SDO server reads and writes, and the exchange itself in NMT Operational.
//
// Object rules [CiA 301 §7.5.2.35/36; AKD part 1 §12.2, §12.3, §12.6]:
// - COB-ID (sub 1, U32): bit 31 = PDO invalid, bit 30 = no RTR, bit 29 (29-bit ids) is refused
//   with 06090030h like any bit in 28..11; the id bits change only while the PDO is invalid
//   (06090030h), and a valid PDO needs an id other than 0.
// - Transmission type (sub 2, U8): the persona's allowed set, else 06090030h.
// - TPDO inhibit time (sub 3, U16, 100 µs) and event timer (sub 5, U16, ms); RPDOs have neither
//   (AKD part 1 §12.2, SD6 quirk 5). Sub 0 is read-only (2 for RPDOs, 5 for TPDOs).
// - Mapping sub 0 (count) and entries change only while the PDO is invalid (08000022h). An entry
//   must name an object the owner can map in that direction with its exact byte length, or be 0
//   (06040041h). The count is 0 (mapping off) or n <= the persona's entry limit (06090030h) with
//   entries 1..n set (06040041h) and at most 8 bytes in all (06040042h).
// - A write whose SDO size does not match the object's (1, 2 or 4 bytes) gets 06070010h.
//
// Exchange, only in Operational (the owner says so):
// - RPDO of type 254/255: applied on reception; 0..240: kept and applied at the next SYNC (the AKD
//   persona applies types 1..240 at every n-th SYNC only: AKD part 1 §12.2, quirk 8). A frame
//   shorter than the mapping is dropped, counted and flagged for an EMCY 8210h; a longer one is
//   used and counted [CiA 301 §7.2.2.2].
// - TPDO of type 1..240: sent at every n-th SYNC (AKD part 2 §12.10: type 2 after S2, S4, ...);
//   type 0: sent at a SYNC when the mapped data changed; 254/255: sent when the mapped data
//   changes, no sooner than the inhibit time after the previous one, and at the latest one event
//   timer after it. The SD6 persona sends type 254 on RPDO reception instead of on change, with
//   the event timer as the fall-back (stoeber-sd6-canopen.md §6.2, quirk 3).
// A TPDO is also "changed" when it was not sent since it became valid or the node operational.
//
// The values come from and go to the owner (the simulated drive's object dictionary) through
// PdoObjects. Nothing here allocates after construction.
#include <array>
#include <cstdint>
#include <optional>
#include <span>

#include "adapters/canopen/master/tx_queue.hpp"
#include "adapters/canopen/wire/can_frame.hpp"
#include "adapters/canopen/wire/cob_id.hpp"
#include "core/clock.hpp"
#include "profiles/cia402/objects.hpp"

namespace drivegate::canopen::sim {

// The objects the PDOs carry: implemented by the owner of the PDOs.
class PdoObjects {
 public:
  virtual ~PdoObjects() = default;
  // The object's type when it exists and may be mapped into an RPDO (`receive`: the slave writes
  // it) or a TPDO (the slave reads it); nullopt otherwise.
  [[nodiscard]] virtual std::optional<cia402::DataType> mappable(cia402::ObjectId id, bool receive) const noexcept = 0;
  [[nodiscard]] virtual std::int64_t read(cia402::ObjectId id) const noexcept = 0;
  // `value` is sign-extended per the object's type.
  virtual void write(cia402::ObjectId id, std::int64_t value) noexcept = 0;
};

// The values 1400h../1800h.. sub 2 accept.
struct TransmissionTypes {
  std::uint8_t sync_min = 0;  // synchronous types sync_min..sync_max
  std::uint8_t sync_max = 240;
  bool type_254 = true;
  bool type_255 = true;
  [[nodiscard]] constexpr bool allows(std::uint8_t t) const noexcept {
    return (t >= sync_min && t <= sync_max && t <= 240) || (t == 254 && type_254) || (t == 255 && type_255);
  }
  // The type an unused PDO holds: one allowed, so that it reads back as a value the drive could have.
  [[nodiscard]] constexpr std::uint8_t unused() const noexcept {
    if (type_255) return 255;
    if (type_254) return 254;
    return sync_min;
  }
};

// Persona options (the device profile's quirks as data).
struct SlavePdoOptions {
  std::uint8_t max_entries = 8;  // mapping entries per PDO (SD6: 6, quirk 5)
  // 0: CiA 301 mapping rules. N: mapping sub 0 is the constant N and the entries are read-only
  // over SDO; empty (0) entries among 1..N map nothing (SD6: 6, quirk 4).
  std::uint8_t fixed_count = 0;
  TransmissionTypes transmission_types{};  // SD6: 1..240 and 254 (quirk 3)
  bool rpdo_every_nth_sync = false;        // AKD: RPDO types 1..240 apply at every n-th SYNC (quirk 8)
  bool tpdo_254_on_rpdo = false;           // SD6: type 254 TPDOs are sent on RPDO reception (quirk 3)
};

// One PDO's parameters as the owner sets them up (its power-on defaults).
struct SlavePdoConfig {
  std::uint32_t cob_id = cob::kInvalid;  // sub 1, with bit 31 for a disabled PDO
  std::uint8_t transmission_type = 255;  // sub 2
  std::uint16_t inhibit_time = 0;        // TPDO sub 3, 100 µs
  std::uint16_t event_timer = 0;         // TPDO sub 5, ms
  std::uint8_t count = 0;                // mapping sub 0
  std::array<std::uint32_t, 8> mapping{};  // mapping subs 1..8 (wire/pdo_mapping.hpp encoding)
};

struct SlavePdoCounters {
  std::uint64_t rpdos_received = 0;
  std::uint64_t rpdos_applied = 0;
  std::uint64_t short_rpdos = 0;  // dropped (EMCY 8210h)
  std::uint64_t long_rpdos = 0;   // used, counted
  std::uint64_t tpdos_sent = 0;
  std::uint64_t ignored = 0;      // on an RPDO COB-ID while not operational, RTRs, DLC > 8
  std::uint64_t tx_full = 0;
};

struct PdoObjectRead {
  std::uint32_t abort_code = 0;  // 0 or a CiA 301 SDO abort code
  std::uint32_t value = 0;
  std::uint8_t size = 0;  // bytes: 1, 2 or 4
};

class SlavePdos {
 public:
  static constexpr std::size_t kPdos = 4;  // per direction

  // `rpdos`/`tpdos`: the power-on defaults of PDO 1.. (at most four each; missing ones are invalid
  // and empty). Throws std::invalid_argument for more than four, options that contradict each
  // other, or a default the rules above refuse (a persona's fixed mapping included).
  SlavePdos(PdoObjects& objects, SlavePdoOptions options, std::span<const SlavePdoConfig> rpdos,
            std::span<const SlavePdoConfig> tpdos);

  // Back to the power-on defaults (NMT reset: the AKD resets its PDO configuration on Reset Node,
  // AKD part 1 quirk 10).
  void restore_defaults() noexcept;

  // The SDO-facing object store: 1400h..1403h, 1600h..1603h, 1800h..1803h, 1A00h..1A03h.
  [[nodiscard]] static bool owns(std::uint16_t index) noexcept;
  [[nodiscard]] PdoObjectRead read(cia402::ObjectId id) const noexcept;
  // `size` = the SDO's byte count (0: not indicated). Returns 0 or a CiA 301 abort code.
  std::uint32_t write(cia402::ObjectId id, std::uint32_t value, std::uint8_t size = 0) noexcept;

  // NMT Operational or not. Entering it restarts SYNC counting and sends every event-driven TPDO
  // once; leaving it drops RPDO data waiting for a SYNC.
  void set_operational(bool on) noexcept;
  [[nodiscard]] bool operational() const noexcept { return operational_; }

  // Engine interface. on_frame takes the frames of valid RPDOs (false for other COB-IDs).
  bool on_frame(const CanFrame& frame, core::TimePoint now) noexcept;
  // A SYNC was received (the owner routes the 1005h COB-ID here): apply and send what is due.
  void on_sync(core::TimePoint now, TxQueue& tx) noexcept;
  // Event-driven TPDOs: changed data, RPDO triggers, inhibit and event timers.
  void poll(core::TimePoint now, TxQueue& tx) noexcept;
  // The next event timer or inhibit-time expiry (TimePoint::max() when none).
  [[nodiscard]] core::TimePoint next_deadline() const noexcept;

  // True once after an RPDO shorter than its mapping was dropped: the owner sends EMCY 8210h.
  bool take_length_error() noexcept;

  [[nodiscard]] const SlavePdoCounters& counters() const noexcept { return counters_; }

 private:
  struct Field {
    cia402::ObjectId id{};
    cia402::DataType type = cia402::DataType::U8;
    std::uint8_t offset = 0;
  };
  struct Layout {
    std::array<Field, 8> fields{};
    std::uint8_t count = 0;
    std::uint8_t bytes = 0;
  };
  struct Pdo {
    SlavePdoConfig params;  // the object values
    Layout layout;          // resolved from the mapping when its count was set
    bool receive = false;   // RPDO
    // Exchange state.
    std::array<std::uint8_t, 8> data{};  // RPDO: data waiting for a SYNC; TPDO: last sent
    bool pending = false;                // RPDO: data waiting; TPDO: triggered by an RPDO
    bool ever_sent = false;              // TPDO: sent since it became valid / operational
    bool held = false;                   // TPDO: a send is waiting for the inhibit time
    core::TimePoint sent_at{};
    std::uint8_t syncs = 0;              // SYNCs counted towards the n-th
    [[nodiscard]] bool valid() const noexcept { return (params.cob_id & cob::kInvalid) == 0; }
  };

  std::uint32_t check_entry(std::uint32_t entry, bool receive) const noexcept;
  std::uint32_t resolve(const SlavePdoConfig& params, bool receive, Layout& out) const noexcept;
  std::uint32_t write_comm(Pdo& pdo, std::uint8_t sub, std::uint32_t value, std::uint8_t size) noexcept;
  std::uint32_t write_mapping(Pdo& pdo, std::uint8_t sub, std::uint32_t value, std::uint8_t size) noexcept;
  void restart(Pdo& pdo) noexcept;
  void apply(Pdo& pdo, std::span<const std::uint8_t> data) noexcept;
  void pack(const Pdo& pdo, std::array<std::uint8_t, 8>& out) const noexcept;
  void send(Pdo& pdo, const std::array<std::uint8_t, 8>& bytes, core::TimePoint now, TxQueue& tx) noexcept;

  PdoObjects& objects_;
  SlavePdoOptions options_;
  std::array<Pdo, 2 * kPdos> pdos_{};      // RPDO 1..4, then TPDO 1..4
  std::array<Pdo, 2 * kPdos> defaults_{};  // as constructed
  bool operational_ = false;
  bool length_error_ = false;
  SlavePdoCounters counters_;
};

}  // namespace drivegate::canopen::sim
