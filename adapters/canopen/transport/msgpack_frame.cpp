#include "adapters/canopen/transport/msgpack_frame.hpp"

#include <array>
#include <bit>
#include <string_view>

namespace drivegate::canopen {
namespace {

// The keys in python-can's pack_message() order, which the encoder keeps.
enum Key : std::uint8_t {
  kTimestamp,
  kArbitrationId,
  kIsExtendedId,
  kIsRemoteFrame,
  kIsErrorFrame,
  kChannel,
  kDlc,
  kData,
  kIsFd,
  kBitrateSwitch,
  kErrorStateIndicator,
  kKeyCount,
};

constexpr std::array<std::string_view, kKeyCount> kKeys = {
    "timestamp", "arbitration_id", "is_extended_id", "is_remote_frame", "is_error_frame", "channel",
    "dlc",       "data",           "is_fd",          "bitrate_switch",  "error_state_indicator"};

int key_index(std::span<const std::uint8_t> name) noexcept {
  const std::string_view s(reinterpret_cast<const char*>(name.data()), name.size());
  for (std::size_t i = 0; i < kKeys.size(); ++i) {
    if (kKeys[i] == s) return static_cast<int>(i);
  }
  return -1;
}

class Writer {
 public:
  explicit Writer(std::span<std::uint8_t> out) noexcept : out_(out) {}

  void byte(std::uint8_t b) noexcept {
    if (pos_ < out_.size()) {
      out_[pos_] = b;
    } else {
      overflow_ = true;
    }
    ++pos_;
  }
  void big_endian(std::uint64_t v, int bytes) noexcept {
    for (int i = bytes - 1; i >= 0; --i) byte(static_cast<std::uint8_t>(v >> (8 * i)));
  }
  void str(std::string_view s) noexcept {  // every key is shorter than 32: fixstr
    byte(static_cast<std::uint8_t>(0xA0U | s.size()));
    for (const char c : s) byte(static_cast<std::uint8_t>(c));
  }
  // The smallest encoding, as msgpack-python chooses it for a Python int >= 0.
  void uint(std::uint64_t v) noexcept {
    if (v < 0x80) {
      byte(static_cast<std::uint8_t>(v));
    } else if (v <= 0xFF) {
      byte(0xCC);
      big_endian(v, 1);
    } else if (v <= 0xFFFF) {
      byte(0xCD);
      big_endian(v, 2);
    } else if (v <= 0xFFFFFFFFU) {
      byte(0xCE);
      big_endian(v, 4);
    } else {
      byte(0xCF);
      big_endian(v, 8);
    }
  }
  void boolean(bool b) noexcept { byte(b ? 0xC3 : 0xC2); }
  void float64(double d) noexcept {
    byte(0xCB);
    big_endian(std::bit_cast<std::uint64_t>(d), 8);
  }
  [[nodiscard]] std::size_t finish() const noexcept { return overflow_ ? 0 : pos_; }

 private:
  std::span<std::uint8_t> out_;
  std::size_t pos_ = 0;
  bool overflow_ = false;
};

// One msgpack object as far as a field needs it. Arrays and maps are reported with their element
// count and not consumed; ext values are consumed and reported as Other.
struct Value {
  enum class Kind : std::uint8_t { Nil, Bool, UInt, NegInt, Float, Str, Bin, Array, Map, Other };
  Kind kind = Kind::Nil;
  bool b = false;
  std::uint64_t u = 0;  // UInt value; Array/Map element count
  std::int64_t i = 0;   // NegInt value
  double f = 0.0;
  std::span<const std::uint8_t> bytes;  // Str/Bin contents
};

class Reader {
 public:
  explicit Reader(std::span<const std::uint8_t> in) noexcept : in_(in) {}

  [[nodiscard]] std::size_t left() const noexcept { return in_.size() - pos_; }

  bool big_endian(std::size_t n, std::uint64_t& v) noexcept {
    if (left() < n) return false;
    v = 0;
    for (std::size_t i = 0; i < n; ++i) v = (v << 8) | in_[pos_ + i];
    pos_ += n;
    return true;
  }
  bool take(std::size_t n, std::span<const std::uint8_t>& out) noexcept {
    if (left() < n) return false;
    out = in_.subspan(pos_, n);
    pos_ += n;
    return true;
  }

