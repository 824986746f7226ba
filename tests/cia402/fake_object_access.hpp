#pragma once
// A scripted stand-in for a bus adapter: a small object dictionary (some objects "mapped" into the
// cyclic image), acyclic requests that finish after a set number of polls, and per-object aborts.
// Fixed-size storage so that it allocates nothing while the master runs (alloc test).
#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

#include "profiles/cia402/object_access.hpp"

namespace drivegate::cia402::test {

class FakeObjectAccess final : public ObjectAccess {
 public:
  struct Logged {
    ObjectId id;
    std::int64_t value;
  };

  // A change of the mapping is a new mapping generation, as an adapter's reconfiguration is.
  void map(ObjectId id) noexcept {
    slot(id).mapped = true;
    ++generation_;
  }
  void unmap(ObjectId id) noexcept {
    slot(id).mapped = false;
    ++generation_;
  }
  void set(ObjectId id, std::int64_t v) noexcept { slot(id).value = v; }
  [[nodiscard]] std::int64_t value(ObjectId id) const noexcept {
    for (const auto& o : objects_) {
      if (o.used && o.id == id) return o.value;
    }
    return 0;
  }
  void abort_on(ObjectId id, std::uint32_t code) noexcept { slot(id).abort = code; }
  void set_latency(int polls) noexcept { latency_ = polls; }
  void set_queue_full(bool full) noexcept { queue_full_ = full; }
  void set_fresh(bool fresh) noexcept { fresh_ = fresh; }
  void set_fault_report(DriveFaultReport r) noexcept { report_ = r; }
  DriveFaultReport fault_report() const noexcept override { return report_; }
  // Objects the fake bus owns (index only), and the control losses the master reported.
  void own(std::uint16_t index) noexcept { owned_index_ = index; }
  std::string_view owner_of(ObjectId id) const noexcept override {
    return id.index == owned_index_ ? std::string_view("owned by the test bus (its own configuration)")
                                    : std::string_view{};
  }
  void control_lost(std::string_view) noexcept override { ++control_losses_; }
  [[nodiscard]] int control_losses() const noexcept { return control_losses_; }

  // Acyclic writes in the order they were submitted (kept up to kLog entries).
  [[nodiscard]] std::size_t acyclic_writes() const noexcept { return log_count_; }
  [[nodiscard]] const Logged& acyclic_write(std::size_t i) const noexcept { return log_[i]; }
  [[nodiscard]] std::size_t acyclic_reads() const noexcept { return reads_; }
  [[nodiscard]] std::size_t pending_requests() const noexcept {
    std::size_t n = 0;
    for (const auto& r : requests_) n += r.used ? 1U : 0U;
    return n;
  }

  ImageRef resolve(ObjectId id) const noexcept override {
    for (std::size_t i = 0; i < objects_.size(); ++i) {
      if (objects_[i].used && objects_[i].id == id && objects_[i].mapped)
        return ImageRef::at(static_cast<std::uint16_t>(i), generation_);
    }
    return {};
  }
  std::uint32_t mapping_generation() const noexcept override { return generation_; }
  using ObjectAccess::read;
  using ObjectAccess::write;
  std::int64_t read(ImageRef ref) const noexcept override {
    return ref.current(generation_) ? objects_[ref.slot()].value : 0;
  }
  void write(ImageRef ref, std::int64_t v) noexcept override {
    if (ref.current(generation_)) objects_[ref.slot()].value = v;
  }
  bool inputs_fresh() const noexcept override { return fresh_; }

