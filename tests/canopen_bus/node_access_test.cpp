// NodeAccess' references into the node's process image (cia402::ImageRef): resolved once, they
// read and write the object without a lookup, and a reconfiguration of the node's PDOs (a reboot
// with another mapping) makes them stale, so that they never reach the object that now sits at
// their index.
#include <gtest/gtest.h>

#include <array>
#include <initializer_list>

#include "adapters/canopen/node_access.hpp"
#include "adapters/canopen/wire/cob_id.hpp"

namespace drivegate::canopen::test {
namespace {

namespace obj = cia402::obj;

constexpr NodeId kNode = 5;

PdoLayout layout_of(std::initializer_list<cia402::ObjectDef> defs) {
  PdoLayout l;
  for (const auto& d : defs)
    EXPECT_EQ(l.add(d, static_cast<std::uint8_t>(8 * cia402::size_of(d.type))), PdoLayout::Error::None);
  return l;
}

// The node's first RPDO or TPDO, synchronous.
RpdoConfig rpdo(std::initializer_list<cia402::ObjectDef> defs) {
  return {cob::rpdo(0, kNode), layout_of(defs), 1, {}, 0};
}
TpdoConfig tpdo(std::initializer_list<cia402::ObjectDef> defs) { return {cob::tpdo(0, kNode), layout_of(defs), 1, {}}; }

struct Node {
  NodePdos pdos;
  SdoClient sdo{std::span<const SdoChannelConfig>{}, SdoTiming{}};
  EmcyConsumer emcy{std::span<const EmcyNodeConfig>{}};
  NodeAccess io{kNode, -1, pdos, sdo, emcy};
};

TEST(CanopenNodeAccess, ReferencesReadAndWriteTheImage) {
  Node n;
  const std::array<RpdoConfig, 1> rx{rpdo({obj::kControlword, obj::kTargetVelocity})};
  const std::array<TpdoConfig, 1> tx{tpdo({obj::kStatusword, obj::kVelocityActual})};
  ASSERT_TRUE(n.pdos.configure(rx, tx));
  const cia402::ImageRef cw = n.io.resolve(obj::kControlword.id);
  const cia402::ImageRef sw = n.io.resolve(obj::kStatusword.id);
  ASSERT_TRUE(cw.mapped());
  ASSERT_TRUE(sw.mapped());
  EXPECT_FALSE(n.io.resolve(obj::kTargetPosition.id).mapped());
  EXPECT_EQ(cw.generation(), n.io.mapping_generation());

  n.io.write(cw, 0x1000F);  // truncated to UNSIGNED16 like a write by id
  EXPECT_EQ(n.pdos.image().get(obj::kControlword.id), 0x000F);
  n.pdos.image().set(obj::kStatusword.id, 0x0237);
  EXPECT_EQ(n.io.read(sw), 0x0237);
  EXPECT_EQ(n.io.read(obj::kStatusword.id), 0x0237);
  // An unmapped reference reads 0 and writes nothing.
  EXPECT_EQ(n.io.read(cia402::ImageRef{}), 0);
  n.io.write(cia402::ImageRef{}, 5);
  EXPECT_EQ(n.pdos.image().get(obj::kControlword.id), 0x000F);
}

TEST(CanopenNodeAccess, ReconfigurationMakesReferencesStale) {
  Node n;
  const std::array<RpdoConfig, 1> rx{rpdo({obj::kControlword, obj::kTargetVelocity})};
  ASSERT_TRUE(n.pdos.configure(rx, {}));
  const cia402::ImageRef velocity = n.io.resolve(obj::kTargetVelocity.id);
  const std::uint32_t before = n.io.mapping_generation();

  // After a reboot the node gets another mapping: 6071h sits where 60FFh was.
  const std::array<RpdoConfig, 1> other{rpdo({obj::kControlword, obj::kTargetTorque})};
  ASSERT_TRUE(n.pdos.configure(other, {}));
  EXPECT_NE(n.io.mapping_generation(), before);
  EXPECT_FALSE(velocity.current(n.io.mapping_generation()));
  n.io.write(velocity, 1234);  // dropped: never into 6071h
  EXPECT_EQ(n.pdos.image().get(obj::kTargetTorque.id), 0);
  n.pdos.image().set(obj::kTargetTorque.id, 77);
  EXPECT_EQ(n.io.read(velocity), 0);

  // Resolved again under the new mapping.
  EXPECT_FALSE(n.io.resolve(obj::kTargetVelocity.id).mapped());
  const cia402::ImageRef torque = n.io.resolve(obj::kTargetTorque.id);
  EXPECT_EQ(n.io.read(torque), 77);
  // A configuration the node refuses keeps the old image, and with it the references.
  const std::array<RpdoConfig, 5> five{};
  EXPECT_FALSE(n.pdos.configure(five, {}));
  EXPECT_EQ(n.io.read(torque), 77);
}

}  // namespace
}  // namespace drivegate::canopen::test
