// A bus type is added by one registration (config/bus_types.hpp): its options, the axes' and device
// profiles' sections, its checks, its printout rows, its factory and its resource are reached
// through the entry, with no change to the loader, the plan or the printout.
#include <gtest/gtest.h>

#include "config/bus_types.hpp"
#include "config/describe.hpp"
#include "tests/config/test_support.hpp"

namespace drivegate::config::test {
namespace {

// The plan parts of a bus type the loader has never heard of.
struct RingOptions {
  int ring = 0;
};
struct SlotSection {
  int slot = 0;
};
struct ModuleSection {
  std::string module;
};

// A bus type the build does not have, made by one registration.
BusTypeInfo ring_bus_type(int& buses_made) {
  BusTypeInfo t;
  t.name = "ringbus";
  t.max_address = 65535;
  t.axis_section = "ringbus";
  t.device_section = "ringbus";
  t.address_name = "station";
  t.options.push_back({"ring", OptionKind::Integer, 1, 4, std::int64_t{1}, "ring number", {}});
  t.read_bus = [](const MapReader&, const MapReader&, BusPlan& bus) {
    bus.sections.edit<RingOptions>().ring = static_cast<int>(std::get<std::int64_t>(bus.options.at("ring")));
  };
  t.read_axis = [](const MapReader& axis, const BusPlan&, const DeviceProfile* device, const std::filesystem::path&,
                   AxisPlan& a) {
    const MapReader m = axis.map("ringbus", Need::Required);
    m.check_keys({"slot"});
    a.sections.edit<SlotSection>().slot = static_cast<int>(m.integer("slot", Need::Required, 0, 9).value_or(0));
    if (device && device->section<ModuleSection>().module.empty())
      axis.error("device", "device \"" + device->name + "\" has no ringbus section");
  };
  t.read_device = [](const MapReader& root, DeviceProfile& p) {
    const MapReader m = root.map("ringbus", Need::Optional);
    m.check_keys({"module"});
    p.sections.edit<ModuleSection>().module = m.string("module", Need::Required).value_or("");
  };
  t.check_bus.push_back([](const BusPlan& bus, const BusEntry& at) {
    if (bus.axes.size() > 1) at.source.error(at.mark, at.path, "one axis per ring");
  });
  t.describe_bus.push_back([](const BusPlan& bus, DescribeRows& rows) {
    rows.emplace_back("ring", std::to_string(bus.section<RingOptions>().ring));
  });
  t.describe_axis = [](const BusPlan&, const AxisPlan& a, DescribeRows& rows) {
    rows.emplace_back("slot", std::to_string(a.section<SlotSection>().slot) + " (" +
                                  a.device.section<ModuleSection>().module + ")");
  };
  t.resource = [](const BusPlan& bus) { return "ring " + std::to_string(bus.section<RingOptions>().ring); };
  t.make_bus = [&buses_made](const BusPlan&) -> std::unique_ptr<core::Bus> {
    ++buses_made;
    return nullptr;
  };
  return t;
}

const std::string kProfile = R"(name: ring-drive
vendor: test
modes: [csp]
units:
  position: { per_rev: counts }
  velocity: { unit: position_per_s }
  acceleration: { unit: position_per_s2 }
cyclic_objects: ["0x6040", "0x6041", "0x607A"]
ringbus:
  module: XR-7
)";

std::string ring_config(const std::string& axes) {
  return "gateway: { name: g }\nbuses:\n  - { name: r0, type: ringbus, cycle_time: 1ms, options: { ring: 3 } }\n"
         "axes:\n" + axes;
}

class BusTypes : public TempDir {
 protected:
  LoadOptions options() {
    LoadOptions o = test_options();
    o.device_dirs.push_back(dir_);
    o.bus_types.add(ring_bus_type(buses_made_));
    return o;
  }
  int buses_made_ = 0;
};

TEST_F(BusTypes, OneRegistrationAddsABusType) {
  write("ring-drive.yaml", kProfile);
  const std::string yaml = ring_config(
      "  - { name: x, bus: r0, address: 1001, device: ring-drive, mechanics: { encoder_counts_per_rev: 4096 }, "
      "ringbus: { slot: 7 } }\n");
  const Plan plan = load_plan_from_string(yaml, "t.yaml", options());
  const BusPlan& bus = plan.buses.at(0);
  EXPECT_EQ(bus.section<RingOptions>().ring, 3);
  EXPECT_EQ(bus.axes.at(0).section<SlotSection>().slot, 7);
  EXPECT_EQ(bus.axes.at(0).device.section<ModuleSection>().module, "XR-7");

  const std::string text = describe_plan(plan);
  EXPECT_NE(text.find("    ring:            3\n"), std::string::npos) << text;
  EXPECT_NE(text.find("      station:               1001\n"), std::string::npos) << text;
  EXPECT_NE(text.find("      slot:                  7 (XR-7)\n"), std::string::npos) << text;

  ASSERT_TRUE(bus.type_info);
  EXPECT_EQ(bus.type_info->resource(bus), "ring 3");
  EXPECT_EQ(bus.type_info->make_bus(bus), nullptr);
  EXPECT_EQ(buses_made_, 1);
}

TEST_F(BusTypes, ItsChecksAndSectionsAreEnforced) {
  write("ring-drive.yaml", kProfile);
  const std::string e = errors_of(
      ring_config("  - { name: x, bus: r0, address: 1, device: ring-drive, ringbus: { slot: 12 } }\n"
                  "  - { name: y, bus: r0, address: 1, device: ring-drive, sim: {}, ringbus: { slot: 1 } }\n"),
      options());
  EXPECT_REPORTED(e, "t.yaml:5:74: axes[0].ringbus.slot: must be an integer in 0..9, got \"12\"");
  EXPECT_REPORTED(e, "t.yaml:6:62: axes[1].sim: only allowed for axes on a sim bus; bus is of type ringbus");
  EXPECT_REPORTED(e, "t.yaml:6:34: axes[1].address: station 1 on bus \"r0\" is already used by axes[0].address");
  EXPECT_REPORTED(e, "t.yaml:3:5: buses[0]: one axis per ring");
}

TEST_F(BusTypes, ProfilesReadTheSectionsOfTheRegisteredTypes) {
  const auto file = write("ring-drive.yaml", kProfile + "  slot: 1\n");
  Problems problems;
  BusTypeRegistry types = BusTypeRegistry::builtin();
  const auto errors = [](const Problems& p) {
    std::string out;
    for (const auto& d : p.errors()) out += d.to_string() + "\n";
    return out;
  };
  EXPECT_FALSE(parse_device_profile(file, problems, types));  // without the registration: an unknown key
  EXPECT_REPORTED(errors(problems), file.string() + ":9:1: ringbus: unknown field");
  int made = 0;
  types.add(ring_bus_type(made));
  Problems again;
  EXPECT_FALSE(parse_device_profile(file, again, types));
  EXPECT_REPORTED(errors(again), file.string() + ":11:3: ringbus.slot: unknown field (allowed: module)");
}

}  // namespace
}  // namespace drivegate::config::test
