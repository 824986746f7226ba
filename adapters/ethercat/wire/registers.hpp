#pragma once
// ESC registers a master uses [ETG.1000.4 §6, register map Table 31 (DL information, station
// address, DL control and status, watchdogs, SII access, FMMU, SyncManager, distributed clocks);
// ETG.1000.6 §5.3.2 (AL control/status/status code)], the 16-byte FMMU and 8-byte SyncManager entries, and
// the AL (EtherCAT) state. All register contents are little-endian.
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string_view>

namespace drivegate::ethercat {

namespace reg {
// DL information [ETG.1000.4 Table 31]
inline constexpr std::uint16_t kType = 0x0000;            // u8
inline constexpr std::uint16_t kRevision = 0x0001;        // u8
inline constexpr std::uint16_t kBuild = 0x0002;           // u16
inline constexpr std::uint16_t kFmmusSupported = 0x0004;  // u8
inline constexpr std::uint16_t kSmsSupported = 0x0005;    // u8
inline constexpr std::uint16_t kRamSize = 0x0006;         // u8, KiB
inline constexpr std::uint16_t kPortDescriptor = 0x0007; // u8, 2 bits per port
inline constexpr std::uint16_t kEscFeatures = 0x0008;     // u16
// Station address [ETG.1000.4 Table 31]
inline constexpr std::uint16_t kStationAddress = 0x0010;  // u16 configured station address
inline constexpr std::uint16_t kStationAlias = 0x0012;    // u16 configured station alias
// Write protection and reset
inline constexpr std::uint16_t kWriteEnable = 0x0020;
inline constexpr std::uint16_t kWriteProtection = 0x0021;
inline constexpr std::uint16_t kEscWriteEnable = 0x0030;
inline constexpr std::uint16_t kEscWriteProtection = 0x0031;
inline constexpr std::uint16_t kEscResetEcat = 0x0040;
inline constexpr std::uint16_t kEscResetPdi = 0x0041;
// Data link layer [ETG.1000.4 Table 31; DL status Table 34]
inline constexpr std::uint16_t kDlControl = 0x0100;       // u32
inline constexpr std::uint16_t kPhysicalRwOffset = 0x0108;
inline constexpr std::uint16_t kDlStatus = 0x0110;        // u16
// Application layer [ETG.1000.6 §5.3.2]
inline constexpr std::uint16_t kAlControl = 0x0120;       // u16
inline constexpr std::uint16_t kAlStatus = 0x0130;        // u16
inline constexpr std::uint16_t kAlStatusCode = 0x0134;    // u16
inline constexpr std::uint16_t kRunLedOverride = 0x0138;
inline constexpr std::uint16_t kErrLedOverride = 0x0139;
// PDI [ETG.1000.4 Table 31]
inline constexpr std::uint16_t kPdiControl = 0x0140;      // u8
inline constexpr std::uint16_t kEscConfiguration = 0x0141;
inline constexpr std::uint16_t kPdiConfiguration = 0x0150;
inline constexpr std::uint16_t kSyncLatchConfig = 0x0151;  // sync/latch PDI configuration
inline constexpr std::uint16_t kExtendedPdiConfig = 0x0152;
// Interrupts
inline constexpr std::uint16_t kEcatEventMask = 0x0200;
inline constexpr std::uint16_t kAlEventMask = 0x0204;
inline constexpr std::uint16_t kEcatEventRequest = 0x0210;
inline constexpr std::uint16_t kAlEventRequest = 0x0220;
// Error counters
inline constexpr std::uint16_t kRxErrorCounter = 0x0300;         // 2 bytes per port (invalid frame, RX error)
inline constexpr std::uint16_t kForwardedRxErrorCounter = 0x0308; // 1 byte per port
inline constexpr std::uint16_t kProcessingUnitErrorCounter = 0x030C;
inline constexpr std::uint16_t kPdiErrorCounter = 0x030D;
inline constexpr std::uint16_t kLostLinkCounter = 0x0310;        // 1 byte per port
// Watchdogs [ETG.1000.4 Table 31; digest §8.2]
inline constexpr std::uint16_t kWatchdogDivider = 0x0400;         // u16, in 40 ns units minus 2
inline constexpr std::uint16_t kWatchdogTimePdi = 0x0410;         // u16, in divider ticks
inline constexpr std::uint16_t kWatchdogTimeProcessData = 0x0420; // u16 SM watchdog, in divider ticks
inline constexpr std::uint16_t kWatchdogStatusProcessData = 0x0440;  // u16, bit 0: 0 = expired
inline constexpr std::uint16_t kWatchdogCounterProcessData = 0x0442; // u8
inline constexpr std::uint16_t kWatchdogCounterPdi = 0x0443;         // u8
// SII EEPROM interface [ETG.1000.4 Table 48]
inline constexpr std::uint16_t kSiiConfig = 0x0500;        // u8 EEPROM configuration
inline constexpr std::uint16_t kSiiPdiAccess = 0x0501;     // u8 EEPROM PDI access state
inline constexpr std::uint16_t kSiiControl = 0x0502;       // u16 control/status
inline constexpr std::uint16_t kSiiAddress = 0x0504;       // u32 word address
inline constexpr std::uint16_t kSiiData = 0x0508;          // 4 or 8 bytes read data
inline constexpr std::uint16_t kSiiInterfaceEnd = 0x050F;
// FMMU and SyncManager blocks [ETG.1000.4 Tables 56-59]
inline constexpr std::uint16_t kFmmu0 = 0x0600;
inline constexpr std::uint16_t kFmmuSize = 16;
inline constexpr std::uint16_t kSm0 = 0x0800;
inline constexpr std::uint16_t kSmSize = 8;
constexpr std::uint16_t fmmu(unsigned n) noexcept { return static_cast<std::uint16_t>(kFmmu0 + n * kFmmuSize); }
constexpr std::uint16_t sm(unsigned n) noexcept { return static_cast<std::uint16_t>(kSm0 + n * kSmSize); }
// The last three bytes of SM n's entry [ETG.1000.4 Table 59]: status (sm_status bits, read-only for
// the master), activate (sm_activate bits) and PDI control (sm_pdi_control bits, read-only for the
// master), e.g. 080Dh/080Eh/080Fh for SM1.
constexpr std::uint16_t sm_status(unsigned n) noexcept { return static_cast<std::uint16_t>(sm(n) + 5U); }
constexpr std::uint16_t sm_activation(unsigned n) noexcept { return static_cast<std::uint16_t>(sm(n) + 6U); }
constexpr std::uint16_t sm_pdi_control(unsigned n) noexcept { return static_cast<std::uint16_t>(sm(n) + 7U); }
// Distributed clocks [ETG.1000.4 Table 31]
inline constexpr std::uint16_t kDcReceiveTimePort0 = 0x0900;  // u32 each, ports 0..3 at +4
inline constexpr std::uint16_t kDcReceiveTimePort1 = 0x0904;
inline constexpr std::uint16_t kDcReceiveTimePort2 = 0x0908;
inline constexpr std::uint16_t kDcReceiveTimePort3 = 0x090C;
inline constexpr std::uint16_t kDcSystemTime = 0x0910;                  // u64
inline constexpr std::uint16_t kDcReceiveTimeProcessingUnit = 0x0918;   // u64
inline constexpr std::uint16_t kDcSystemTimeOffset = 0x0920;            // u64
inline constexpr std::uint16_t kDcSystemTimeDelay = 0x0928;             // u32
inline constexpr std::uint16_t kDcSystemTimeDifference = 0x092C;        // u32: bit 31 sign, bits 0-30 magnitude
inline constexpr std::uint16_t kDcSpeedCounterStart = 0x0930;           // u16
inline constexpr std::uint16_t kDcSpeedCounterDiff = 0x0932;            // u16
inline constexpr std::uint16_t kDcTimeDifferenceFilterDepth = 0x0934;   // u8
inline constexpr std::uint16_t kDcSpeedCounterFilterDepth = 0x0935;     // u8
inline constexpr std::uint16_t kDcCyclicUnitControl = 0x0980;           // u8
inline constexpr std::uint16_t kDcActivation = 0x0981;                  // u8
inline constexpr std::uint16_t kDcSyncPulseLength = 0x0982;             // u16
inline constexpr std::uint16_t kDcActivationStatus = 0x0984;            // u8
inline constexpr std::uint16_t kDcSync0Status = 0x098E;                 // u8
inline constexpr std::uint16_t kDcSync1Status = 0x098F;                 // u8
inline constexpr std::uint16_t kDcSync0StartTime = 0x0990;              // u64 start time cyclic operation
inline constexpr std::uint16_t kDcSync1NextPulse = 0x0998;              // u64
inline constexpr std::uint16_t kDcSync0CycleTime = 0x09A0;              // u32 ns
inline constexpr std::uint16_t kDcSync1CycleTime = 0x09A4;              // u32 ns
inline constexpr std::uint16_t kDcLatch0Control = 0x09A8;
inline constexpr std::uint16_t kDcLatch1Control = 0x09A9;
// Process data RAM starts here on every ESC [ETG.1000.4 Table 31].
inline constexpr std::uint16_t kProcessRam = 0x1000;
}  // namespace reg

// DC activation register 0x0981 bits [ETG.1000.4 §6, DC registers].
namespace dc_activation {
inline constexpr std::uint8_t kCyclicOperation = 0x01;
inline constexpr std::uint8_t kSync0 = 0x02;
inline constexpr std::uint8_t kSync1 = 0x04;
}  // namespace dc_activation

// SII control/status 0x0502 bits [ETG.1000.4 Table 48].
namespace sii_control {
inline constexpr std::uint16_t kWriteEnable = 0x0001;
inline constexpr std::uint16_t kEmulation = 0x0020;
inline constexpr std::uint16_t kRead8Bytes = 0x0040;   // 1: reads return 8 bytes, 0: 4 bytes
inline constexpr std::uint16_t kTwoAddressBytes = 0x0080;
inline constexpr std::uint16_t kCommandRead = 0x0100;
inline constexpr std::uint16_t kCommandWrite = 0x0200;
inline constexpr std::uint16_t kCommandReload = 0x0400;
inline constexpr std::uint16_t kCommandMask = 0x0700;
inline constexpr std::uint16_t kChecksumError = 0x0800;
inline constexpr std::uint16_t kDeviceInfoError = 0x1000;
inline constexpr std::uint16_t kCommandError = 0x2000;  // missing acknowledge / invalid command
inline constexpr std::uint16_t kWriteError = 0x4000;
inline constexpr std::uint16_t kBusy = 0x8000;
}  // namespace sii_control

// DL status 0x0110 bits [ETG.1000.4 Table 34]: link and loop state per port.
namespace dl_status {
inline constexpr std::uint16_t kPdiOperational = 0x0001;
inline constexpr std::uint16_t kWatchdogStatus = 0x0002;
inline constexpr std::uint16_t kEnhancedLinkDetection = 0x0004;
constexpr std::uint16_t link_on_port(unsigned port) noexcept { return static_cast<std::uint16_t>(0x0010U << port); }
constexpr std::uint16_t loop_closed_port(unsigned port) noexcept { return static_cast<std::uint16_t>(0x0100U << (2 * port)); }
constexpr std::uint16_t communication_on_port(unsigned port) noexcept {
  return static_cast<std::uint16_t>(0x0200U << (2 * port));
}
}  // namespace dl_status

// ---- AL state [ETG.1000.6 §5.3.2, Table 9 AL control] ------------------------------

enum class AlState : std::uint8_t {
  None = 0,  // not a valid state; an unread or powerless slave answers 0
  Init = 1,
  PreOp = 2,
  Boot = 3,
  SafeOp = 4,
  Op = 8,
};
inline constexpr std::uint16_t kAlStateMask = 0x000F;
inline constexpr std::uint16_t kAlErrorBit = 0x0010;     // AL status: error indicator; AL control: acknowledge
inline constexpr std::uint16_t kAlIdentBit = 0x0020;     // AL status: device identification loaded; control: request

// "INIT", "PRE-OP", "BOOT", "SAFE-OP", "OP"; "NONE" for 0; "unknown" otherwise.
std::string_view to_string(AlState s) noexcept;
bool is_valid_state(std::uint8_t raw) noexcept;

struct AlStatus {
  std::uint8_t raw_state = 0;  // bits 0-3 as read
  bool error = false;          // bit 4
  bool identification = false; // bit 5
  AlState state() const noexcept { return is_valid_state(raw_state) ? static_cast<AlState>(raw_state) : AlState::None; }
};
AlStatus decode_al_status(std::uint16_t reg_value) noexcept;
// AL control word: requested state, error acknowledge bit [ETG.1000.6 §5.3.2].
constexpr std::uint16_t al_control(AlState s, bool acknowledge = false) noexcept {
  return static_cast<std::uint16_t>(static_cast<std::uint16_t>(s) | (acknowledge ? kAlErrorBit : 0));
}

// ---- FMMU entry (16 bytes) [ETG.1000.4 Table 56] ---------------------------

namespace fmmu_type {
inline constexpr std::uint8_t kRead = 0x01;   // inputs: the ESC copies physical memory into the frame
inline constexpr std::uint8_t kWrite = 0x02;  // outputs: the ESC copies frame data into physical memory
}  // namespace fmmu_type

struct FmmuEntry {
  std::uint32_t logical_start = 0;
  std::uint16_t length = 0;        // bytes
  std::uint8_t logical_start_bit = 0;  // 0..7
  std::uint8_t logical_stop_bit = 7;   // 0..7
  std::uint16_t physical_start = 0;
  std::uint8_t physical_start_bit = 0;
  std::uint8_t type = 0;           // fmmu_type bits
  bool active = false;

