#include "profiles/profidrive/telegram.hpp"

#include <initializer_list>

namespace drivegate::profidrive {

namespace {

using enum Signal;
constexpr Direction kOut = Direction::Setpoint;
constexpr Direction kIn = Direction::Actual;

// [§12.1] with the lengths the telegram layouts use; STW2/ZSW2/XIST_A from §14.
constexpr std::array<SignalInfo, 22> kSignals{{
    {Stw1, kOut, 1, "STW1"},
    {Zsw1, kIn, 1, "ZSW1"},
    {Stw2, kOut, 1, "STW2"},
    {Zsw2, kIn, 1, "ZSW2"},
    {NsollA, kOut, 1, "NSOLL_A"},
    {NistA, kIn, 1, "NIST_A"},
    {XistA, kIn, 2, "XIST_A"},
    {Satzanw, kOut, 1, "SATZANW"},
    {Aktsatz, kIn, 1, "AKTSATZ"},
    {MdiTarpos, kOut, 2, "MDI_TARPOS"},
    {MdiVelocity, kOut, 2, "MDI_VELOCITY"},
    {MdiAcc, kOut, 1, "MDI_ACC"},
    {MdiDec, kOut, 1, "MDI_DEC"},
    {MdiMod, kOut, 1, "MDI_MOD"},
    {ItistGlatt, kIn, 1, "ITIST_GLATT"},
    {HomeDist, kOut, 2, "HOME_DIST"},
    {MtFeedrate, kOut, 1, "MT_FEEDRATE"},
    {IlCmdFieldbus, kOut, 1, "IL_CMD_FIELDBUS"},
    {HomeMode, kOut, 1, "HOME_MODE"},
    {XistError, kIn, 1, "XIST_ERROR"},
    {DriveMotionStatus, kIn, 1, "DRIVE_MOTION_STATUS"},
    {DriveInputs, kIn, 1, "DRIVE_INPUTS"},
}};

std::uint8_t words_of(Signal s) noexcept {
  const SignalInfo* i = find_signal(static_cast<std::uint16_t>(s));
  return i != nullptr ? i->words : 1;
}

// Signals packed one after the other from word 0.
TelegramLayout packed(std::uint16_t number, std::initializer_list<Signal> out, std::initializer_list<Signal> in) noexcept {
  TelegramLayout l;
  l.number = number;
  for (const Signal s : out) {
    l.setpoints[l.setpoint_count++] = SignalSlot{s, l.setpoint_words};
    l.setpoint_words = static_cast<std::uint8_t>(l.setpoint_words + words_of(s));
  }
  for (const Signal s : in) {
    l.actuals[l.actual_count++] = SignalSlot{s, l.actual_words};
    l.actual_words = static_cast<std::uint8_t>(l.actual_words + words_of(s));
  }
  return l;
}

std::uint32_t get_be(std::span<const std::uint8_t> b, std::size_t word, std::uint8_t words) noexcept {
  std::uint32_t v = 0;
  for (std::size_t i = 0; i < 2U * words; ++i) v = (v << 8) | b[2 * word + i];
  return v;
}
void put_be(std::span<std::uint8_t> b, std::size_t word, std::uint8_t words, std::uint32_t v) noexcept {
  for (std::size_t i = 2U * words; i-- > 0;) {
    b[2 * word + i] = static_cast<std::uint8_t>(v & 0xFFU);
    v >>= 8;
  }
}

// The raw wire value of a signal, two's complement for the signed ones.
std::uint32_t raw_of(const Setpoints& s, Signal sig) noexcept {
  switch (sig) {
    case Stw1: return s.stw1;
    case Stw2: return s.stw2;
    case NsollA: return static_cast<std::uint16_t>(s.nsoll_a);
    case Satzanw: return s.satzanw;
    case MdiTarpos: return static_cast<std::uint32_t>(s.mdi_tarpos);
    case MdiVelocity: return s.mdi_velocity;
    case MdiAcc: return s.mdi_acc;
    case MdiDec: return s.mdi_dec;
    case MdiMod: return s.mdi_mod;
    case HomeDist: return static_cast<std::uint32_t>(s.home_dist);
    case HomeMode: return s.home_mode;
    case MtFeedrate: return s.mt_feedrate;
    case IlCmdFieldbus: return static_cast<std::uint16_t>(s.il_cmd);
    default: return 0;
  }
}
void set_raw(Setpoints& s, Signal sig, std::uint32_t v) noexcept {
  const auto u16 = static_cast<std::uint16_t>(v);
  switch (sig) {
    case Stw1: s.stw1 = u16; break;
    case Stw2: s.stw2 = u16; break;
    case NsollA: s.nsoll_a = static_cast<std::int16_t>(u16); break;
    case Satzanw: s.satzanw = u16; break;
    case MdiTarpos: s.mdi_tarpos = static_cast<std::int32_t>(v); break;
    case MdiVelocity: s.mdi_velocity = v; break;
    case MdiAcc: s.mdi_acc = u16; break;
    case MdiDec: s.mdi_dec = u16; break;
    case MdiMod: s.mdi_mod = u16; break;
    case HomeDist: s.home_dist = static_cast<std::int32_t>(v); break;
    case HomeMode: s.home_mode = u16; break;
    case MtFeedrate: s.mt_feedrate = u16; break;
    case IlCmdFieldbus: s.il_cmd = static_cast<std::int16_t>(u16); break;
    default: break;
  }
}
std::uint32_t raw_of(const Actuals& a, Signal sig) noexcept {
  switch (sig) {
    case Zsw1: return a.zsw1;
    case Zsw2: return a.zsw2;
    case NistA: return static_cast<std::uint16_t>(a.nist_a);
    case Aktsatz: return a.aktsatz;
    case XistA: return static_cast<std::uint32_t>(a.xist_a);
    case ItistGlatt: return static_cast<std::uint16_t>(a.itist_glatt);
    case XistError: return static_cast<std::uint16_t>(a.xist_error);
    case DriveMotionStatus: return a.drive_motion_status;
    case DriveInputs: return a.drive_inputs;
    default: return 0;
  }
}
void set_raw(Actuals& a, Signal sig, std::uint32_t v) noexcept {
  const auto u16 = static_cast<std::uint16_t>(v);
  switch (sig) {
    case Zsw1: a.zsw1 = u16; break;
    case Zsw2: a.zsw2 = u16; break;
    case NistA: a.nist_a = static_cast<std::int16_t>(u16); break;
    case Aktsatz: a.aktsatz = u16; break;
    case XistA: a.xist_a = static_cast<std::int32_t>(v); break;
    case ItistGlatt: a.itist_glatt = static_cast<std::int16_t>(u16); break;
    case XistError: a.xist_error = static_cast<std::int16_t>(u16); break;
    case DriveMotionStatus: a.drive_motion_status = u16; break;
    case DriveInputs: a.drive_inputs = u16; break;
    default: break;
  }
}

template <typename Values>
TelegramError encode_image(std::span<const SignalSlot> slots, std::size_t bytes, const Values& v,
                           std::span<std::uint8_t> out) noexcept {
  if (out.size() != bytes) return TelegramError::WrongLength;
  for (auto& b : out) b = 0;
  for (const SignalSlot& s : slots) put_be(out, s.word, words_of(s.signal), raw_of(v, s.signal));
  return TelegramError::None;
}

template <typename Values>
TelegramError decode_image(std::span<const SignalSlot> slots, std::size_t bytes, std::span<const std::uint8_t> in,
                           Values& v) noexcept {
  if (in.size() != bytes) return TelegramError::WrongLength;
  for (const SignalSlot& s : slots) set_raw(v, s.signal, get_be(in, s.word, words_of(s.signal)));
  return TelegramError::None;
}

// One PNU 915/916 list into slots.
TelegramError read_list(std::span<const std::uint16_t> list, std::size_t image_words, Direction dir,
                        std::array<SignalSlot, kMaxTelegramWords>& slots, std::uint8_t& count, std::size_t& at) noexcept {
  count = 0;
  if (image_words > kMaxTelegramWords) {
    at = 0;
    return TelegramError::TooManyWords;
  }
  if (list.size() > image_words) {
    at = image_words;
    return TelegramError::TooManyWords;
  }
  for (std::size_t i = 0; i < list.size(); ++i) {
    at = i;
    if (list[i] == 0) continue;
    const SignalInfo* info = find_signal(list[i]);
    if (info == nullptr) return TelegramError::UnknownSignal;
    if (info->direction != dir) return TelegramError::WrongDirection;
    for (std::size_t k = 0; k < count; ++k) {
      if (slots[k].signal == info->signal) return TelegramError::DuplicateSignal;
    }
    if (info->words == 2) {
      // The second word: the same number or 0, inside the image.
      if (i + 1 >= image_words) return TelegramError::SplitSignal;
      if (i + 1 < list.size() && list[i + 1] != 0 && list[i + 1] != list[i]) return TelegramError::SplitSignal;
    }
    slots[count++] = SignalSlot{info->signal, static_cast<std::uint8_t>(i)};
    if (info->words == 2) ++i;
  }
  return TelegramError::None;
}

}  // namespace

const SignalInfo* find_signal(std::uint16_t number) noexcept {
  for (const SignalInfo& s : kSignals) {
    if (static_cast<std::uint16_t>(s.signal) == number) return &s;
  }
  return nullptr;
}

bool TelegramLayout::carries(Signal s) const noexcept {
  for (const SignalSlot& slot : setpoint_slots()) {
    if (slot.signal == s) return true;
  }
  for (const SignalSlot& slot : actual_slots()) {
    if (slot.signal == s) return true;
  }
  return false;
}

std::string_view to_string(TelegramError e) noexcept {
  switch (e) {
    case TelegramError::None: return "ok";
    case TelegramError::WrongLength: return "the image is not the telegram's length";
    case TelegramError::UnknownTelegram: return "telegram number without a fixed layout";
    case TelegramError::UnknownSignal: return "signal number the drive does not define";
    case TelegramError::WrongDirection: return "signal mapped in the wrong direction";
    case TelegramError::SplitSignal: return "32-bit signal without its second word";
    case TelegramError::DuplicateSignal: return "signal mapped twice";
    case TelegramError::TooManyWords: return "more words than the telegram holds";
  }
  return "unknown telegram error";
}

std::optional<TelegramLayout> standard_layout(std::uint16_t telegram) noexcept {
  switch (telegram) {
    case 1: return packed(1, {Stw1, NsollA}, {Zsw1, NistA});  // §14.2
    case 7: return packed(7, {Stw1, Satzanw}, {Zsw1, Aktsatz});  // §14.3
    case 9:  // §14.4
      return packed(9, {Stw1, Satzanw, Stw2, MdiTarpos, MdiVelocity, MdiAcc, MdiDec, MdiMod},
                    {Zsw1, Aktsatz, Zsw2, XistA});
    case 350: return packed(350, {Stw1, NsollA}, {Zsw1, NistA, ItistGlatt});  // §14.5
    case 351: return packed(351, {Stw1, NsollA}, {Zsw1, NistA, ItistGlatt, XistA});  // §14.6
    case 352:  // §14.7
      return packed(352, {Stw1, Satzanw, Stw2, MdiTarpos, MdiVelocity, MdiAcc, MdiDec, MdiMod, HomeDist},
                    {Zsw1, Aktsatz, Zsw2, XistA});
    case 353:  // §14.8
      return packed(353, {Stw1, Satzanw, Stw2, MdiTarpos, MdiVelocity, MdiAcc, MdiDec, MdiMod, HomeDist, HomeMode},
                    {Zsw1, Aktsatz, Zsw2, XistA});
    default: return std::nullopt;
  }
}

std::optional<TelegramSize> telegram_size(std::uint16_t telegram) noexcept {
  if (telegram == 400) return TelegramSize{24, 24};  // §4.3, §14.9
  const auto l = standard_layout(telegram);
  if (!l) return std::nullopt;
  return TelegramSize{l->setpoint_bytes(), l->actual_bytes()};
}

LayoutResult free_layout(std::uint16_t telegram, std::span<const std::uint16_t> pnu915, std::size_t setpoint_words,
                         std::span<const std::uint16_t> pnu916, std::size_t actual_words) noexcept {
  LayoutResult r;
  r.layout.number = telegram;
  if (telegram != 0 && telegram != 400) {
    r.error = TelegramError::UnknownTelegram;
    return r;
  }
  r.error = read_list(pnu915, setpoint_words, Direction::Setpoint, r.layout.setpoints, r.layout.setpoint_count, r.at);
  if (r.error != TelegramError::None) return r;
  r.pnu916 = true;
  r.error = read_list(pnu916, actual_words, Direction::Actual, r.layout.actuals, r.layout.actual_count, r.at);
  if (r.error != TelegramError::None) return r;
  r.pnu916 = false;
  r.at = 0;
  r.layout.setpoint_words = static_cast<std::uint8_t>(setpoint_words);
  r.layout.actual_words = static_cast<std::uint8_t>(actual_words);
  return r;
}

TelegramError encode_setpoints(const TelegramLayout& layout, const Setpoints& in, std::span<std::uint8_t> out) noexcept {
  return encode_image(layout.setpoint_slots(), layout.setpoint_bytes(), in, out);
}
TelegramError decode_actuals(const TelegramLayout& layout, std::span<const std::uint8_t> in, Actuals& out) noexcept {
  return decode_image(layout.actual_slots(), layout.actual_bytes(), in, out);
}
TelegramError encode_actuals(const TelegramLayout& layout, const Actuals& in, std::span<std::uint8_t> out) noexcept {
  return encode_image(layout.actual_slots(), layout.actual_bytes(), in, out);
}
TelegramError decode_setpoints(const TelegramLayout& layout, std::span<const std::uint8_t> in, Setpoints& out) noexcept {
  return decode_image(layout.setpoint_slots(), layout.setpoint_bytes(), in, out);
}

}  // namespace drivegate::profidrive
