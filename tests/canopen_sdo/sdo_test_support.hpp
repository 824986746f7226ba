#pragma once
// Helpers shared by the SDO client and server tests: frames as (COB-ID, bytes) pairs that gtest can
// compare and print, conversations that can be played from either side, and an object store for
// the simulated server that does not allocate once set up.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <iomanip>
#include <ostream>
#include <span>
#include <utility>
#include <vector>

#include "adapters/canopen/master/tx_queue.hpp"
#include "adapters/canopen/sim/sdo_server.hpp"
#include "adapters/canopen/wire/can_frame.hpp"
#include "adapters/canopen/wire/sdo_codec.hpp"

namespace drivegate::canopen::test_sdo {

using Bytes = std::vector<std::uint8_t>;

struct Sent {
  std::uint32_t id = 0;
  Bytes data;
  friend bool operator==(const Sent&, const Sent&) = default;
};
using Frames = std::vector<Sent>;

inline std::ostream& operator<<(std::ostream& os, const Sent& s) {
  os << std::hex << std::uppercase << std::setfill('0') << std::setw(3) << s.id << ":";
  for (auto b : s.data) os << ' ' << std::setw(2) << unsigned{b};
  return os << std::dec;
}

inline CanFrame frame(std::uint32_t id, const Bytes& data) { return make_frame(id, std::span<const std::uint8_t>(data)); }

// Everything queued, oldest first; the queue is left empty.
inline Frames drain(TxQueue& tx) {
  Frames out;
  for (; !tx.empty(); tx.pop()) {
    const CanFrame& f = tx.front();
    out.push_back({f.id, Bytes(f.data.begin(), f.data.begin() + f.dlc)});
  }
  return out;
}

// One SDO exchange as the digests print it: who sends, and the 8 data bytes.
struct Step {
  bool from_client = true;
  Bytes data;
};
using Conversation = std::vector<Step>;

// `n` bytes 01 02 03 ... (the payload of SD6 TV-1/TV-2 for n = 16).
inline Bytes counting(std::size_t n) {
  Bytes b(n);
  for (std::size_t i = 0; i < n; ++i) b[i] = static_cast<std::uint8_t>(i + 1);
  return b;
}

// SD6 TV-1 (stoeber-sd6-canopen.md §11.1): segmented download of 01..10h. The manual leaves the
// object open (IL IH SS); 2000h:01 fills it in.
inline const ObjectId kTvObject{0x2000, 0x01};
inline Conversation sd6_tv1() {
  return {
      {true, {0x21, 0x00, 0x20, 0x01, 0x10, 0x00, 0x00, 0x00}},
      {false, {0x60, 0x00, 0x20, 0x01, 0x00, 0x00, 0x00, 0x00}},
      {true, {0x00, 0x01, 0x02, 0x03, 0x04, 0x05, 0x06, 0x07}},
      {false, {0x20, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00}},
      {true, {0x10, 0x08, 0x09, 0x0A, 0x0B, 0x0C, 0x0D, 0x0E}},
      {false, {0x30, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00}},
      {true, {0x0B, 0x0F, 0x10, 0x00, 0x00, 0x00, 0x00, 0x00}},
      {false, {0x20, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00}},
  };
}
// SD6 TV-2 (§11.1): segmented upload of the same 16 bytes.
inline Conversation sd6_tv2() {
  return {
      {true, {0x40, 0x00, 0x20, 0x01, 0x00, 0x00, 0x00, 0x00}},
      {false, {0x41, 0x00, 0x20, 0x01, 0x10, 0x00, 0x00, 0x00}},
      {true, {0x60, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00}},
      {false, {0x00, 0x01, 0x02, 0x03, 0x04, 0x05, 0x06, 0x07}},
      {true, {0x70, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00}},
      {false, {0x10, 0x08, 0x09, 0x0A, 0x0B, 0x0C, 0x0D, 0x0E}},
      {true, {0x60, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00}},
      {false, {0x0B, 0x0F, 0x10, 0x00, 0x00, 0x00, 0x00, 0x00}},
  };
}

// An object dictionary for the simulated server. Entries are added before the test runs; reads
// and writes then touch fixed storage only.
class TestBackend final : public sim::SdoBackend {
 public:
  static constexpr std::size_t kCapacity = 4140;  // more than the server's buffer, to test its limit

  TestBackend() { entries_.reserve(64); }

  void add(ObjectId id, const Bytes& value, bool writable = true) {
    Entry e;
    e.id = id;
    e.size = value.size();
    e.writable = writable;
    std::copy(value.begin(), value.end(), e.bytes.begin());
    entries_.push_back(e);
  }
  [[nodiscard]] Bytes value(ObjectId id) const {
    const Entry* e = find(id);
    return e == nullptr ? Bytes{} : Bytes(e->bytes.begin(), e->bytes.begin() + static_cast<std::ptrdiff_t>(e->size));
  }
  [[nodiscard]] std::size_t writes() const noexcept { return writes_; }

  sim::SdoReadResult sdo_read(ObjectId id, std::span<std::uint8_t> out) noexcept override {
    const Entry* e = find(id);
    if (e == nullptr) return {cia402::sdo_abort_code::kNoObject, 0};
    std::copy_n(e->bytes.begin(), std::min(e->size, out.size()), out.begin());
    return {0, e->size};
  }
  std::uint32_t sdo_write(ObjectId id, std::span<const std::uint8_t> data) noexcept override {
    Entry* e = find(id);
    if (e == nullptr) return cia402::sdo_abort_code::kNoObject;
    if (!e->writable) return cia402::sdo_abort_code::kReadOnly;
    std::copy(data.begin(), data.end(), e->bytes.begin());
    e->size = data.size();
    ++writes_;
    return 0;
  }

 private:
  struct Entry {
    ObjectId id{};
    std::array<std::uint8_t, kCapacity> bytes{};
    std::size_t size = 0;
    bool writable = true;
  };
  [[nodiscard]] const Entry* find(ObjectId id) const noexcept {
    const auto it = std::find_if(entries_.begin(), entries_.end(), [id](const Entry& e) { return e.id == id; });
    return it == entries_.end() ? nullptr : &*it;
  }
  Entry* find(ObjectId id) noexcept { return const_cast<Entry*>(std::as_const(*this).find(id)); }

  std::vector<Entry> entries_;
  std::size_t writes_ = 0;
};

}  // namespace drivegate::canopen::test_sdo
