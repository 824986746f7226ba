// The bus-neutral half of the scan: the table, the configuration skeleton (accepted by the loader
// as it is), the file writer and the scanner registry.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "config/canopen/plan.hpp"
#include "config/loader.hpp"
#include "daemon/bus_lock.hpp"
#include "daemon/scan.hpp"
#include "core/bus.hpp"

namespace drivegate::daemon {
namespace {

using namespace std::chrono_literals;

core::ScanResult two_devices() {
  core::ScanResult r;
  r.bus_type = "canopen";
  r.bus_name = "can0";
  r.description = "udp-multicast 239.1.2.3:17000 on 127.0.0.1";
  r.bus_options = {{"transport", "udp-multicast"}, {"interface", "127.0.0.1"}, {"bitrate", "500000"},
                   {"group", "239.1.2.3"}, {"port", "17000"}};
  r.cycle_times = {4ms, 8ms};
  core::FoundDevice akd;
  akd.address = {5, "5 (05h)"};
  akd.device_type = 0x00020192;
  akd.device_type_text = "CiA 402 drive: servo drive";
  akd.identity.vendor_id = 0x6A;
  akd.name = "M006";
  akd.profile = "kollmorgen-akd";
  akd.profile_reason = "vendor 0x0000006A is kollmorgen-akd's";
  akd.drive = true;
  akd.notes = {"1009h not present"};
  core::FoundDevice io;
  io.address = {9, "9 (09h)"};
  io.device_type = 0x000F0191;
  io.device_type_text = "CiA 401 I/O module";
  io.profile_reason = "vendor 0x00000123 matches no profile and no profile fits 1000h = 0x000F0191";
  io.next_step = "add a device profile for it (profiles/devices/README.md) and scan again";
  r.devices = {akd, io};
  r.elapsed = 412ms;
  return r;
}

TEST(ScanTable, OneRowPerDeviceThenReasonsAndNotes) {
  const std::string t = format_scan_table(two_devices());
  EXPECT_EQ(t.find("canopen udp-multicast 239.1.2.3:17000 on 127.0.0.1: 2 devices (scan took 412 ms)\n"), 0U) << t;
  EXPECT_NE(t.find("5 (05h)  0x00020192   CiA 402 drive: servo drive  0x0000006A  -        -         -       \"M006\"  -  "
                   "       -         kollmorgen-akd\n"),
            std::string::npos)
      << t;
  EXPECT_NE(t.find("(none)\n"), std::string::npos) << t;
  EXPECT_NE(t.find("5 (05h): kollmorgen-akd: vendor 0x0000006A is kollmorgen-akd's\n    1009h not present\n"),
            std::string::npos)
      << t;
  EXPECT_NE(t.find("9 (09h): no profile: vendor 0x00000123 matches no profile"), std::string::npos) << t;
}

// The AKD's node-ID answered twice: its identity is a mix of two devices' answers.
core::ScanResult akd_in_conflict() {
  auto r = two_devices();
  r.devices[0].conflict = "node-ID 5: more than one device answers on 605h/585h (a node-ID conflict); its identity "
                          "cannot be trusted";
  r.warnings = {r.devices[0].conflict};
  return r;
}

TEST(ScanTable, AConflictIsMarkedInTheRowAndAWarningLine) {
  const std::string t = format_scan_table(akd_in_conflict());
  EXPECT_NE(t.find("(conflict)\n"), std::string::npos) << t;
  EXPECT_EQ(t.find("kollmorgen-akd\n"), std::string::npos) << t;
  EXPECT_NE(t.find("\nwarning: node-ID 5: more than one device answers on 605h/585h (a node-ID conflict); its "
                   "identity cannot be trusted\n"),
            std::string::npos)
      << t;
}

TEST(ScanSkeleton, ADeviceInConflictIsNoAxisEvenWithAProfile) {
  const config::LoadOptions load;
  const auto r = akd_in_conflict();
  ASSERT_TRUE(r.devices[0].drive);  // the skeleton does not rely on the scanner clearing it
  const std::string text = scan_skeleton(r, load);
  EXPECT_TRUE(config::load_plan_from_string(text, "skeleton.yaml", load).buses[0].axes.empty()) << text;
  EXPECT_NE(text.find("  #   not an axis here: node-ID 5: more than one device answers on 605h/585h"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("give every device its own node-ID"), std::string::npos) << text;
}

TEST(ScanTable, SaysSoWhenNobodyAnswered) {
  core::ScanResult r;
  r.bus_type = "canopen";
  r.description = "socketcan vcan0";
  r.notes = {"3 malformed frames dropped"};
  EXPECT_EQ(format_scan_table(r),
            "canopen socketcan vcan0: no devices answered (scan took 0 ms)\nnote: 3 malformed frames dropped\n");
}

TEST(ScanSkeleton, TheLoaderAcceptsItWithAnAxisPerDrive) {
  const config::LoadOptions load;
  const std::string text = scan_skeleton(two_devices(), load);
  const auto plan = config::load_plan_from_string(text, "skeleton.yaml", load);
  ASSERT_EQ(plan.buses.size(), 1U);
  EXPECT_EQ(plan.buses[0].section<config::CanopenBusOptions>().group, "239.1.2.3");
  EXPECT_EQ(plan.buses[0].section<config::CanopenBusOptions>().port, 17000);
  EXPECT_EQ(plan.buses[0].cycle_time, 4ms);
  ASSERT_EQ(plan.buses[0].axes.size(), 1U);
  EXPECT_EQ(plan.buses[0].axes[0].address, 5);
  EXPECT_EQ(plan.buses[0].axes[0].device.name, "kollmorgen-akd");
  // The device without a profile is there as a comment saying what to do.
  EXPECT_NE(text.find("  # 9 (09h): CiA 401 I/O module\n"), std::string::npos) << text;
  EXPECT_NE(text.find("not an axis here: add a device profile"), std::string::npos) << text;
  EXPECT_NE(text.find("CHECK"), std::string::npos);
}

TEST(ScanSkeleton, TakesTheNextCycleTimeWhenTheFirstIsRefused) {
  auto r = two_devices();
  r.cycle_times = {3ms, 8ms};  // the SD6 runs 1, 2, 4 or 8 ms only
  r.devices[0].profile = "stoeber-sd6";
  const config::LoadOptions load;
  const auto plan = config::load_plan_from_string(scan_skeleton(r, load), "skeleton.yaml", load);
  EXPECT_EQ(plan.buses[0].cycle_time, 8ms);
  r.cycle_times = {3ms};
  try {
    (void)scan_skeleton(r, load);
    FAIL() << "a skeleton with a cycle time the SD6 refuses";
  } catch (const core::ScanError& e) {
    EXPECT_NE(std::string(e.what()).find("the skeleton does not pass the configuration checks with any of the cycle "
                                         "times 3ms"),
              std::string::npos)
        << e.what();
  }
}

TEST(ScanSkeleton, AProblemNotAboutTheCycleDoesNotBlameTheCycleTimes) {
  auto r = two_devices();
  r.devices[0].profile = "no-such-profile";
  const config::LoadOptions load;
  try {
    (void)scan_skeleton(r, load);
    FAIL() << "a skeleton naming a profile that does not exist";
  } catch (const core::ScanError& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.find("the skeleton does not pass the configuration checks, so it is not written:\n"), 0U) << what;
    EXPECT_EQ(what.find("cycle time"), std::string::npos) << what;
  }
}

TEST(ScanSkeleton, ABitRateNotGivenIsACheckAndTheTableSaysItWasAssumed) {
  auto r = two_devices();
  r.bus_option_checks = {{"bitrate", "the bus' bit rate (not read from the interface; set it to the interface's)"}};
  r.assumed = "bit rate not given (500 kbit/s assumed for the answer times and the load estimate)";
  const config::LoadOptions load;
  const std::string text = scan_skeleton(r, load);
  EXPECT_NE(text.find("      bitrate: 500000    # CHECK: the bus' bit rate (not read from the interface; set it to "
                      "the interface's)\n"),
            std::string::npos)
      << text;
  EXPECT_EQ(config::load_plan_from_string(text, "skeleton.yaml", load).buses[0].section<config::CanopenBusOptions>().bitrate,
            500000U);
  EXPECT_EQ(format_scan_table(r).find("canopen udp-multicast 239.1.2.3:17000 on 127.0.0.1, bit rate not given (500 "
                                      "kbit/s assumed for the answer times and the load estimate): 2 devices"),
            0U)
      << format_scan_table(r);
}

TEST(ScanSkeleton, DeviceDirsAreQuotedScalars) {
  const auto dir = std::filesystem::temp_directory_path() /
                   ("drivegate-scan-dirs-" + std::to_string(::getpid())) / "a: b #c \"q\" back\\slash";
  std::filesystem::create_directories(dir);
  config::LoadOptions load;
  load.device_dirs = {dir};
  for (const auto& d : config::default_device_dirs()) load.device_dirs.push_back(d);
  const std::string text = scan_skeleton(two_devices(), load);
  EXPECT_NE(text.find("    - \"" + dir.parent_path().string() + "/a: b #c \\\"q\\\" back\\\\slash\"\n"),
            std::string::npos)
      << text;
  std::filesystem::remove_all(dir.parent_path());
}

TEST(ScanSkeleton, WhatToDoAboutADeviceWithoutProfileIsTheScannersWord) {
  auto r = two_devices();
  r.devices[1].next_step = "its SDO server did not answer; check the device's node-ID";
  const std::string text = scan_skeleton(r, config::LoadOptions{});
  EXPECT_NE(text.find("  #   not an axis here: its SDO server did not answer; check the device's node-ID\n"),
            std::string::npos)
      << text;
  EXPECT_EQ(text.find("add a device profile"), std::string::npos) << text;
}

TEST(ScanSkeleton, WithoutDevicesIsABusWithoutAxes) {
  auto r = two_devices();
  r.devices.clear();
  const config::LoadOptions load;
  const std::string text = scan_skeleton(r, load);
  EXPECT_NE(text.find("axes: []\n"), std::string::npos) << text;
  EXPECT_TRUE(config::load_plan_from_string(text, "skeleton.yaml", load).buses[0].axes.empty());
}

TEST(WriteSkeleton, KeepsAnExistingFileUnlessForced) {
  const auto dir = std::filesystem::temp_directory_path() / ("drivegate-scan-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const auto file = dir / "cell.yaml";
  write_skeleton(file, "first\n", false);
  EXPECT_THROW(write_skeleton(file, "second\n", false), core::ScanError);
  const auto read = [&] {
    std::ifstream in(file);
    std::ostringstream text;
    text << in.rdbuf();
    return text.str();
  };
  EXPECT_EQ(read(), "first\n");
  write_skeleton(file, "second\n", true);
  EXPECT_EQ(read(), "second\n");
  // No temporary file is left behind.
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir), {}), 1);
  EXPECT_THROW(write_skeleton(dir / "no-such-dir" / "x.yaml", "x\n", false), core::ScanError);
  std::filesystem::remove_all(dir);
}

