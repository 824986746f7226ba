#pragma once
// Cyclic telegram codecs [akd-profinet-profidrive.md §12, §13, §14]: the signals the AKD knows,
// the layouts of telegrams 1, 7, 9, 350, 351, 352, 353, and free layouts (telegram 0 and 400) built
// from a PNU 915/916 signal list, and encode/decode of the setpoint (controller -> drive) and
// actual-value (drive -> controller) images. All words are big-endian; 32-bit signals take two
// words, high word first [§14]. Spans must have the telegram's exact size; nothing allocates.
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string_view>

namespace drivegate::profidrive {

// Signal numbers (= their PNU on the AKD) [§11.2, §12.1]; STW2/ZSW2 and XIST_A are used by the
// telegrams but missing from the manual's signal table [§12.1].
enum class Signal : std::uint16_t {
  Stw1 = 1,
  Zsw1 = 2,
  Stw2 = 3,
  Zsw2 = 4,
  NsollA = 5,
  NistA = 6,
  XistA = 28,
  Satzanw = 32,
  Aktsatz = 33,
  MdiTarpos = 34,
  MdiVelocity = 35,
  MdiAcc = 36,
  MdiDec = 37,
  MdiMod = 38,
  ItistGlatt = 52,
  HomeDist = 100,
  MtFeedrate = 101,
  IlCmdFieldbus = 102,
  HomeMode = 103,
  XistError = 104,
  DriveMotionStatus = 105,
  DriveInputs = 106,
};

enum class Direction : std::uint8_t {
  Setpoint,  // controller -> drive (PNU 915, output)
  Actual,    // drive -> controller (PNU 916, input)
};

struct SignalInfo {
  Signal signal;
  Direction direction;
  std::uint8_t words;     // 1 or 2 (32-bit)
  std::string_view name;  // PROFIdrive name, e.g. "NSOLL_A"
};
// The signal with this number, or nullptr when the AKD does not define it (107 is reserved).
const SignalInfo* find_signal(std::uint16_t number) noexcept;

// Controller -> drive. Fields the telegram does not carry are ignored by the encoder and left
// untouched by the decoder.
struct Setpoints {
  std::uint16_t stw1 = 0;
  std::uint16_t stw2 = 0;  // bits undocumented on the AKD; send 0 [§12.1, §25.7]
  std::int16_t nsoll_a = 0;
  std::uint16_t satzanw = 0;  // bit 15 selects MDI [§16.3]
  std::int32_t mdi_tarpos = 0;
  std::uint32_t mdi_velocity = 0;  // signedness not stated [§17.1]
  std::uint16_t mdi_acc = 0;
  std::uint16_t mdi_dec = 0;
  std::uint16_t mdi_mod = 0;  // bit 0: 1 = absolute [§12.2]
  std::int32_t home_dist = 0;
  std::uint16_t home_mode = 0;
  std::uint16_t mt_feedrate = 0;
  std::int16_t il_cmd = 0;
  bool operator==(const Setpoints&) const = default;
};

// Drive -> controller.
struct Actuals {
  std::uint16_t zsw1 = 0;
  std::uint16_t zsw2 = 0;
  std::int16_t nist_a = 0;
  std::uint16_t aktsatz = 0;
  std::int32_t xist_a = 0;        // printed U32, signed in practice [§11.2, §23.17]
  std::int16_t itist_glatt = 0;   // printed U16, signed in practice (-182 in §17.4)
  std::int16_t xist_error = 0;
  std::uint16_t drive_motion_status = 0;
  std::uint16_t drive_inputs = 0;
  bool operator==(const Actuals&) const = default;
};

struct SignalSlot {
  Signal signal = Signal::Stw1;
  std::uint8_t word = 0;  // 0-based PZD word of its first (high) word
};

// Free layouts may hold at most this many words per direction (telegram 400 has 12 [§14.9];
// telegram 0's length is set by its module [§13]).
inline constexpr std::size_t kMaxTelegramWords = 32;

struct TelegramLayout {
  std::uint16_t number = 0;
  std::array<SignalSlot, kMaxTelegramWords> setpoints{};
  std::array<SignalSlot, kMaxTelegramWords> actuals{};
  std::uint8_t setpoint_count = 0;
  std::uint8_t actual_count = 0;
  std::uint8_t setpoint_words = 0;  // whole image, unmapped words included
  std::uint8_t actual_words = 0;
  [[nodiscard]] std::size_t setpoint_bytes() const noexcept { return 2U * setpoint_words; }
  [[nodiscard]] std::size_t actual_bytes() const noexcept { return 2U * actual_words; }
  [[nodiscard]] std::span<const SignalSlot> setpoint_slots() const noexcept {
    return std::span<const SignalSlot>(setpoints).first(setpoint_count);
  }
  [[nodiscard]] std::span<const SignalSlot> actual_slots() const noexcept {
    return std::span<const SignalSlot>(actuals).first(actual_count);
  }
  [[nodiscard]] bool carries(Signal s) const noexcept;
};

enum class TelegramError : std::uint8_t {
  None,
  WrongLength,      // the span is not the telegram's size
  UnknownTelegram,  // not 1, 7, 9, 350..353 (or 0/400 without a signal list)
  UnknownSignal,    // a PNU 915/916 entry the AKD does not define
  WrongDirection,   // an actual value in PNU 915 or a setpoint in PNU 916
  SplitSignal,      // a 32-bit signal without its second word (the list or the image ends)
  DuplicateSignal,
  TooManyWords,     // the list is longer than the image, or the image longer than kMaxTelegramWords
};
std::string_view to_string(TelegramError e) noexcept;

// The fixed layout of telegram 1, 7, 9, 350, 351, 352 or 353 [§14.2..§14.8].
std::optional<TelegramLayout> standard_layout(std::uint16_t telegram) noexcept;

// Image sizes in bytes (setpoint, actual) of every telegram with a fixed size [§4.3]; telegram 400
// is 24/24 whatever its mapping, telegram 0 has none (its module sets it).
struct TelegramSize {
  std::size_t setpoint_bytes = 0;
  std::size_t actual_bytes = 0;
};
std::optional<TelegramSize> telegram_size(std::uint16_t telegram) noexcept;

// A free layout (telegram 0 or 400) from the PNU 915 (setpoint) and PNU 916 (actual) lists:
// entry i is the signal number of PZD word i+1, 0 = word unused [§13, STD]. A 32-bit signal's second
// word holds the same number again or 0 (the manual does not say which [§13]); both are accepted.
// The images are `setpoint_words`/`actual_words` long (telegram 400: 12 each); the lists may be
// shorter (the rest is unused) but not longer.
struct LayoutResult {
  TelegramError error = TelegramError::None;
  std::size_t at = 0;  // index of the offending entry
  bool pnu916 = false; // the offending entry is in the actual-value list
  TelegramLayout layout;
};
LayoutResult free_layout(std::uint16_t telegram, std::span<const std::uint16_t> pnu915, std::size_t setpoint_words,
                         std::span<const std::uint16_t> pnu916, std::size_t actual_words) noexcept;

// Controller side: setpoints out, actual values in. Unmapped words are written as 0.
TelegramError encode_setpoints(const TelegramLayout& layout, const Setpoints& in, std::span<std::uint8_t> out) noexcept;
TelegramError decode_actuals(const TelegramLayout& layout, std::span<const std::uint8_t> in, Actuals& out) noexcept;

// Drive side (the simulator): actual values out, setpoints in.
TelegramError encode_actuals(const TelegramLayout& layout, const Actuals& in, std::span<std::uint8_t> out) noexcept;
TelegramError decode_setpoints(const TelegramLayout& layout, std::span<const std::uint8_t> in, Setpoints& out) noexcept;

}  // namespace drivegate::profidrive
