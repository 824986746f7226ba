#pragma once
// Shared pieces of the PDO tests: a small object store standing in for the simulated drive's
// dictionary, layout builders, SDO frames applied to a SlavePdos, and virtual time.
#include <gtest/gtest.h>

#include <array>
#include <chrono>
#include <cstdint>
#include <initializer_list>
#include <vector>

#include "adapters/canopen/master/pdo.hpp"
#include "adapters/canopen/sim/slave_pdo.hpp"
#include "adapters/canopen/wire/sdo_codec.hpp"

namespace drivegate::canopen::test {

using namespace std::chrono_literals;
using cia402::DataType;
using cia402::ObjectDef;
namespace obj = cia402::obj;

using Bytes = std::vector<std::uint8_t>;

// Manufacturer status register (AKD part 1 §12.6, part 2 §2.5): a U32 the TPDO1 remap maps.
inline constexpr ObjectDef kManufacturerStatus{{0x1002, 0}, DataType::U32};

// Virtual time: tests start well away from the epoch so "never" (TimePoint{}) is distinct.
inline constexpr core::TimePoint kT0{std::chrono::seconds(100)};

inline Bytes payload(const CanFrame& f) { return {f.data.begin(), f.data.begin() + f.dlc}; }

inline std::vector<CanFrame> drain(TxQueue& q) {
  std::vector<CanFrame> out;
  while (!q.empty()) {
    out.push_back(q.front());
    q.pop();
  }
  return out;
}

inline CanFrame sync_frame() { return make_frame(cob::kSync, {}); }

inline PdoLayout layout(std::initializer_list<ObjectDef> defs) {
  PdoLayout l;
  for (const auto& d : defs) {
    EXPECT_EQ(l.add(d, static_cast<std::uint8_t>(8 * cia402::size_of(d.type))), PdoLayout::Error::None);
  }
  return l;
}

inline std::uint32_t entry(ObjectDef d) {
  return encode_mapping({d.id, static_cast<std::uint8_t>(8 * cia402::size_of(d.type))});
}

inline sim::SlavePdoConfig slave_pdo(std::uint32_t cob_id, std::uint8_t type, std::initializer_list<ObjectDef> defs) {
  sim::SlavePdoConfig c;
  c.cob_id = cob_id;
  c.transmission_type = type;
  for (const auto& d : defs) c.mapping[c.count++] = entry(d);
  return c;
}

// The drive's objects: which ones an RPDO (rx) or TPDO (tx) may carry, and their values.
class FakeObjects final : public sim::PdoObjects {
 public:
  FakeObjects() {
    // The CiA 402 objects of the reference default mappings (AKD part 1 §12.5, NORD §8.1).
    for (const auto& d : {obj::kControlword, obj::kVlTargetVelocity, obj::kModesOfOperation, obj::kTargetPosition,
                          obj::kProfileVelocity, obj::kProfileAcceleration, obj::kProfileDeceleration,
                          obj::kTargetVelocity, obj::kTargetTorque}) {
      add(d, true, false);
    }
    for (const auto& d : {obj::kStatusword, obj::kVlVelocityActual, obj::kModesOfOperationDisplay, obj::kTorqueActual,
                          obj::kPositionActual, obj::kVelocityActual, kManufacturerStatus}) {
      add(d, false, true);
    }
    add(obj::kSupportedDriveModes, false, false);  // exists, not mappable
  }

  void add(ObjectDef def, bool rx, bool tx) { objects_[size_++] = {def, rx, tx, 0}; }
  void set(cia402::ObjectId id, std::int64_t v) noexcept { at(id).value = v; }
  [[nodiscard]] std::int64_t get(cia402::ObjectId id) const noexcept { return at(id).value; }
  [[nodiscard]] std::size_t writes() const noexcept { return writes_; }

  [[nodiscard]] std::optional<DataType> mappable(cia402::ObjectId id, bool receive) const noexcept override {
    const auto* o = find(id);
    if (o == nullptr || !(receive ? o->rx : o->tx)) return std::nullopt;
    return o->def.type;
  }
  [[nodiscard]] std::int64_t read(cia402::ObjectId id) const noexcept override { return at(id).value; }
  void write(cia402::ObjectId id, std::int64_t value) noexcept override {
    at(id).value = value;
    ++writes_;
  }

 private:
  struct Object {
    ObjectDef def;
    bool rx = false;
    bool tx = false;
    std::int64_t value = 0;
  };
  const Object* find(cia402::ObjectId id) const noexcept {
    for (std::size_t i = 0; i < size_; ++i) {
      if (objects_[i].def.id == id) return &objects_[i];
    }
    return nullptr;
  }
  Object* find(cia402::ObjectId id) noexcept {
    return const_cast<Object*>(static_cast<const FakeObjects*>(this)->find(id));
  }
  // The object, or a scratch entry for ids the fake does not hold (the slave only asks for
  // objects mappable() accepted, so tests never see the scratch value).
  Object& at(cia402::ObjectId id) noexcept {
    Object* o = find(id);
    return o != nullptr ? *o : scratch_;
  }
  const Object& at(cia402::ObjectId id) const noexcept {
    const Object* o = find(id);
    return o != nullptr ? *o : scratch_;
  }

  std::array<Object, 32> objects_{};
  Object scratch_{};
  std::size_t size_ = 0;
  std::size_t writes_ = 0;
};

// An SDO request frame's payload applied to the slave's object store as its SDO server would:
// returns the server's response payload (download confirmation or abort).
inline Bytes sdo(sim::SlavePdos& slave, const Bytes& request) {
  const auto d = decode_sdo_request(request);
  EXPECT_EQ(d.error, SdoDecodeError::None);
  EXPECT_EQ(d.message.command, SdoCommand::InitiateDownloadRequest);
  EXPECT_TRUE(d.message.expedited);
  const auto& m = d.message;
  const auto value = get_le(m.data, 0, m.length);
  const auto size = m.size_indicated ? m.length : std::uint8_t{0};
  const auto code = slave.write(m.object, value, size);
  const auto reply = code == 0 ? sdo_download_response(m.object) : sdo_abort(m.object, code);
  return {reply.begin(), reply.end()};
}

inline Bytes confirm(std::uint16_t index, std::uint8_t sub) {
  return {0x60, static_cast<std::uint8_t>(index & 0xFF), static_cast<std::uint8_t>(index >> 8), sub, 0, 0, 0, 0};
}

}  // namespace drivegate::canopen::test