TEST(ScanBus, RefusesBusTypesWithoutAScanner) {
  auto registry = config::BusTypeRegistry::builtin();
  config::BusTypeInfo modbus;  // known without an adapter
  modbus.name = "modbus";
  registry.add(modbus);
  core::ScanRequest r;
  r.bus_type = "modbus";
  try {
    (void)scan_bus(r, registry);
    FAIL() << "scanned modbus";
  } catch (const core::ScanError& e) {
    EXPECT_STREQ(e.what(), "cannot scan modbus: no adapter in this build (scans: canopen, ethercat, profinet)");
  }
  r.bus_type = "canbus";
  EXPECT_THROW((void)scan_bus(r, registry), core::ScanError);
  // sim has an adapter, only no scanner.
  r.bus_type = "sim";
  try {
    (void)scan_bus(r, registry);
    FAIL() << "scanned sim";
  } catch (const core::ScanError& e) {
    EXPECT_STREQ(e.what(), "cannot scan sim: sim has no bus scan (scans: canopen, ethercat, profinet)");
  }
}

TEST(ScanBus, TakesNoLockForABusThatHoldsNothing) {
  config::BusTypeRegistry registry;
  config::BusTypeInfo fake;
  fake.name = "fake";
  fake.make_bus = [](const config::BusPlan&) { return std::unique_ptr<core::Bus>{}; };
  fake.resource = [](const config::BusPlan&) { return std::string(); };
  fake.scan.plan = [&registry](const core::ScanRequest&, const config::BusTypeRegistry&) {
    config::BusPlan p;
    p.type_info = registry.find("fake");
    return p;
  };
  fake.scan.run = [](const config::BusPlan&, const core::ScanRequest&, const config::BusTypeRegistry&) {
    core::ScanResult result;
    result.bus_type = "fake";
    return result;
  };
  registry.add(fake);
  // Another process locking "" (what BusLock would name an empty resource) does not stop the scan.
  const BusLock held("");
  core::ScanRequest r;
  r.bus_type = "fake";
  EXPECT_EQ(scan_bus(r, registry).bus_type, "fake");
}

}  // namespace
}  // namespace drivegate::daemon
