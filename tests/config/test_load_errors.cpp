// Every class of configuration error is reported with FILE:LINE:COL and the field path.
#include <gtest/gtest.h>

#include <sys/stat.h>

#include <string>

#include "config/loader.hpp"
#include "config/yaml_reader.hpp"
#include "tests/config/test_support.hpp"

namespace drivegate::config {
namespace {

using test::errors_of;
using test::test_options;

// A valid file up to and including the first axis' device line (line 11); tests append lines.
const std::string kHead = R"(gateway:
  name: cell-1
buses:
  - name: sim0
    type: sim
    cycle_time: 1ms
axes:
  - name: x
    bus: sim0
    address: 1
    device: sim-servo
)";
// Line 12.
const std::string kCounts = "    mechanics: { encoder_counts_per_rev: 4096 }\n";

TEST(LoadErrors, HeadIsValid) { EXPECT_NO_THROW(load_plan_from_string(kHead + kCounts, "t.yaml", test_options())); }

TEST(LoadErrors, YamlSyntaxError) {
  const std::string e = errors_of("gateway:\n  name: [cell\nbuses: []\n");
  EXPECT_REPORTED(e, "t.yaml:3:6: YAML syntax error: ");
}

TEST(LoadErrors, UnknownKeyWithSuggestion) {
  const std::string e = errors_of(kHead + kCounts + "    comand_timeout: 1s\n");
  EXPECT_REPORTED(e, "t.yaml:13:5: axes[0].comand_timeout: unknown field, did you mean \"command_timeout\"?");
  const std::string top = errors_of(kHead + kCounts + "gatway: {}\n");
  EXPECT_REPORTED(top, "t.yaml:13:1: gatway: unknown field, did you mean \"gateway\"?");
}

TEST(LoadErrors, DuplicateKey) {
  const std::string e = errors_of(kHead + kCounts + "    address: 2\n");
  EXPECT_REPORTED(e, "t.yaml:13:5: axes[0].address: given more than once");
}

TEST(LoadErrors, WrongTypes) {
  const std::string e = errors_of(kHead + kCounts +
                                  "    limits: { max_velocity: fast }\n"
                                  "    defaults: [pp]\n"
                                  "    command_timeout: \"1s\"\n");
  EXPECT_REPORTED(e, "t.yaml:13:29: axes[0].limits.max_velocity: must be a number > 0 and at most 1e+12, got \"fast\"");
  EXPECT_REPORTED(e, "t.yaml:14:15: axes[0].defaults: must be a map of fields, got a list");
  EXPECT_REPORTED(e, "t.yaml:15:22: axes[0].command_timeout: must be a duration > 0");
}

TEST(LoadErrors, MissingRequiredFields) {
  const std::string e = errors_of(R"(gateway:
  dds: { domain: 1 }
buses:
  - type: sim
axes:
  - name: x
    bus: sim0
)");
  EXPECT_REPORTED(e, "t.yaml:2:3: gateway.name: missing required field");
  EXPECT_REPORTED(e, "t.yaml:4:5: buses[0].name: missing required field");
  EXPECT_REPORTED(e, "t.yaml:4:5: buses[0].cycle_time: missing required field");
  EXPECT_REPORTED(e, "t.yaml:6:5: axes[0].address: missing required field");
  EXPECT_REPORTED(e, "t.yaml:6:5: axes[0].device: missing required field");
  const std::string no_buses = errors_of("gateway: { name: g }\n");
  EXPECT_REPORTED(no_buses, "t.yaml:1:1: buses: missing required field");
}

TEST(LoadErrors, EncoderResolutionRequiredForCountingDevices) {
  const std::string e = errors_of(kHead);
  EXPECT_REPORTED(e, "t.yaml:8:5: axes[0].mechanics.encoder_counts_per_rev: missing required field");
}

TEST(LoadErrors, DuplicateBusAndAxisNamesAndAddresses) {
  const std::string e = errors_of(R"(gateway: { name: g }
buses:
  - { name: sim0, type: sim, cycle_time: 1ms }
  - { name: sim0, type: sim, cycle_time: 2ms }
axes:
  - { name: x, bus: sim0, address: 1, device: pp-only }
  - { name: x, bus: sim0, address: 2, device: pp-only }
  - { name: y, bus: sim0, address: 1, device: pp-only }
)");
  EXPECT_REPORTED(e, "t.yaml:4:13: buses[1].name: bus name \"sim0\" is already used by buses[0].name");
  EXPECT_REPORTED(e, "t.yaml:7:13: axes[1].name: axis name \"x\" is already used by axes[0].name");
  EXPECT_REPORTED(e, "t.yaml:8:36: axes[2].address: address 1 on bus \"sim0\" is already used by axes[0].address");
}

TEST(LoadErrors, UnknownBusListsKnownOnes) {
  const std::string e = errors_of(R"(gateway: { name: g }
buses:
  - { name: sim0, type: sim, cycle_time: 1ms }
  - { name: bench, type: sim, cycle_time: 1ms }
axes:
  - { name: x, bus: sim1, address: 1, device: pp-only }
)");
  EXPECT_REPORTED(e, "t.yaml:6:21: axes[0].bus: unknown bus \"sim1\", did you mean \"sim0\"? (buses: sim0, bench)");
}

TEST(LoadErrors, UnknownDeviceListsAvailableOnes) {
  const std::string e = errors_of(R"(gateway: { name: g }
buses:
  - { name: sim0, type: sim, cycle_time: 1ms }
axes:
  - { name: x, bus: sim0, address: 1, device: sim-servoo }
)");
  EXPECT_REPORTED(e, "t.yaml:5:47: axes[0].device: unknown device profile \"sim-servoo\", did you mean \"sim-servo\"?");
  EXPECT_REPORTED(e, "available: esr-triodrive, generic-cia402, generic-cia402-2axis, kollmorgen-akd, kollmorgen-akd-profinet, nord-sk500p, pp-only, sim-servo, stoeber-sd6;");
}

TEST(LoadErrors, NoDeviceProfileInTheSearchPath) {
  LoadOptions o = test_options();
  o.device_dirs = {DRIVEGATE_TEST_DEVICE_DIR "/../no-such-dir"};
  const std::string e = errors_of(kHead + kCounts, o);
  EXPECT_REPORTED(e, "t.yaml:11:13: axes[0].device: unknown device profile \"sim-servo\" (available: (none)");
}

TEST(LoadErrors, ModeTheDeviceDoesNotSupport) {
  const std::string e = errors_of(R"(gateway: { name: g }
buses:
  - { name: sim0, type: sim, cycle_time: 1ms }
axes:
  - name: x
    bus: sim0
    address: 1
    device: pp-only
    defaults: { mode: profile_velocity }
  - name: y
    bus: sim0
    address: 2
    device: pp-only
    defaults: { mode: warp_speed }
)");
  EXPECT_REPORTED(e, "t.yaml:9:23: axes[0].defaults.mode: device \"pp-only\" does not support mode profile_velocity; "
                     "supported: pp, hm");
  EXPECT_REPORTED(e, "t.yaml:14:23: axes[1].defaults.mode: must be a mode name");
}

TEST(LoadErrors, HomingMethodTheDeviceLacks) {
  const std::string e = errors_of(R"(gateway: { name: g }
buses:
  - { name: sim0, type: sim, cycle_time: 1ms }
axes:
  - name: x
    bus: sim0
    address: 1
    device: pp-only
    homing: { method: 19 }
)");
  EXPECT_REPORTED(e, "t.yaml:9:23: axes[0].homing.method: device \"pp-only\" does not support homing method 19; "
                     "supported: 35, 37");
}

TEST(LoadErrors, OutOfRangeValues) {
  const std::string e = errors_of(R"(gateway:
  name: "cell 1"
  dds: { domain: 300, namespace: a-b }
  log_level: loud
  status_rate_hz: 0
  status_keepalive: -1s
buses:
  - name: fast
    type: sim
    cycle_time: 50us
    priority: 100
    cpu: -2
    options: { acyclic_latency_cycles: -1 }
  - name: slow
    type: sim
    cycle_time: 2s
axes:
  - name: x
    bus: fast
    address: 200
    device: pp-only
    command_timeout: -5ms
    enable_step_timeout: 0s
    timeout_stop: brake
    limits: { min_position: 10, max_position: 10, max_acceleration: -1 }
    homing: { timeout: 0 }
    mechanics: { gear_ratio: 0, feed: -5 }
)");
  EXPECT_REPORTED(e, "t.yaml:2:9: gateway.name: must be a name of 1 to 63 characters from A-Z a-z 0-9 _ . -, got \"cell 1\"");
  EXPECT_REPORTED(e, "t.yaml:3:18: gateway.dds.domain: must be an integer in 0..232, got \"300\"");
  EXPECT_REPORTED(e, "t.yaml:3:34: gateway.dds.namespace: must be a name of 1 to 63 characters from A-Z a-z 0-9 _");
  EXPECT_REPORTED(e, "t.yaml:4:14: gateway.log_level: must be one of trace, debug, info, warn, error, critical, off, got \"loud\"");
  EXPECT_REPORTED(e, "t.yaml:5:19: gateway.status_rate_hz: must be a number in 1..1000 (Hz), got \"0\"");
  EXPECT_REPORTED(e, "t.yaml:6:21: gateway.status_keepalive: must be a duration in 0..500ms");
  EXPECT_REPORTED(e, "t.yaml:10:17: buses[0].cycle_time: must be a duration in 100us..1s");
  EXPECT_REPORTED(e, "t.yaml:11:15: buses[0].priority: must be an integer in 0..99, got \"100\"");
  EXPECT_REPORTED(e, "t.yaml:12:10: buses[0].cpu: must be an integer in -1..1023, got \"-2\"");
  EXPECT_REPORTED(e, "t.yaml:13:40: buses[0].options.acyclic_latency_cycles: must be an integer in 1..1000");
  EXPECT_REPORTED(e, "t.yaml:16:17: buses[1].cycle_time: must be a duration in 100us..1s");
  EXPECT_REPORTED(e, "t.yaml:20:14: axes[0].address: must be an integer in 1..127, got \"200\"");
  EXPECT_REPORTED(e, "t.yaml:22:22: axes[0].command_timeout: must be a duration > 0");
  EXPECT_REPORTED(e, "t.yaml:23:26: axes[0].enable_step_timeout: must be a duration > 0");
  EXPECT_REPORTED(e, "t.yaml:24:19: axes[0].timeout_stop: must be one of quick_stop, halt, got \"brake\"");
  EXPECT_REPORTED(e, "t.yaml:25:29: axes[0].limits.min_position: must be less than max_position (10), got 10");
  EXPECT_REPORTED(e, "t.yaml:25:69: axes[0].limits.max_acceleration: must be a number > 0 and at most 1e+12, got \"-1\"");
  EXPECT_REPORTED(e, "t.yaml:26:24: axes[0].homing.timeout: must be a duration > 0");
  EXPECT_REPORTED(e, "t.yaml:27:30: axes[0].mechanics.gear_ratio: must be a number in 1e-06..1000000, got \"0\"");
  EXPECT_REPORTED(e, "t.yaml:27:39: axes[0].mechanics.feed: must be a number in 1e-06..1000000, got \"-5\"");
}

TEST(LoadErrors, NonFiniteNumbers) {
  const std::string e = errors_of(kHead + kCounts + "    limits: { min_position: -.inf, max_position: .nan, max_velocity: .inf }\n");
  EXPECT_REPORTED(e, "t.yaml:13:29: axes[0].limits.min_position: must be a number in -1e+12..1e+12, got \"-.inf\" (not a finite number)");
  EXPECT_REPORTED(e, "t.yaml:13:50: axes[0].limits.max_position: must be a number in -1e+12..1e+12, got \".nan\"");
  EXPECT_REPORTED(e, "t.yaml:13:70: axes[0].limits.max_velocity: must be a number > 0 and at most 1e+12, got \".inf\"");
}

TEST(LoadErrors, OnlyOnePositionLimit) {
  const std::string e = errors_of(kHead + kCounts + "    limits: { min_position: 0 }\n");
  EXPECT_REPORTED(e, "t.yaml:13:13: axes[0].limits.max_position: missing: give both min_position and max_position");
}

TEST(LoadErrors, PositionLimitBeyondDriveRange) {
  const std::string e = errors_of(kHead + kCounts + "    limits: { min_position: -1e6, max_position: 1 }\n");
  EXPECT_REPORTED(e, "t.yaml:13:29: axes[0].limits.min_position: is -4096000000 in drive units");
}

TEST(LoadErrors, DefaultsAboveLimits) {
  const std::string e = errors_of(kHead + kCounts +
                                  "    limits: { max_velocity: 10 }\n"
                                  "    defaults: { velocity: 20 }\n");
  EXPECT_REPORTED(e, "t.yaml:14:27: axes[0].defaults.velocity: must not exceed limits.max_velocity (10), got 20");
}

TEST(LoadErrors, BusTypes) {
  // A type the registry knows without an adapter (as a bus type whose adapter is not linked in).
  LoadOptions options = test_options();
  BusTypeInfo modbus;
  modbus.name = "modbus";
  options.bus_types.add(modbus);
  const std::string e = errors_of(R"(gateway: { name: g }
buses:
  - { name: a, type: simm, cycle_time: 1ms }
  - { name: b, type: modbus, cycle_time: 1ms }
  - { name: c, type: sim, cycle_time: 1ms, options: { latency: 2 } }
)", options);
  EXPECT_REPORTED(e, "t.yaml:3:22: buses[0].type: unknown bus type \"simm\", did you mean \"sim\"? (available: sim, canopen, ethercat, profinet)");
  EXPECT_REPORTED(e, "t.yaml:4:22: buses[1].type: bus type \"modbus\" has no adapter in this build (available: sim, canopen, ethercat, profinet)");
  EXPECT_REPORTED(e, "t.yaml:5:55: buses[2].options.latency: unknown field (allowed: acyclic_latency_cycles)");
}

TEST(LoadErrors, SimSectionOnlyOnSimBuses) {
  const std::string e = errors_of(R"(gateway: { name: g }
buses:
  - { name: can0, type: canopen, cycle_time: 1ms }
axes:
  - name: x
    bus: can0
    address: 5
    device: generic-cia402
    mechanics: { encoder_counts_per_rev: 4096 }
    sim: { home_switch: 3 }
)");
  EXPECT_REPORTED(e, "t.yaml:10:10: axes[0].sim: only allowed for axes on a sim bus; bus is of type canopen");
}

TEST(LoadErrors, SimSectionRanges) {
  const std::string e = errors_of(kHead + kCounts +
                                  "    sim: { negative_limit_switch: 5, positive_limit_switch: 1, home_switch: 9 }\n");
  EXPECT_REPORTED(e, "t.yaml:13:35: axes[0].sim.negative_limit_switch: must be less than positive_limit_switch (1), got 5");
  EXPECT_REPORTED(e, "t.yaml:13:77: axes[0].sim.home_switch: must lie between the limit switches");
}

TEST(LoadErrors, DeviceDirsRelativeToTheFile) {
  const std::string e = errors_of("gateway: { name: g, device_dirs: [nowhere] }\nbuses: []\n");
  EXPECT_REPORTED(e, "t.yaml:1:35: gateway.device_dirs[0]: directory \"");
  EXPECT_REPORTED(e, "t.yaml:2:8: buses: must list at least one bus");
}

TEST(LoadErrors, AllProblemsAtOnceInFileOrder) {
  const std::string e = errors_of(R"(gateway:
  name: g
  log_level: chatty
buses:
  - { name: sim0, type: sim, cycle_time: 0 }
axes:
  - { name: x, bus: nope, address: 1, device: pp-only }
  - { name: y, bus: sim0, address: 1, device: pp-only, limits: { max_velocity: fast } }
)");
  const auto a = e.find("t.yaml:3:14: gateway.log_level:");
  const auto b = e.find("t.yaml:5:42: buses[0].cycle_time:");
  const auto c = e.find("t.yaml:7:21: axes[0].bus: unknown bus \"nope\"");
  const auto d = e.find("t.yaml:8:80: axes[1].limits.max_velocity:");
  ASSERT_NE(a, std::string::npos) << e;
  ASSERT_NE(b, std::string::npos) << e;
  ASSERT_NE(c, std::string::npos) << e;
  ASSERT_NE(d, std::string::npos) << e;
  EXPECT_LT(a, b);
  EXPECT_LT(b, c);
  EXPECT_LT(c, d);
  EXPECT_EQ(std::count(e.begin(), e.end(), '\n'), 3) << e;  // exactly four problems, one a line
}

TEST(LoadErrors, ProblemsAreStructuredToo) {
  try {
    load_plan_from_string(kHead + kCounts + "    unit: \"\"\n", "t.yaml", test_options());
    FAIL() << "expected ConfigError";
  } catch (const ConfigError& e) {
    ASSERT_EQ(e.problems().size(), 1U);
    EXPECT_EQ(e.problems()[0].line, 13);
    EXPECT_EQ(e.problems()[0].column, 11);
    EXPECT_EQ(e.problems()[0].path, "axes[0].unit");
  }
}

TEST(LoadErrors, MissingFile) {
  try {
    load_plan("/nonexistent/drivegate.yaml");
    FAIL() << "expected ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_REPORTED(std::string{e.what()}, "/nonexistent/drivegate.yaml: cannot open file: No such file");
  }
}

// What load_plan(path) reports, or "(loaded without error)".
std::string file_errors(const std::string& path) {
  try {
    load_plan(path, test_options());
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "(loaded without error)";
}

// Only regular files are read: a directory, a device (/dev/zero grew to 24 GB), a pipe (would
// block) are refused at once with what they are.
using FileErrors = test::TempDir;

TEST_F(FileErrors, NonRegularFilesAreRefusedWithWhatTheyAre) {
  EXPECT_REPORTED(file_errors(dir_.string()), dir_.string() + ": is a directory, not a file");
  EXPECT_REPORTED(file_errors("/dev/zero"), "/dev/zero: is not a regular file (it is a character device)");
  const auto fifo = dir_ / "fifo.yaml";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  EXPECT_REPORTED(file_errors(fifo.string()), "fifo.yaml: is not a regular file (it is a pipe)");
}

TEST_F(FileErrors, FilesAboveTheLimitAreRefusedBeforeParsing) {
  std::string big = kHead + kCounts;
  big.resize(static_cast<std::size_t>(kMaxYamlBytes) + 1, '#');
  const auto p = write("big.yaml", big);
  EXPECT_REPORTED(file_errors(p.string()), "big.yaml: is " + std::to_string(kMaxYamlBytes + 1) +
                                               " bytes; this kind of file is limited to 1 MiB");
  // At the limit it is read (and here loads: the rest is a comment).
  big.resize(static_cast<std::size_t>(kMaxYamlBytes));
  EXPECT_EQ(file_errors(write("limit.yaml", big).string()), "(loaded without error)");
}

// A Fast DDS profiles file comes with the participant profile to use; a profile needs its file.
TEST_F(FileErrors, DdsProfilesFileNeedsItsProfile) {
  const auto xml = write("fastdds.xml", "<profiles/>\n");
  std::string yaml = kHead + kCounts;
  yaml.replace(yaml.find("  name: cell-1\n"), 15, "  name: cell-1\n  dds: { profiles_file: \"" + xml.string() + "\" }\n");
  EXPECT_REPORTED(errors_of(yaml), "gateway.dds.profile: missing required field");
  yaml = kHead + kCounts;
  yaml.replace(yaml.find("  name: cell-1\n"), 15, "  name: cell-1\n  dds: { profile: cell }\n");
  EXPECT_REPORTED(errors_of(yaml), "gateway.dds.profile: names a participant profile of profiles_file");
}

TEST(LoadErrors, ASecondDocumentIsAnError) {
  const std::string e = errors_of(kHead + kCounts + "---\ngateway: { name: other }\n");
  EXPECT_REPORTED(e, "t.yaml:14:1: a second YAML document starts here");
}

// A value echoed in a message is cut: a megabyte of garbage must not come back as a megabyte of
// error text. Hundreds of errors are summarised after the first 50.
TEST(LoadErrors, EchoedValuesAreCutAndManyErrorsSummarised) {
  const std::string junk(5000, 'z');
  const std::string e = errors_of(kHead + kCounts + "    unit: [1]\n    limits: { max_velocity: " + junk + " }\n");
  EXPECT_REPORTED(e, "got \"" + std::string(60, 'z') + "\"...(5000 characters)");
  EXPECT_LT(e.size(), 1000u) << e.size();
  std::string many = kHead + kCounts + "    limits:\n";
  for (int i = 0; i < 300; ++i) many += "      k" + std::to_string(i) + ": 1\n";
  const std::string m = errors_of(many);
  EXPECT_REPORTED(m, "... and 250 more problems");
}

// Every mechanics and limit value has a sane range: an encoder of 1e-6 counts aborted the daemon,
// a feed of 1e-300 was accepted.
TEST(LoadErrors, MechanicsAndLimitsHaveSaneRanges) {
  std::string e = errors_of(kHead + "    mechanics: { encoder_counts_per_rev: 1e-6 }\n");
  EXPECT_REPORTED(e, "axes[0].mechanics.encoder_counts_per_rev: must be a number of counts per motor revolution in 1..2^32");
  e = errors_of(kHead + "    mechanics: { encoder_counts_per_rev: 4096, feed: 1e-300, gear_ratio: 1e9, rated_torque: 1e-9 }\n");
  EXPECT_REPORTED(e, "axes[0].mechanics.feed: must be a number in 1e-06..1000000, got \"1e-300\"");
  EXPECT_REPORTED(e, "axes[0].mechanics.gear_ratio: must be a number in 1e-06..1000000");
  EXPECT_REPORTED(e, "axes[0].mechanics.rated_torque: must be 0 (torque in percent) or a torque in 0.001..1e6 Nm");
  e = errors_of(kHead + kCounts + "    limits: { max_velocity: 1e300 }\n    homing: { offset: -1e20 }\n");
  EXPECT_REPORTED(e, "axes[0].limits.max_velocity: must be a number > 0 and at most 1e+12");
  EXPECT_REPORTED(e, "axes[0].homing.offset: must be a number in -1e+12..1e+12");
  // Within range each, but together a scaling nothing could be commanded with.
  e = errors_of(kHead + "    mechanics: { encoder_counts_per_rev: 4294967296, feed: 1e-6, gear_ratio: 1e6 }\n");
  EXPECT_REPORTED(e, "drive position units per");
}

TEST(LoadErrors, EmptyDocument) {
  const std::string e = errors_of("");
  EXPECT_REPORTED(e, "t.yaml: must be a map of fields, got nothing");
}

}  // namespace
}  // namespace drivegate::config
