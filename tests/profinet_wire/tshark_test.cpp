// Frames written by the codecs dissect cleanly in Debian's tshark: no "Malformed", no expert
// warnings or errors, and the fields filled. The frames go through a classic pcap file (link type
// 1 = Ethernet, tests/support/pcap.hpp) to `tshark -r FILE -V`, one file per frame so that each
// dissection is judged on its own. Skipped when tshark is not installed (scripts/install-deps.sh).
#include <gtest/gtest.h>

#include <array>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "adapters/profinet/wire/alarm.hpp"
#include "adapters/profinet/wire/dcp.hpp"
#include "adapters/profinet/wire/ethernet.hpp"
#include "adapters/profinet/wire/rt.hpp"
#include "tests/support/pcap.hpp"
#include "tests/support/run_program.hpp"

namespace drivegate::profinet {
namespace {

using Bytes = std::vector<std::uint8_t>;

constexpr MacAddress kController{0x02, 0x00, 0x00, 0x00, 0x00, 0x01};
constexpr MacAddress kDevice{0x00, 0x1B, 0x1B, 0x12, 0x34, 0x56};

bool have_tshark() { return test::run_program({"tshark", "--version"}).status != 127; }

// `tshark -V` (plus `extra` options) of one frame, with expert infos listed (-z expert).
std::string dissect(const Bytes& frame, const std::vector<std::string>& extra = {}) {
  static int serial = 0;
  const auto path = std::filesystem::temp_directory_path() /
                    ("drivegate-pn-tshark-" + std::to_string(::getpid()) + "-" + std::to_string(serial++) + ".pcap");
  test::write_pcap(path, {frame});
  std::vector<std::string> argv{"tshark", "-r", path.string(), "-V", "-z", "expert,note"};
  argv.insert(argv.end(), extra.begin(), extra.end());
  const test::RunResult r = test::run_program(argv);
  if (std::getenv("KEEP_PCAP") == nullptr) std::filesystem::remove(path);
  return r.output;
}

// An Ethernet frame around a PDU written by `encode` into the buffer after the header.
template <typename Encode>
Bytes frame(const EthernetHeader& h, Encode encode) {
  std::array<std::uint8_t, kMaxFrameSize> buf{};
  const std::size_t at = encode_ethernet_header(h, buf);
  EXPECT_NE(at, 0U);
  const std::size_t n = encode(std::span<std::uint8_t>(buf).subspan(at));
  EXPECT_NE(n, 0U);
  const std::size_t size = pad_frame(buf, at + n);
  return Bytes(buf.begin(), buf.begin() + static_cast<std::ptrdiff_t>(size));
}

EthernetHeader header(const MacAddress& dst, const MacAddress& src, std::uint16_t id) {
  EthernetHeader h;
  h.dst = dst;
  h.src = src;
  h.frame_id = id;
  return h;
}

void expect_clean(const std::string& out, std::initializer_list<const char*> fields) {
  ASSERT_FALSE(out.empty());
  EXPECT_EQ(out.find("Malformed"), std::string::npos) << out;
  EXPECT_EQ(out.find("Exception"), std::string::npos) << out;
  // `-z expert,note` prints a table of warnings and errors when there are any.
  EXPECT_EQ(out.find("Errors ("), std::string::npos) << out;
  EXPECT_EQ(out.find("Warns ("), std::string::npos) << out;
  EXPECT_EQ(out.find("Expert Info (Error"), std::string::npos) << out;
  EXPECT_EQ(out.find("Expert Info (Warning"), std::string::npos) << out;
  for (const char* f : fields) EXPECT_NE(out.find(f), std::string::npos) << "missing: " << f << "\n" << out;
}

IpSuite suite() {
  IpSuite s;
  s.address = {192, 168, 0, 10};
  s.netmask = {255, 255, 255, 0};
  s.gateway = {192, 168, 0, 1};
  return s;
}

TEST(PnTshark, DcpIdentifyAll) {
  if (!have_tshark()) GTEST_SKIP() << "tshark not installed (scripts/install-deps.sh)";
  const Bytes f = frame(header(kDcpIdentifyMulticast, kController, frame_id::kDcpIdentifyRequest),
                        [](std::span<std::uint8_t> out) { return encode_identify_all_request(out, 0x1001, 1); });
  expect_clean(dissect(f), {"PROFINET DCP", "ServiceID: Identify (5)", "ServiceType: Request (0)", "Xid: 0x00001001", "All"});
}

TEST(PnTshark, DcpIdentifyByName) {
  if (!have_tshark()) GTEST_SKIP() << "tshark not installed";
  const Bytes f = frame(header(kDcpIdentifyMulticast, kController, frame_id::kDcpIdentifyRequest),
                        [](std::span<std::uint8_t> out) { return encode_identify_name_request(out, 0x1002, 1, "akd-1"); });
  expect_clean(dissect(f), {"PROFINET DCP", "Identify", "NameOfStation: akd-1"});
}

TEST(PnTshark, DcpIdentifyResponse) {
  if (!have_tshark()) GTEST_SKIP() << "tshark not installed";
  static constexpr std::array<std::uint8_t, 6> kOptions{0x01, 0x02, 0x02, 0x02, 0x05, 0x03};
  DcpDeviceInfo d;
  d.has_type_of_station = true;
  d.type_of_station = "AKD";
  d.has_name_of_station = true;
  d.name_of_station = "akd-1";
  d.has_device_id = true;
  d.vendor_id = 0x002A;
  d.device_id = 0x0301;
  d.has_device_role = true;
  d.device_role = device_role::kIoDevice;
  d.has_device_options = true;
  d.device_options = kOptions;
  d.has_device_instance = true;
  d.instance_low = 1;
  d.has_ip = true;
  d.ip_block_info = ip_block_info::kSet;
  d.ip = suite();
  const Bytes f = frame(header(kController, kDevice, frame_id::kDcpIdentifyResponse),
                        [&d](std::span<std::uint8_t> out) { return encode_identify_response(out, 0x1001, d); });
  expect_clean(dissect(f), {"PROFINET DCP", "Identify", "Response Success", "NameOfStation: akd-1",
                            "DeviceVendorValue: AKD", "VendorID: 0x002a", "DeviceID: 0x0301", "IO-Device",
                            "IPaddress: 192.168.0.10", "Subnetmask: 255.255.255.0", "StandardGateway: 192.168.0.1",
                            "DeviceInstanceLow: 0x01", "Dev-Options(3)"});
}

TEST(PnTshark, DcpHello) {
  if (!have_tshark()) GTEST_SKIP() << "tshark not installed";
  DcpDeviceInfo d;
  d.has_name_of_station = true;
  d.name_of_station = "akd-1";
  d.has_ip = true;
  d.ip_block_info = ip_block_info::kSet;
  d.ip = suite();
  d.has_device_initiative = true;
  d.device_initiative = 1;
  const Bytes f = frame(header(kDcpHelloMulticast, kDevice, frame_id::kDcpHello),
                        [&d](std::span<std::uint8_t> out) { return encode_hello(out, 0x3001, d); });
  expect_clean(dissect(f), {"PROFINET DCP", "ServiceID: Hello (6)", "NameOfStation: akd-1", "IPaddress: 192.168.0.10",
                            "DeviceInitiative"});
}

TEST(PnTshark, DcpSetNameIpSignal) {
  if (!have_tshark()) GTEST_SKIP() << "tshark not installed";
  const EthernetHeader h = header(kDevice, kController, frame_id::kDcpGetSet);
  expect_clean(dissect(frame(h, [](std::span<std::uint8_t> out) {
                 return encode_set_name_request(out, 0x2001, "akd-1", DcpQualifier::Permanent);
               })),
               {"PROFINET DCP", "Set", "NameOfStation: akd-1", "BlockQualifier: Save the value permanent (1)"});
  expect_clean(dissect(frame(h, [](std::span<std::uint8_t> out) {
                 return encode_set_ip_request(out, 0x2002, suite(), DcpQualifier::Temporary);
               })),
               {"PROFINET DCP", "Set", "IPaddress: 192.168.0.10", "BlockQualifier: Use the value temporary (0)"});
  expect_clean(dissect(frame(h, [](std::span<std::uint8_t> out) { return encode_set_signal_request(out, 0x2003); })),
               {"PROFINET DCP", "Set Req", "Control/Signal", "SignalValue: Flash Once (0x0100)"});
  const std::array<DcpSetResult, 1> ok{{{dcp_option::kNameOfStation, DcpBlockError::NoError}}};
  expect_clean(dissect(frame(header(kController, kDevice, frame_id::kDcpGetSet),
                             [&ok](std::span<std::uint8_t> out) { return encode_set_response(out, 0x2001, ok); })),
               {"PROFINET DCP", "Set Ok", "Control/Response", "Name of Station", "BlockError: Ok (0)"});
  const std::array<std::uint16_t, 2> opts{dcp_option::kNameOfStation, dcp_option::kIpParameter};
  expect_clean(dissect(frame(h, [&opts](std::span<std::uint8_t> out) { return encode_get_request(out, 0x2004, opts); })),
               {"PROFINET DCP", "Get Req", "Suboption: Name of Station (2)", "Suboption: IP parameter (2)"});
}

TEST(PnTshark, RtCyclicFrame) {
  if (!have_tshark()) GTEST_SKIP() << "tshark not installed";
  // An output CR of a DAP and one telegram-1-like submodule (4 octets each way), priority tagged.
  const std::array<IoSubmodule, 2> subs{{{IoKind::NoIo, 0, 0}, {IoKind::InputOutput, 4, 4}}};
  std::array<IoPlacement, 2> p{};
  const CsduLayout l = compute_csdu_layout(CrDirection::Output, subs, p);
  ASSERT_TRUE(l.ok());
  std::array<std::uint8_t, kMaxCsduLength> c_sdu{};
  c_sdu[p[1].data_offset] = 0x04;
  c_sdu[p[1].data_offset + 1] = 0x7F;
  c_sdu[p[1].iops_offset] = iox_status::kGood;
  c_sdu[p[0].iocs_offset] = iox_status::kGood;
  c_sdu[p[1].iocs_offset] = iox_status::kGood;
  EthernetHeader h = header(kDevice, kController, 0x8001);
  h.vlan = true;
  h.priority = kPriorityRtCyclic;
  ApduStatus s;
  s.cycle_counter = 0x1234;
  const Bytes f = frame(h, [&](std::span<std::uint8_t> out) {
    return encode_rt_cyclic(out, std::span(c_sdu).first(l.used), l.length, s);
  });
  EXPECT_EQ(f.size(), 64U);
  expect_clean(dissect(f), {"PROFINET cyclic Real-Time, RTC1, ID:0x8001, Len:  40, Cycle: 4660 (Valid,Primary,Ok,Run)",
                            "DataStatus: 0x35", "TransferStatus: 0x00 (OK)",
                            "PROFINET IO Cyclic Service Data Unit: 40 bytes"});
}

EthernetHeader alarm_header(const MacAddress& dst, const MacAddress& src, AlarmPriority p) {
  EthernetHeader h = header(dst, src, p == AlarmPriority::High ? frame_id::kAlarmHigh : frame_id::kAlarmLow);
  h.vlan = true;
  h.priority = p == AlarmPriority::High ? kPriorityAlarmHigh : kPriorityAlarmLow;
  return h;
}

TEST(PnTshark, AlarmExchange) {
  if (!have_tshark()) GTEST_SKIP() << "tshark not installed";
  static constexpr std::array<std::uint8_t, 6> kChannel{0x80, 0x00, 0x08, 0x00, 0x00, 0x01};
  AlarmNotification n;
  n.alarm_type = alarm_type::kDiagnosis;
  n.api = 0x3A00;
  n.slot = 1;
  n.subslot = 1;
  n.module_ident = 0x10;
  n.submodule_ident = 0x01;
  n.specifier.sequence = 5;
  n.specifier.channel_diagnosis = true;
  n.specifier.submodule_diagnosis = true;
  n.specifier.ar_diagnosis = true;
  n.has_user_structure = true;
  n.user_structure_id = user_structure::kChannelDiagnosis;
  n.user_data = kChannel;
  RtaHeader device;  // device -> controller
  device.dst_endpoint = 0x0001;
  device.src_endpoint = 0x0003;
  device.tack = true;
  device.send_seq = 0;
  device.ack_seq = 0xFFFF;
  RtaHeader controller;  // controller -> device
  controller.dst_endpoint = 0x0003;
  controller.src_endpoint = 0x0001;

  const Bytes data = frame(alarm_header(kController, kDevice, AlarmPriority::High), [&](std::span<std::uint8_t> out) {
    const std::size_t block = encode_alarm_notification(out.subspan(kRtaHeaderSize), n);
    return block == 0 ? 0 : encode_rta(out, device, out.subspan(kRtaHeaderSize, block));
  });
  expect_clean(dissect(data), {"PROFINET acyclic Real-Time, Alarm High, ID:0xfc01", "Type: Data-RTA-PDU (0x1)",
                               "TACK: 0x1", "SendSeqNum: 0x0000", "AckSeqNum: 0xffff", "VarPartLen: 0x0022",
                               "BlockType: Alarm Notification High (0x0001)", "AlarmType: Diagnosis (0x0001)",
                               "API: 0x00003a00", "ModuleIdentNumber: 0x00000010",
                               "AlarmSpecifier, Sequence: 5, Channel: 1, Manuf: 0, Submodule: 1 AR: 1",
                               "UserStructureIdentifier: ChannelDiagnosis (0x8000)",
                               "ChannelErrorType: short circuit (0x0001)"});

  RtaHeader ack = controller;
  ack.type = RtaPduType::Ack;
  ack.send_seq = 0xFFFF;
  ack.ack_seq = 0;
  expect_clean(dissect(frame(alarm_header(kDevice, kController, AlarmPriority::High),
                             [&](std::span<std::uint8_t> out) { return encode_rta(out, ack, {}); })),
               {"Type: ACK-RTA-PDU (0x3)", "SendSeqNum: 0xffff", "AckSeqNum: 0x0000", "VarPartLen: 0x0000"});

  RtaHeader ack_data = controller;
  ack_data.tack = true;
  const Bytes alarm_ack = frame(alarm_header(kDevice, kController, AlarmPriority::High), [&](std::span<std::uint8_t> out) {
    const std::size_t block = encode_alarm_ack(out.subspan(kRtaHeaderSize), ack_for(n));
    return block == 0 ? 0 : encode_rta(out, ack_data, out.subspan(kRtaHeaderSize, block));
  });
  expect_clean(dissect(alarm_ack), {"Type: Data-RTA-PDU (0x1)", "BlockType: Alarm Ack High (0x8001)",
                                    "AlarmType: Diagnosis (0x0001)", "Status: OK"});

  RtaHeader err = controller;
  err.send_seq = 0xFFFF;
  err.ack_seq = 0xFFFE;
  expect_clean(dissect(frame(alarm_header(kDevice, kController, AlarmPriority::High), [&](std::span<std::uint8_t> out) {
                 return encode_rta_error(out, err, RtaPnioStatus{0xCF, 0x81, 0xFD, 0x06});
               })),
               {"Type: ERR-RTA-PDU (0x4)", "ErrorCode: RTA error (0xcf)"});

  // A low-priority pull alarm without an AlarmItem on FE01h, priority 5.
  AlarmNotification pull;
  pull.priority = AlarmPriority::Low;
  pull.alarm_type = alarm_type::kPull;
  pull.slot = 1;
  pull.subslot = 1;
  RtaHeader low = device;
  const Bytes pull_frame = frame(alarm_header(kController, kDevice, AlarmPriority::Low), [&](std::span<std::uint8_t> out) {
    const std::size_t block = encode_alarm_notification(out.subspan(kRtaHeaderSize), pull);
    return block == 0 ? 0 : encode_rta(out, low, out.subspan(kRtaHeaderSize, block));
  });
  expect_clean(dissect(pull_frame), {"PRI: 5", "Alarm Low, ID:0xfe01", "BlockType: Alarm Notification Low (0x0002)",
                                     "AlarmType: Pull (0x0003)"});
}

}  // namespace
}  // namespace drivegate::profinet