  // Reads one object header (and the payload of scalars, strings, bins and exts).
  MsgpackFrameError object(Value& v) noexcept {
    std::uint64_t t = 0;
    if (!big_endian(1, t)) return MsgpackFrameError::Truncated;
    v = Value{};
    if (t <= 0x7F) return uint_value(t, v);
    if (t <= 0x8F) return container(Value::Kind::Map, t & 0x0FU, v);
    if (t <= 0x9F) return container(Value::Kind::Array, t & 0x0FU, v);
    if (t <= 0xBF) return blob(Value::Kind::Str, t & 0x1FU, v);
    if (t >= 0xE0) return signed_value(static_cast<std::int64_t>(t) - 0x100, v);
    std::uint64_t x = 0;
    switch (t) {
      case 0xC0: v.kind = Value::Kind::Nil; return MsgpackFrameError::None;
      case 0xC2:
      case 0xC3: v.kind = Value::Kind::Bool; v.b = t == 0xC3; return MsgpackFrameError::None;
      case 0xC4: case 0xC5: case 0xC6:
        if (!big_endian(std::size_t{1} << (t - 0xC4), x)) return MsgpackFrameError::Truncated;
        return blob(Value::Kind::Bin, x, v);
      case 0xC7: case 0xC8: case 0xC9:
        if (!big_endian(std::size_t{1} << (t - 0xC7), x)) return MsgpackFrameError::Truncated;
        return ext(x, v);
      case 0xCA:
        if (!big_endian(4, x)) return MsgpackFrameError::Truncated;
        v.kind = Value::Kind::Float;
        v.f = static_cast<double>(std::bit_cast<float>(static_cast<std::uint32_t>(x)));
        return MsgpackFrameError::None;
      case 0xCB:
        if (!big_endian(8, x)) return MsgpackFrameError::Truncated;
        v.kind = Value::Kind::Float;
        v.f = std::bit_cast<double>(x);
        return MsgpackFrameError::None;
      case 0xCC: case 0xCD: case 0xCE: case 0xCF:
        if (!big_endian(std::size_t{1} << (t - 0xCC), x)) return MsgpackFrameError::Truncated;
        return uint_value(x, v);
      case 0xD0: case 0xD1: case 0xD2: case 0xD3: {
        const std::size_t n = std::size_t{1} << (t - 0xD0);
        if (!big_endian(n, x)) return MsgpackFrameError::Truncated;
        // Sign-extend the n-byte two's complement value.
        const int shift = static_cast<int>(64 - 8 * n);
        return signed_value(static_cast<std::int64_t>(x << shift) >> shift, v);
      }
      case 0xD4: case 0xD5: case 0xD6: case 0xD7: case 0xD8:
        return ext(std::uint64_t{1} << (t - 0xD4), v);
      case 0xD9: case 0xDA: case 0xDB:
        if (!big_endian(std::size_t{1} << (t - 0xD9), x)) return MsgpackFrameError::Truncated;
        return blob(Value::Kind::Str, x, v);
      case 0xDC: case 0xDD:
        if (!big_endian(std::size_t{2} << (t - 0xDC), x)) return MsgpackFrameError::Truncated;
        return container(Value::Kind::Array, x, v);
      case 0xDE: case 0xDF:
        if (!big_endian(std::size_t{2} << (t - 0xDE), x)) return MsgpackFrameError::Truncated;
        return container(Value::Kind::Map, x, v);
      default: return MsgpackFrameError::Malformed;  // 0xC1 is never used
    }
  }

  // Skips `count` whole objects without recursion: a container adds its elements to the count.
  // Every object takes at least one byte, so a count beyond the bytes left is a truncation; this
  // also bounds the count, whatever lengths the datagram claims.
  MsgpackFrameError skip(std::uint64_t count) noexcept {
    Value v;
    while (count > 0) {
      if (count > left()) return MsgpackFrameError::Truncated;
      --count;
      if (const auto e = object(v); e != MsgpackFrameError::None) return e;
      if (v.kind == Value::Kind::Array) count += v.u;
      if (v.kind == Value::Kind::Map) count += 2 * v.u;
    }
    return MsgpackFrameError::None;
  }

  // A field's value: like object(), but a container is skipped whole (it is never a valid field).
  MsgpackFrameError value(Value& v) noexcept {
    if (const auto e = object(v); e != MsgpackFrameError::None) return e;
    if (v.kind == Value::Kind::Array) return skip(v.u);
    if (v.kind == Value::Kind::Map) return skip(2 * v.u);
    return MsgpackFrameError::None;
  }