  bool operator==(const FmmuEntry&) const = default;
};
inline constexpr std::size_t kFmmuEntrySize = 16;
std::array<std::uint8_t, kFmmuEntrySize> encode_fmmu(const FmmuEntry& f) noexcept;
// nullopt when `in` is shorter than 16 bytes; reserved bits are ignored (masked off).
std::optional<FmmuEntry> decode_fmmu(std::span<const std::uint8_t> in) noexcept;

// ---- SyncManager entry (8 bytes) [ETG.1000.4 Table 59] --------------

namespace sm_control {
inline constexpr std::uint8_t kModeBuffered = 0x00;  // bits 0-1: 00 3-buffer
inline constexpr std::uint8_t kModeMailbox = 0x02;   // bits 0-1: 10 1-buffer (mailbox)
inline constexpr std::uint8_t kModeMask = 0x03;
inline constexpr std::uint8_t kDirectionRead = 0x00;   // bits 2-3: 00 ECAT reads, PDI writes (inputs, mailbox in)
inline constexpr std::uint8_t kDirectionWrite = 0x04;  // bits 2-3: 01 ECAT writes, PDI reads (outputs, mailbox out)
inline constexpr std::uint8_t kDirectionMask = 0x0C;
inline constexpr std::uint8_t kEcatEventIrq = 0x10;
inline constexpr std::uint8_t kAlEventIrq = 0x20;
inline constexpr std::uint8_t kWatchdogTrigger = 0x40;
// Typical values: mailbox out (SM0) 26h, mailbox in (SM1) 22h, outputs (SM2) 64h, inputs (SM3) 20h
// (digest §8.2 "typical 0x64").
inline constexpr std::uint8_t kMailboxOut = 0x26;
inline constexpr std::uint8_t kMailboxIn = 0x22;
inline constexpr std::uint8_t kOutputs = 0x64;
inline constexpr std::uint8_t kInputs = 0x20;
}  // namespace sm_control

namespace sm_status {
inline constexpr std::uint8_t kInterruptWrite = 0x01;
inline constexpr std::uint8_t kInterruptRead = 0x02;
inline constexpr std::uint8_t kMailboxFull = 0x08;  // 1-buffer state: mailbox full
}  // namespace sm_status

namespace sm_activate {
inline constexpr std::uint8_t kEnable = 0x01;
inline constexpr std::uint8_t kRepeat = 0x02;
inline constexpr std::uint8_t kDcEvent0Bus = 0x40;
inline constexpr std::uint8_t kDcEvent0Local = 0x80;
}  // namespace sm_activate

namespace sm_pdi_control {
inline constexpr std::uint8_t kDeactivate = 0x01;  // the PDI switched the SM off
inline constexpr std::uint8_t kRepeatAck = 0x02;   // repeat acknowledge (follows sm_activate::kRepeat)
}  // namespace sm_pdi_control

struct SmEntry {
  std::uint16_t physical_start = 0;
  std::uint16_t length = 0;
  std::uint8_t control = 0;
  std::uint8_t status = 0;      // read-only for the master; written as 0
  std::uint8_t activate = 0;    // sm_activate bits
  std::uint8_t pdi_control = 0; // sm_pdi_control bits (PDI side)

