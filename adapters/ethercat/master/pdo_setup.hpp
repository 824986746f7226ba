#pragma once
// Process data set-up of one slave in PRE-OP (dunker-ethercat-coe.md "What an EtherCAT master must
// do", steps 4-5; ETG.1000.6 PDO assignment 1C12h/1C13h and mapping 16xxh/1Axxh; ETG.1000.4 §6
// SyncManager and FMMU registers):
//
//   1. start-up writes: each a CoE download, then an upload that reads it back (some writes are
//      accepted and silently ignored: digest quirk 8). A value that reads back different fails the
//      set-up, unless the object is listed as ignored: then it is a warning.
//   2. PDO assignment and mapping, 1C12h (SM2, RxPDOs) then 1C13h (SM3, TxPDOs), in the order the
//      digest gives (§7.2, §7.4, TV-6): 1C1xh:00 := 0; per PDO 16xxh:00 := 0, its entries :01..n
//      (index << 16 | subindex << 8 | bits, TV-1), :00 := n; then 1C1xh:01..m, 1C1xh:00 := m. Every
//      write is read back. A write the slave refuses (SDO abort) whose read-back already holds the
//      wanted value is accepted: a device with a fixed mapping refuses writes it does not need (for
//      the count cleared first, "wanted" is the count the sequence ends with).
//      A 1-byte sub-index 0 write aborted with a length/type abort is tried again with 2 bytes
//      (digest TV-6 note).
//   3. verify: the entry bits read back per SM, rounded up to bytes, equal the process image's
//      SM2/SM3 lengths.
//   4. registers: SM2 (FPWR 0810h, 8 bytes), SM3 (FPWR 0818h), the output and input FMMUs (FPWR
//      0600h + 16·n, 16 bytes), and the SM watchdog when configured (0400h divider = 2498: 100 µs
//      ticks; 0420h time in ticks) [ETG.1000.4 Table 31; digest §8.2]. Each must come back with WKC
//      1; a lost datagram is sent again up to `retries` times.
//
// A failure stops the set-up with one sentence, e.g.
//   "slave 2 (0x1002): PDO mapping: 1600h:03 reads 0x60710010 after writing 0x607A0020 (the drive ignored the write)"
//
// The CoeSdoClient belongs to the caller, who polls it (as every engine) in the same cycle; PdoSetup
// only submits requests and takes their results. A slave without a mailbox (plain I/O) passes a
// null client: steps 1-3 are skipped. Fixed capacities; nothing allocates.
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

#include "adapters/ethercat/master/coe_sdo_client.hpp"
#include "adapters/ethercat/master/process_image.hpp"
#include "adapters/ethercat/master/transactions.hpp"
#include "core/clock.hpp"
#include "core/fixed_string.hpp"

namespace drivegate::ethercat {

struct PdoEntryConfig {
  std::uint16_t index = 0;   // 0 with sub-index 0: a gap of `bits`
  std::uint8_t subindex = 0;
  std::uint8_t bits = 0;
  // The mapping entry value [digest §7.2, TV-1].
  [[nodiscard]] constexpr std::uint32_t value() const noexcept {
    return (std::uint32_t{index} << 16) | (std::uint32_t{subindex} << 8) | bits;
  }
};

struct PdoConfig {
  std::uint16_t index = 0;  // 1600h.. (RxPDO) or 1A00h.. (TxPDO)
  std::span<const PdoEntryConfig> entries{};
};

struct CoeObjectId {
  std::uint16_t index = 0;
  std::uint8_t subindex = 0;
  friend constexpr bool operator==(CoeObjectId a, CoeObjectId b) noexcept = default;
};

struct CoeStartupWrite {
  std::uint16_t index = 0;
  std::uint8_t subindex = 0;
  std::uint32_t value = 0;
  std::uint8_t size = 0;  // 1..4 bytes
};

struct PdoSetupConfig {
  std::uint16_t position = 0;  // for texts: "slave <position + 1>"
  std::span<const CoeStartupWrite> startup_writes{};
  std::span<const CoeObjectId> ignored_writes{};  // read-back differences here are warnings
  bool map_pdos = true;                           // false: keep the device's assignment (no 1C1xh writes)
  std::span<const PdoConfig> rx_pdos{};           // 1C12h order (SM2)
  std::span<const PdoConfig> tx_pdos{};           // 1C13h order (SM3)
  core::Duration sm_watchdog{0};                  // 0: 0400h/0420h left as they are
  int retries = 3;                                // per register write datagram
};

enum class PdoSetupStatus : std::uint8_t { Idle, Running, Done, Failed };
std::string_view to_string(PdoSetupStatus s) noexcept;
enum class PdoSetupStep : std::uint8_t { StartupWrites, Assignment, Verify, Registers, Finished };
std::string_view to_string(PdoSetupStep s) noexcept;

struct PdoSetupCounters {
  std::uint32_t sdo_writes = 0;
  std::uint32_t sdo_reads = 0;
  std::uint32_t refused_but_set = 0;  // writes refused whose read-back held the wanted value
  std::uint32_t retried_two_bytes = 0;
  std::uint32_t register_writes = 0;
  std::uint32_t register_retries = 0;
};

class PdoSetup final : public DatagramOwner {
 public:
  static constexpr std::size_t kMaxStartupWrites = 32;
  static constexpr std::size_t kMaxIgnored = 16;
  static constexpr std::size_t kMaxPdos = 16;        // both directions together
  static constexpr std::size_t kMaxEntries = 192;    // all PDOs together
  static constexpr std::size_t kMaxOps = kMaxStartupWrites + 4 + 3 * kMaxPdos + kMaxEntries;
  static constexpr std::size_t kMaxWarnings = 4;
  // SM watchdog base: divider 2498 gives (2498 + 2) × 40 ns = 100 µs per tick [digest §8.2].
  static constexpr std::uint16_t kWatchdogDivider = 2498;
  static constexpr std::int64_t kWatchdogTickNs = 100'000;