 private:
  static MsgpackFrameError uint_value(std::uint64_t x, Value& v) noexcept {
    v.kind = Value::Kind::UInt;
    v.u = x;
    return MsgpackFrameError::None;
  }
  static MsgpackFrameError signed_value(std::int64_t x, Value& v) noexcept {
    if (x >= 0) return uint_value(static_cast<std::uint64_t>(x), v);
    v.kind = Value::Kind::NegInt;
    v.i = x;
    return MsgpackFrameError::None;
  }
  static MsgpackFrameError container(Value::Kind kind, std::uint64_t count, Value& v) noexcept {
    v.kind = kind;
    v.u = count;
    return MsgpackFrameError::None;
  }
  MsgpackFrameError blob(Value::Kind kind, std::uint64_t n, Value& v) noexcept {
    if (n > left() || !take(static_cast<std::size_t>(n), v.bytes)) return MsgpackFrameError::Truncated;
    v.kind = kind;
    return MsgpackFrameError::None;
  }
  MsgpackFrameError ext(std::uint64_t n, Value& v) noexcept {  // type byte, then n bytes
    if (n >= left() || !take(static_cast<std::size_t>(n) + 1, v.bytes)) return MsgpackFrameError::Truncated;
    v.kind = Value::Kind::Other;
    return MsgpackFrameError::None;
  }

