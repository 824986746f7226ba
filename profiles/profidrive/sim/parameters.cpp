// DriveModel: the parameter channel, record 47 [akd-profinet-profidrive.md §5], with the PNUs of
// §11 the gateway needs: identification, telegram configuration, operating mode, fault buffer,
// scaling, jog, homing, the motion-task table and the PN parameters.
#include <algorithm>

#include "profiles/profidrive/sim/drive_model.hpp"

namespace drivegate::profidrive::sim {
namespace {

// PROFIdrive error numbers [§5.4, STD]; kOk marks success in the functions below.
namespace err {
inline constexpr std::uint16_t kOk = 0xFFFF;
inline constexpr std::uint16_t kNoPnu = 0x00;
inline constexpr std::uint16_t kReadOnly = 0x01;
inline constexpr std::uint16_t kLimit = 0x02;
inline constexpr std::uint16_t kSubindex = 0x03;
inline constexpr std::uint16_t kNoArray = 0x04;
inline constexpr std::uint16_t kDataType = 0x05;
inline constexpr std::uint16_t kDescriptionReadOnly = 0x07;
inline constexpr std::uint16_t kNoDescription = 0x09;
inline constexpr std::uint16_t kNoText = 0x0F;
inline constexpr std::uint16_t kOperatingState = 0x11;
inline constexpr std::uint16_t kValue = 0x14;
inline constexpr std::uint16_t kTooLong = 0x15;
inline constexpr std::uint16_t kAddress = 0x16;
inline constexpr std::uint16_t kFormat = 0x17;
inline constexpr std::uint16_t kValueCount = 0x18;
inline constexpr std::uint16_t kAxis = 0x19;
}  // namespace err

enum class Kind : std::uint8_t { ReadOnly, ReadWrite, Command };

struct PnuDef {
  std::uint16_t pnu;
  std::uint8_t format;    // 41h/42h/43h, the size the AKD gives it [§11.4]
  std::uint8_t elements;  // 0: a simple parameter; arrays: their length (915/916: the image's words)
  Kind kind;
};

using format::kByte;
using format::kDWord;
using format::kWord;

// PNU 965: profile number 3 (PROFIdrive), version 41 (4.1) [STD, §11.1].
constexpr std::uint16_t kProfileId = 0x0329;

constexpr std::array kPnus{
    // Signals as PNUs with the same number [§11.2].
    PnuDef{1, kWord, 0, Kind::ReadOnly}, PnuDef{2, kWord, 0, Kind::ReadOnly}, PnuDef{5, kWord, 0, Kind::ReadOnly},
    PnuDef{6, kWord, 0, Kind::ReadOnly}, PnuDef{28, kDWord, 0, Kind::ReadOnly}, PnuDef{32, kWord, 0, Kind::ReadOnly},
    PnuDef{33, kWord, 0, Kind::ReadOnly}, PnuDef{52, kWord, 0, Kind::ReadOnly},
    // Profile PNUs [§11.1].
    PnuDef{915, kWord, 0, Kind::ReadWrite}, PnuDef{916, kWord, 0, Kind::ReadWrite},
    PnuDef{922, kWord, 0, Kind::ReadOnly}, PnuDef{930, kWord, 0, Kind::ReadWrite},
    PnuDef{944, kWord, 0, Kind::ReadOnly}, PnuDef{947, kWord, kFaultBufferEntries, Kind::ReadOnly},
    PnuDef{964, kWord, 5, Kind::ReadOnly}, PnuDef{965, kWord, 0, Kind::ReadOnly},
    PnuDef{1001, kWord, 0, Kind::ReadWrite}, PnuDef{1002, kWord, 0, Kind::ReadWrite},
    PnuDef{1004, kWord, 0, Kind::ReadWrite}, PnuDef{1005, kWord, 0, Kind::ReadWrite},
    PnuDef{1006, kWord, 0, Kind::ReadWrite}, PnuDef{1007, kWord, 0, Kind::ReadWrite},
    PnuDef{1008, kWord, 0, Kind::ReadWrite},
    // AKD parameters [§11.4, §19].
    PnuDef{2135, kByte, 0, Kind::ReadWrite},   // DRV.OPMODE
    PnuDef{2157, kDWord, 0, Kind::ReadOnly},   // FBUS.PARAM01: the telegram
    PnuDef{2158, kDWord, 0, Kind::ReadWrite},  // FBUS.PARAM02
    PnuDef{2198, kDWord, 0, Kind::ReadWrite},  // HOME.DIST
    PnuDef{2203, kWord, 0, Kind::ReadWrite},   // HOME.MODE
    PnuDef{2205, kDWord, 0, Kind::ReadWrite},  // HOME.P
    PnuDef{2263, kDWord, 0, Kind::ReadWrite},  // MT.ACC
    PnuDef{2266, kDWord, 0, Kind::ReadWrite},  // MT.CNTL
    PnuDef{2268, kDWord, 0, Kind::ReadWrite},  // MT.DEC
    PnuDef{2271, kByte, 0, Kind::Command},     // MT.LOAD
    PnuDef{2274, kByte, 0, Kind::ReadWrite},   // MT.NUM
    PnuDef{2275, kDWord, 0, Kind::ReadWrite},  // MT.P
    PnuDef{2277, kByte, 0, Kind::Command},     // MT.SET
    PnuDef{2283, kDWord, 0, Kind::ReadWrite},  // MT.V_32
    PnuDef{2290, kDWord, 0, Kind::ReadWrite},  // PL.ERRFTHRESH
    PnuDef{2292, kDWord, 0, Kind::ReadWrite},  // PL.ERRWTHRESH
    PnuDef{3014, kDWord, 0, Kind::ReadWrite},  // PN.POSSCALE
    PnuDef{3022, kDWord, 0, Kind::ReadOnly},   // PN.TIMEOUTFTHRESH
};

const PnuDef* find_pnu(std::uint16_t pnu) noexcept {
  const auto it = std::find_if(kPnus.begin(), kPnus.end(), [pnu](const PnuDef& d) { return d.pnu == pnu; });
  return it == kPnus.end() ? nullptr : &*it;
}

// Requests the decoder refuses, as PROFIdrive error numbers.
std::uint16_t error_for(ParamError e) noexcept {
  switch (e) {
    case ParamError::BadFormat:
    case ParamError::UnknownFormat:
    case ParamError::BadZeroBlock: return err::kFormat;
    case ParamError::ValueCountMismatch:
    case ParamError::CountBeyondData: return err::kValueCount;
    default: return err::kAddress;
  }
}

// The signal number a fixed telegram carries in PZD word `word` (0 = none): P915/P916 of telegrams
// 1..353 show their layout [§13, STD].
std::uint16_t signal_in_word(std::span<const SignalSlot> slots, std::size_t word) noexcept {
  for (const SignalSlot& s : slots) {
    const SignalInfo* info = find_signal(static_cast<std::uint16_t>(s.signal));
    const std::size_t words = info != nullptr ? info->words : 1;
    if (word >= s.word && word < s.word + words) return static_cast<std::uint16_t>(s.signal);
  }
  return 0;
}

constexpr std::size_t padded(std::size_t n) noexcept { return n + (n & 1U); }

void put_be(std::span<std::uint8_t> out, std::size_t width, std::uint32_t v) noexcept {
  for (std::size_t k = 0; k < width; ++k) out[k] = static_cast<std::uint8_t>(v >> (8 * (width - 1 - k)));
}

constexpr std::uint32_t as_u32(std::int32_t v) noexcept { return static_cast<std::uint32_t>(v); }
constexpr std::uint32_t as_u32(std::int16_t v) noexcept { return static_cast<std::uint16_t>(v); }

}  // namespace

RecordStatus DriveModel::write_parameter_record(std::span<const std::uint8_t> request) noexcept {
  if (request.size() < kParamHeaderSize || request.size() > kMaxParamRecord) return RecordStatus::WriteLengthError;
  // One request at a time: its response must be read before the next request [STD].
  if (response_size_ != 0) return RecordStatus::StateConflict;
  process_request(request);
  return RecordStatus::Ok;
}

RecordRead DriveModel::read_parameter_record(std::span<std::uint8_t> out) noexcept {
  if (response_size_ == 0) return {RecordStatus::StateConflict, 0};
  if (out.size() < response_size_) return {RecordStatus::BufferTooSmall, 0};
  std::copy_n(response_.begin(), response_size_, out.begin());
  const std::size_t n = response_size_;
  response_size_ = 0;
  return {RecordStatus::Ok, n};
}

void DriveModel::reject_request(std::span<const std::uint8_t> in, std::uint16_t error) noexcept {
  // A request the drive cannot read is answered with one error block [STD].
  ParamResponse r;
  r.reference = in[0];
  r.response_id = in[1] == static_cast<std::uint8_t>(RequestId::Change) ? response_id::kChangeFailed : response_id::kReadFailed;
  r.axis = in[2];
  r.count = r.block_count = 1;
  put_be(values_, 2, error);
  r.blocks[0] = ValueBlock{format::kError, 1, std::span<const std::uint8_t>(values_).first(2)};
  const EncodeResult e = encode_param_response(response_, r);
  response_size_ = e.size;
}

void DriveModel::process_request(std::span<const std::uint8_t> in) noexcept {
  const RequestResult decoded = decode_param_request(in);
  if (decoded.error != ParamError::None) {
    reject_request(in, error_for(decoded.error));
    return;
  }
  const ParamRequest& q = decoded.request;
  const bool change = q.id == RequestId::Change;
  ParamResponse r;
  r.reference = q.reference;
  r.axis = q.axis;
  r.count = r.block_count = q.count;
  bool any_error = false;
  std::size_t used = 0;                      // bytes of values_ in use
  std::size_t total = kParamHeaderSize;      // response bytes so far
  for (std::size_t i = 0; i < q.count; ++i) {
    // Room for an error block for every parameter still to come.
    const std::size_t reserve = 4 * (q.count - i - 1);
    std::uint16_t e = err::kOk;
    ValueBlock b{change ? format::kAkdNone : format::kByte, 0, {}};
    if (q.axis != 0) {
      e = err::kAxis;  // the AKD has one drive object, 0 [§5.2]
    } else if (change) {
      e = change_parameter(q.params[i], q.values[i]);
    } else {
      const std::size_t room = kMaxParamRecord - total - reserve;
      // Whole words, so an odd Byte block's pad fits too.
      const std::size_t fits = std::min(room > 2 ? (room - 2) & ~std::size_t{1} : 0, values_.size() - used);
      const std::span<std::uint8_t> data = std::span(values_).subspan(used, fits);
      std::uint8_t fmt = 0;
      e = read_parameter(q.params[i], data, fmt);
      if (e == err::kOk) b = ValueBlock{fmt, q.params[i].elements, data.first(format_size(fmt) * q.params[i].elements)};
    }
    if (e != err::kOk) {
      any_error = true;
      const std::span<std::uint8_t> data = std::span(values_).subspan(used, 2);
      put_be(data, 2, e);
      b = ValueBlock{format::kError, 1, data};
    }
    used += padded(b.data.size());
    total += 2 + padded(b.data.size());
    r.blocks[i] = b;
  }
  if (change && any_error) {
    // Successful changes in a negative reply: 40h "zero" blocks [STD].
    for (ValueBlock& b : std::span(r.blocks).first(q.count)) {
      if (b.format == format::kAkdNone) b.format = format::kZero;
    }
  }
  // A positive change reply is the AKD's "ref 02 00 n" plus 00 00 per parameter [§5.5].
  r.response_id = change ? (any_error ? response_id::kChangeFailed : response_id::kChangeOk)
                         : (any_error ? response_id::kReadFailed : response_id::kReadOk);
  response_size_ = encode_param_response(response_, r).size;
}

std::uint16_t DriveModel::read_parameter(const ParamAddress& a, std::span<std::uint8_t> data, std::uint8_t& fmt) noexcept {
  const PnuDef* def = find_pnu(a.pnu);
  if (def == nullptr) return err::kNoPnu;
  if (a.attribute == Attribute::Description) return err::kNoDescription;  // values only [§5.1]
  if (a.attribute == Attribute::Text) return err::kNoText;
  const std::size_t length = a.pnu == 915 ? layout_.setpoint_words : a.pnu == 916 ? layout_.actual_words : def->elements;
  if (length == 0 && (a.subindex != 0 || a.elements != 1)) return err::kNoArray;
  if (length != 0 && static_cast<std::size_t>(a.subindex) + a.elements > length) return err::kSubindex;
  const std::size_t width = format_size(def->format);
  if (data.size() < width * a.elements) return err::kTooLong;
  for (std::size_t i = 0; i < a.elements; ++i) {
    const auto v = pnu_value(a.pnu, static_cast<std::uint16_t>(a.subindex + i));
    put_be(data.subspan(i * width), width, v.value_or(0));
  }
  fmt = def->format;
  return err::kOk;
}

std::uint16_t DriveModel::change_parameter(const ParamAddress& a, const ValueBlock& values) noexcept {
  const PnuDef* def = find_pnu(a.pnu);
  if (def == nullptr) return err::kNoPnu;
  if (a.attribute != Attribute::Value) return a.attribute == Attribute::Text ? err::kNoText : err::kDescriptionReadOnly;
  if (def->kind == Kind::ReadOnly) return err::kReadOnly;
  if (def->kind == Kind::Command) return set_pnu(a.pnu, values.value(0));  // the value is not used
  if (values.format != def->format) return err::kDataType;
  const bool list = a.pnu == 915 || a.pnu == 916;
  const std::size_t length = a.pnu == 915 ? free_setpoint_words_ : a.pnu == 916 ? free_actual_words_ : def->elements;
  // The signal lists are writable only for the free telegrams [§13]; fixed telegrams read them.
  if (list && length == 0) return err::kReadOnly;
  if (length == 0 && (a.subindex != 0 || a.elements != 1)) return err::kNoArray;
  if (length != 0 && static_cast<std::size_t>(a.subindex) + a.elements > length) return err::kSubindex;
  if (list) {
    if (state_ == State::S4Operation) return err::kOperatingState;
    auto& target = a.pnu == 915 ? pnu915_ : pnu916_;
    const auto keep = target;
    for (std::size_t i = 0; i < a.elements; ++i) target[a.subindex + i] = static_cast<std::uint16_t>(values.value(i));
    const LayoutResult check = free_layout(config_.telegram, std::span<const std::uint16_t>(pnu915_).first(free_setpoint_words_),
                                           free_setpoint_words_, std::span<const std::uint16_t>(pnu916_).first(free_actual_words_),
                                           free_actual_words_);
    if (check.error != TelegramError::None) {
      target = keep;
      return err::kValue;
    }
    layout_ = check.layout;
    return err::kOk;
  }
  return set_pnu(a.pnu, values.value(0));
}

std::optional<std::uint32_t> DriveModel::pnu_value(std::uint16_t pnu, std::uint16_t sub) const noexcept {
  const Identification& id = config_.identification;
  switch (pnu) {
    case 1: return sp_.stw1;
    case 2: return actuals_.zsw1;
    case 5: return as_u32(sp_.nsoll_a);
    case 6: return as_u32(actuals_.nist_a);
    case 28: return as_u32(actuals_.xist_a);
    case 32: return sp_.satzanw;
    case 33: return actuals_.aktsatz;
    case 52: return as_u32(actuals_.itist_glatt);
    case 915: return free_setpoint_words_ != 0 ? pnu915_[sub] : signal_in_word(layout_.setpoint_slots(), sub);
    case 916: return free_actual_words_ != 0 ? pnu916_[sub] : signal_in_word(layout_.actual_slots(), sub);
    case 922:
    case 2157: return config_.telegram;
    case 930:
    case 2135: return static_cast<std::uint32_t>(mode_);
    case 944: return fault_counter_;
    case 947: return faults_[sub];
    case 964: {
      const std::array<std::uint16_t, 5> v{id.manufacturer, id.device_type, id.firmware_version, id.firmware_year,
                                           id.firmware_day_month};
      return v[sub];
    }
    case 965: return kProfileId;
    case 1001:
    case 2203: return home_mode_;
    case 1002: return single_turn_bits_;
    case 1004: return as_u32(jog_[0]);
    case 1005: return as_u32(jog_[1]);
    case 1006: return jog_acc_;
    case 1007: return jog_dec_;
    case 1008: return pnu1008_;
    case 2158: return fbus_param02_;
    case 2198: return as_u32(home_dist_);
    case 2205: return as_u32(home_p_);
    case 2263: return mt_edit_.acceleration;
    case 2266: return mt_edit_.control;
    case 2268: return mt_edit_.deceleration;
    case 2274: return mt_num_;
    case 2275: return as_u32(mt_edit_.position);
    case 2283: return mt_edit_.velocity;
    case 2290: return pl_errfthresh_;
    case 2292: return pl_errwthresh_;
    case 3014: return posscale_;
    case 3022: return config_.watchdog_ms;
    default: return std::nullopt;  // commands read as 0
  }
}

std::uint16_t DriveModel::set_pnu(std::uint16_t pnu, std::uint32_t v) noexcept {
  const auto in = [v](std::uint32_t lo, std::uint32_t hi) { return v >= lo && v <= hi; };
  switch (pnu) {
    case 930:
    case 2135:
      // Speed (1) or position (2) [§11.1, §15, §16.1]; not while the drive is in operation [sim].
      if (!in(1, 2)) return err::kLimit;
      if (state_ == State::S4Operation) return err::kOperatingState;
      mode_ = static_cast<OperatingMode>(v);
      return err::kOk;
    case 1001:
    case 2203:
      // HOME.MODE [§16.4]: the modes the model runs (current position, home switch).
      if (v != 0 && v != 4) return err::kLimit;
      home_mode_ = static_cast<std::uint16_t>(v);
      return err::kOk;
    case 1002:
      if (!in(1, 31)) return err::kLimit;  // single-turn bits [§17.2]
      if (state_ == State::S4Operation) return err::kOperatingState;
      single_turn_bits_ = static_cast<std::uint16_t>(v);
      return err::kOk;
    case 1004: jog_[0] = static_cast<std::int16_t>(v); return err::kOk;
    case 1005: jog_[1] = static_cast<std::int16_t>(v); return err::kOk;
    case 1006:
    case 1007:
      if (v == 0) return err::kLimit;
      (pnu == 1006 ? jog_acc_ : jog_dec_) = static_cast<std::uint16_t>(v);
      return err::kOk;
    case 1008: pnu1008_ = static_cast<std::uint16_t>(v); return err::kOk;
    case 2158: fbus_param02_ = v; return err::kOk;
    case 2198: home_dist_ = static_cast<std::int32_t>(v); return err::kOk;
    case 2205: home_p_ = static_cast<std::int32_t>(v); return err::kOk;
    // The motion-task table [§16.1, MT.* §11.4]: MT.NUM selects the task, MT.P/V_32/ACC/DEC/CNTL
    // edit it, MT.SET stores it, MT.LOAD reads it back. Values in the MDI signals' units [sim].
    case 2263:
    case 2268:
      if (!in(1, 0xFFFF)) return err::kLimit;
      (pnu == 2263 ? mt_edit_.acceleration : mt_edit_.deceleration) = static_cast<std::uint16_t>(v);
      return err::kOk;
    case 2266:
      if (!in(0, 1)) return err::kLimit;  // bit 0 only, as MDI_MOD [§12.2]
      mt_edit_.control = static_cast<std::uint16_t>(v);
      return err::kOk;
    case 2271: mt_edit_ = tasks_[mt_num_]; return err::kOk;
    case 2274:
      if (v >= kMotionTasks) return err::kLimit;
      mt_num_ = static_cast<std::uint8_t>(v);
      return err::kOk;
    case 2275: mt_edit_.position = static_cast<std::int32_t>(v); return err::kOk;
    case 2277: tasks_[mt_num_] = mt_edit_; return err::kOk;
    case 2283:
      if (v == 0) return err::kLimit;
      mt_edit_.velocity = v;
      return err::kOk;
    case 2290: pl_errfthresh_ = v; return err::kOk;
    case 2292: pl_errwthresh_ = v; return err::kOk;
    case 3014:
      if (!in(1, 1000000)) return err::kLimit;  // [§19.1]
      posscale_ = v;
      return err::kOk;
    default: return err::kReadOnly;
  }
}

}  // namespace drivegate::profidrive::sim