  PdoSetup() noexcept = default;

  // Starts (or restarts) the set-up of the slave at `image` (station, SM and FMMU entries, planned
  // sizes). The config is copied: its spans need not outlive the call. `coe` may be null (no
  // mailbox: registers only) and must outlive the set-up. False (Failed, text says why) when the
  // config exceeds the capacities or a CoE step is configured without a client.
  bool start(CoeSdoClient* coe, const PdoSetupConfig& config, const SlaveImage& image, core::TimePoint now) noexcept;
  void poll(core::TimePoint now, Transactions& tx) noexcept;
  void on_result(std::uint32_t tag, const DatagramAnswer& answer) noexcept override;

  [[nodiscard]] PdoSetupStatus status() const noexcept { return status_; }
  [[nodiscard]] PdoSetupStep step() const noexcept { return step_; }
  [[nodiscard]] std::string_view text() const noexcept { return text_.view(); }
  [[nodiscard]] std::size_t warning_count() const noexcept { return warning_count_; }
  [[nodiscard]] std::string_view warning(std::size_t i) const noexcept { return warnings_[i].view(); }
  [[nodiscard]] const PdoSetupCounters& counters() const noexcept { return counters_; }
  // Entry bits read back per SM (2: outputs, 3: inputs) after the mapping.
  [[nodiscard]] std::uint32_t mapped_bits(unsigned sm) const noexcept { return sm == 2 ? bits_[0] : sm == 3 ? bits_[1] : 0; }

 private:
  enum class Area : std::uint8_t { Startup, Assignment, Mapping };
  struct Op {
    Area area = Area::Startup;
    std::uint16_t index = 0;
    std::uint8_t subindex = 0;
    std::uint8_t size = 0;
    std::uint32_t value = 0;
    std::uint8_t entry_sm = 0;  // 2/3: a mapping entry whose bits count for that SM
    bool ignored = false;
    // A count cleared before the entries are written (1C1xh:00 / 16xxh:00 := 0): the count the
    // sequence ends with. A refused clear that reads this count is a fixed assignment/mapping.
    std::uint32_t final_value = 0;
  };
  enum class SdoPhase : std::uint8_t { Download, WaitDownload, Upload, WaitUpload };
  struct RegWrite {
    std::uint16_t ado = 0;
    std::uint8_t length = 0;
    std::array<std::uint8_t, 16> data{};
    const char* what = "";
    bool due = false;
    bool waiting = false;
    bool done = false;
    int retries_left = 0;
  };
  static constexpr std::size_t kMaxRegWrites = 6;

  void add_op(Area area, std::uint16_t index, std::uint8_t subindex, std::uint32_t value, std::uint8_t size,
              std::uint8_t entry_sm = 0, std::uint32_t final_value = 0) noexcept;
  bool add_direction(std::uint16_t assign_index, std::span<const PdoConfig> pdos, std::uint8_t sm) noexcept;
  void add_reg(std::uint16_t ado, std::span<const std::uint8_t> data, const char* what) noexcept;
  void step_sdo() noexcept;
  void finish_op(bool download_ok, std::uint32_t download_abort, const CoeSdoResult& read) noexcept;
  void next_op() noexcept;
  void verify() noexcept;
  void warn(const char* fmt, ...) noexcept __attribute__((format(printf, 2, 3)));
  void fail(const char* fmt, ...) noexcept __attribute__((format(printf, 2, 3)));
  [[nodiscard]] static const char* area_name(Area a) noexcept;
  [[nodiscard]] bool is_ignored(std::uint16_t index, std::uint8_t subindex) const noexcept;

  CoeSdoClient* coe_ = nullptr;
  std::uint16_t slave_number_ = 1;
  std::uint16_t station_ = 0;
  SlaveImage image_{};
  bool map_pdos_ = true;
  int retries_ = 3;
  std::array<CoeObjectId, kMaxIgnored> ignored_{};
  std::size_t ignored_count_ = 0;

  std::array<Op, kMaxOps> ops_{};
  std::size_t op_count_ = 0;
  std::size_t op_ = 0;
  SdoPhase sdo_phase_ = SdoPhase::Download;
  CoeSdoId sdo_id_ = 0;
  std::uint8_t write_size_ = 0;       // size of the download in flight (1 -> 2 retry)
  bool download_ok_ = false;
  std::uint32_t download_abort_ = 0;
  std::array<std::uint32_t, 2> bits_{};
  // A request still running when start() was called again: taken (freed) once it ends.
  CoeSdoClient* abandoned_client_ = nullptr;
  CoeSdoId abandoned_ = 0;

  std::array<RegWrite, kMaxRegWrites> regs_{};
  std::size_t reg_count_ = 0;
  std::uint16_t generation_ = 0;      // tags of an earlier start() are ignored

  PdoSetupStatus status_ = PdoSetupStatus::Idle;
  PdoSetupStep step_ = PdoSetupStep::StartupWrites;
  core::TimePoint now_{};
  PdoSetupCounters counters_{};
  core::FixedString<240> text_{};
  std::array<core::FixedString<200>, kMaxWarnings> warnings_{};
  std::size_t warning_count_ = 0;
};

}  // namespace drivegate::ethercat