  bool enabled() const noexcept { return (activate & sm_activate::kEnable) != 0; }
  bool operator==(const SmEntry&) const = default;
};
inline constexpr std::size_t kSmEntrySize = 8;
std::array<std::uint8_t, kSmEntrySize> encode_sm(const SmEntry& s) noexcept;
// nullopt when `in` is shorter than 8 bytes.
std::optional<SmEntry> decode_sm(std::span<const std::uint8_t> in) noexcept;

// System time difference register 0x092C [ETG.1000.4 §6 DC registers]: sign and magnitude, not two's
// complement. Bits 0-30: |difference| in ns; bit 31 = 1: the local copy of the system time is
// smaller than the received time (local - received < 0), 0: greater or equal. Returns the signed
// difference (local - received) in ns.
constexpr std::int32_t decode_system_time_difference(std::uint32_t raw) noexcept {
  const auto magnitude = static_cast<std::int32_t>(raw & 0x7FFFFFFFU);
  return (raw & 0x80000000U) ? -magnitude : magnitude;
}
// The register value of a signed difference (local - received) in ns, the inverse of the decoder;
// a magnitude beyond 31 bits saturates at 7FFFFFFFh (2.1 s), keeping the sign.
constexpr std::uint32_t encode_system_time_difference(std::int64_t diff) noexcept {
  constexpr std::uint64_t kMax = 0x7FFFFFFFU;
  const std::uint64_t magnitude =
      diff < 0 ? static_cast<std::uint64_t>(-(diff + 1)) + 1U : static_cast<std::uint64_t>(diff);
  return static_cast<std::uint32_t>(magnitude > kMax ? kMax : magnitude) | (diff < 0 ? 0x80000000U : 0U);
}

}  // namespace drivegate::ethercat