  RequestId submit_read(ObjectDef def) noexcept override {
    ++reads_;
    return add_request(def, false, 0);
  }
  RequestId submit_write(ObjectDef def, std::int64_t v) noexcept override {
    const RequestId id = add_request(def, true, v);
    if (id != kNoRequest && log_count_ < log_.size()) log_[log_count_++] = Logged{def.id, v};
    return id;
  }
  // Byte-level requests see an object as its bytes: those given by set_bytes(), else the value's
  // four little-endian bytes.
  void set_bytes(ObjectId id, std::span<const std::uint8_t> b) noexcept {
    Object& o = slot(id);
    o.size = std::min(b.size(), o.bytes.size());
    std::copy_n(b.begin(), o.size, o.bytes.begin());
  }
  [[nodiscard]] std::span<const std::uint8_t> bytes(ObjectId id) noexcept {
    Object& o = slot(id);
    return {o.bytes.data(), o.size};
  }
  RequestId submit_upload(ObjectId id, std::span<std::uint8_t> into, std::uint8_t /*expected*/) noexcept override {
    ++reads_;
    const RequestId r = add_request(ObjectDef{id, DataType::U32}, false, 0);
    if (Request* req = find(r)) req->into = into;
    return r;
  }
  RequestId submit_download(ObjectId id, std::span<const std::uint8_t> data) noexcept override {
    const RequestId r = add_request(ObjectDef{id, DataType::U32}, true, 0);
    Request* req = find(r);
    if (req == nullptr) return r;
    req->bytes = true;
    req->size = std::min(data.size(), req->data.size());
    std::copy_n(data.begin(), req->size, req->data.begin());
    if (log_count_ < log_.size()) log_[log_count_++] = Logged{id, static_cast<std::int64_t>(le(data))};
    return r;
  }
  RequestResult poll(RequestId id) noexcept override {
    for (auto& r : requests_) {
      if (!r.used || r.id != id) continue;
      if (--r.polls_left > 0) return {RequestState::Pending, 0, 0, 0, true};
      r.used = false;
      Object& o = slot(r.def.id);
      if (o.abort != 0) return {RequestState::Failed, 0, o.abort, 0, true};
      if (r.bytes) {
        set_bytes(r.def.id, {r.data.data(), r.size});
        o.value = static_cast<std::int64_t>(le({r.data.data(), r.size}));
        return {RequestState::Done, 0, 0, 0, true};
      }
      if (r.write) o.value = r.value;
      if (!r.into.empty()) {
        std::array<std::uint8_t, 4> four{};
        for (std::size_t i = 0; i < four.size(); ++i) four[i] = static_cast<std::uint8_t>(o.value >> (8 * i));
        const std::span<const std::uint8_t> from = o.size != 0 ? std::span<const std::uint8_t>(o.bytes.data(), o.size)
                                                               : std::span<const std::uint8_t>(four);
        if (from.size() > r.into.size()) return {RequestState::Failed, 0, 0x05040005, 0, true};
        std::copy(from.begin(), from.end(), r.into.begin());
        return {RequestState::Done, 0, 0, static_cast<std::uint32_t>(from.size()), true};
      }
      return {RequestState::Done, o.value, 0, 0, true};
    }
    return {};
  }
  void cancel(RequestId id) noexcept override {
    for (auto& r : requests_) {
      if (!r.used || r.id != id) continue;
      r.used = false;
      ++cancels_;
    }
  }
  [[nodiscard]] std::size_t cancels() const noexcept { return cancels_; }

 private:
  std::uint16_t owned_index_ = 0;
  int control_losses_ = 0;
  std::uint32_t generation_ = 0;

  struct Object {
    bool used = false;
    ObjectId id{};
    std::int64_t value = 0;
    bool mapped = false;
    std::uint32_t abort = 0;
    std::array<std::uint8_t, 64> bytes{};
    std::size_t size = 0;  // 0: the object is its value
  };
  struct Request {
    bool used = false;
    RequestId id = kNoRequest;
    ObjectDef def{};
    bool write = false;
    std::int64_t value = 0;
    int polls_left = 0;
    std::span<std::uint8_t> into{};  // submit_upload()
    bool bytes = false;              // submit_download(): data[0..size)
    std::array<std::uint8_t, 64> data{};
    std::size_t size = 0;
  };
  static std::uint64_t le(std::span<const std::uint8_t> b) noexcept {
    std::uint64_t v = 0;
    for (std::size_t i = std::min<std::size_t>(b.size(), 8); i-- > 0;) v = (v << 8) | b[i];
    return v;
  }
  Request* find(RequestId id) noexcept {
    for (auto& r : requests_)
      if (r.used && r.id == id) return &r;
    return nullptr;
  }

  Object& slot(ObjectId id) noexcept {
    for (auto& o : objects_) {
      if (o.used && o.id == id) return o;
    }
    for (auto& o : objects_) {
      if (!o.used) {
        o = Object{};
        o.used = true;
        o.id = id;
        return o;
      }
    }
    return objects_.back();  // full: tests never get here
  }
  RequestId add_request(ObjectDef def, bool write, std::int64_t v) noexcept {
    if (queue_full_) return kNoRequest;
    for (auto& r : requests_) {
      if (r.used) continue;
      r = Request{};
      r.used = true;
      r.id = ++next_id_;
      r.def = def;
      r.write = write;
      r.value = v;
      r.polls_left = latency_;
      return r.id;
    }
    return kNoRequest;
  }

  std::array<Object, 96> objects_{};
  std::array<Request, 32> requests_{};
  std::array<Logged, 256> log_{};
  std::size_t log_count_ = 0;
  std::size_t reads_ = 0;
  std::size_t cancels_ = 0;
  RequestId next_id_ = 0;
  int latency_ = 2;
  bool queue_full_ = false;
  bool fresh_ = true;
  DriveFaultReport report_{};
};

}  // namespace drivegate::cia402::test