  std::span<const std::uint8_t> in_;
  std::size_t pos_ = 0;
};

// Python truthiness, as Message() applies it to its flag arguments.
bool flag(const Value& v, bool& out) noexcept {
  switch (v.kind) {
    case Value::Kind::Bool: out = v.b; return true;
    case Value::Kind::UInt: out = v.u != 0; return true;
    case Value::Kind::NegInt: out = true; return true;
    default: return false;
  }
}

}  // namespace

std::size_t encode_msgpack_frame(const CanFrame& frame, double timestamp_s, std::span<std::uint8_t> out) noexcept {
  if (!frame.valid()) return 0;
  Writer w(out);
  w.byte(0x80 | kKeyCount);  // fixmap
  w.str(kKeys[kTimestamp]);
  w.float64(timestamp_s);
  w.str(kKeys[kArbitrationId]);
  w.uint(frame.id);
  w.str(kKeys[kIsExtendedId]);
  w.boolean(frame.extended);
  w.str(kKeys[kIsRemoteFrame]);
  w.boolean(frame.remote);
  w.str(kKeys[kIsErrorFrame]);
  w.boolean(false);
  w.str(kKeys[kChannel]);
  w.byte(0xC0);
  w.str(kKeys[kDlc]);
  w.uint(frame.dlc);
  w.str(kKeys[kData]);
  const auto payload = frame.payload();
  w.byte(0xC4);  // bin8
  w.byte(static_cast<std::uint8_t>(payload.size()));
  for (const auto b : payload) w.byte(b);
  w.str(kKeys[kIsFd]);
  w.boolean(false);
  w.str(kKeys[kBitrateSwitch]);
  w.boolean(false);
  w.str(kKeys[kErrorStateIndicator]);
  w.boolean(false);
  return w.finish();
}

const char* to_string(MsgpackFrameError e) noexcept {
  switch (e) {
    case MsgpackFrameError::None: return "none";
    case MsgpackFrameError::Malformed: return "not msgpack";
    case MsgpackFrameError::Truncated: return "truncated";
    case MsgpackFrameError::NotAMap: return "not a msgpack map";
    case MsgpackFrameError::BadKey: return "map key is not a string";
    case MsgpackFrameError::DuplicateKey: return "key given twice";
    case MsgpackFrameError::WrongType: return "value of the wrong type";
    case MsgpackFrameError::MissingField: return "arbitration_id or is_extended_id missing";
    case MsgpackFrameError::IdOutOfRange: return "arbitration_id out of range";
    case MsgpackFrameError::DlcOutOfRange: return "dlc out of range";
    case MsgpackFrameError::DataTooLong: return "more than 8 data bytes";
    case MsgpackFrameError::Inconsistent: return "dlc, data and frame type disagree";
    case MsgpackFrameError::CanFd: return "CAN FD frame";
    case MsgpackFrameError::TrailingBytes: return "bytes after the map";
  }
  return "?";
}

MsgpackFrameDecoded decode_msgpack_frame(std::span<const std::uint8_t> bytes) noexcept {
  MsgpackFrameDecoded d;
  auto fail = [&d](MsgpackFrameError e) {
    d.error = e;
    return d;
  };
  Reader r(bytes);
  Value v;
  if (const auto e = r.object(v); e != MsgpackFrameError::None) return fail(e);
  if (v.kind != Value::Kind::Map) return fail(MsgpackFrameError::NotAMap);
  const std::uint64_t entries = v.u;

  std::uint32_t seen = 0;
  std::uint64_t id = 0;
  bool id_negative = false;
  bool has_dlc = false;
  std::uint64_t dlc = 0;
  std::size_t data_len = 0;
  bool fd = false;
  for (std::uint64_t i = 0; i < entries; ++i) {
    if (const auto e = r.object(v); e != MsgpackFrameError::None) return fail(e);
    if (v.kind != Value::Kind::Str) return fail(MsgpackFrameError::BadKey);
    const int key = key_index(v.bytes);
    if (key < 0) {  // a key python-can may add one day: its value is skipped
      if (const auto e = r.skip(1); e != MsgpackFrameError::None) return fail(e);
      continue;
    }
    const auto bit = std::uint32_t{1} << key;
    if ((seen & bit) != 0) return fail(MsgpackFrameError::DuplicateKey);
    seen |= bit;
    if (const auto e = r.value(v); e != MsgpackFrameError::None) return fail(e);

    bool ok = true;
    bool b = false;
    switch (key) {
      case kTimestamp:
        // Reported, not used: receivers stamp frames with their own reception time, as
        // python-can does (bus.py replaces the timestamp with the socket's).
        if (v.kind == Value::Kind::Float) {
          d.timestamp_s = v.f;
        } else if (v.kind == Value::Kind::UInt) {
          d.timestamp_s = static_cast<double>(v.u);
        } else if (v.kind == Value::Kind::NegInt) {
          d.timestamp_s = static_cast<double>(v.i);
        } else {
          ok = false;
        }
        break;
      case kArbitrationId:
        ok = v.kind == Value::Kind::UInt || v.kind == Value::Kind::NegInt;
        id = v.u;
        id_negative = v.kind == Value::Kind::NegInt;
        break;
      case kIsExtendedId: ok = flag(v, d.frame.extended); break;
      case kIsRemoteFrame: ok = flag(v, d.frame.remote); break;
      case kIsErrorFrame: ok = flag(v, d.error_frame); break;
      case kIsFd:
      case kBitrateSwitch:
      case kErrorStateIndicator:
        ok = flag(v, b);
        fd = fd || b;
        break;
      case kChannel:
        ok = v.kind == Value::Kind::Nil || v.kind == Value::Kind::Str || v.kind == Value::Kind::UInt ||
             v.kind == Value::Kind::NegInt;
        break;
      case kDlc:
        if (v.kind == Value::Kind::NegInt) return fail(MsgpackFrameError::DlcOutOfRange);
        ok = v.kind == Value::Kind::UInt || v.kind == Value::Kind::Nil;  // nil: from the data
        has_dlc = v.kind == Value::Kind::UInt;
        dlc = v.u;
        break;
      case kData:
        ok = v.kind == Value::Kind::Bin || v.kind == Value::Kind::Str || v.kind == Value::Kind::Nil;
        if (v.bytes.size() > kMaxDlc) return fail(MsgpackFrameError::DataTooLong);
        data_len = v.bytes.size();
        for (std::size_t k = 0; k < data_len; ++k) d.frame.data[k] = v.bytes[k];
        break;
      default: break;
    }
    if (!ok) return fail(MsgpackFrameError::WrongType);
  }
  if (r.left() != 0) return fail(MsgpackFrameError::TrailingBytes);

  // python-can defaults is_extended_id to True; other senders may not. An id whose format is a
  // guess would land on the wrong object, so both are required.
  const auto required = (std::uint32_t{1} << kArbitrationId) | (std::uint32_t{1} << kIsExtendedId);
  if ((seen & required) != required) return fail(MsgpackFrameError::MissingField);
  if (fd) return fail(MsgpackFrameError::CanFd);
  if (id_negative || id > (d.frame.extended ? kMaxExtendedId : kMaxStandardId)) {
    return fail(MsgpackFrameError::IdOutOfRange);
  }
  if (!has_dlc) dlc = data_len;  // Message(dlc=None) takes the data length
  if (dlc > kMaxDlc) return fail(MsgpackFrameError::DlcOutOfRange);
  // The same consistency rules as python-can's Message._check.
  if (d.frame.remote ? (data_len != 0 || d.error_frame) : dlc != data_len) {
    return fail(MsgpackFrameError::Inconsistent);
  }
  d.frame.id = static_cast<std::uint32_t>(id);
  d.frame.dlc = static_cast<std::uint8_t>(dlc);
  return d;
}

}  // namespace drivegate::canopen
