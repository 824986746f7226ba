// The ESI reader (config/ethercat/esi.hpp) on three hand-written files in the shapes vendors' files
// have (tests/config/esi/: an ESR-like drive, a CiA 402 drive with DC operation modes, an I/O
// terminal family), field by field, and every error and warning with its exact message. The
// expected values are read off the files themselves; the element and attribute names follow
// ETG.2000 (EtherCATInfo schema).
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "config/ethercat/esi.hpp"

namespace drivegate::config {
namespace {

const std::string kDir = DRIVEGATE_TEST_ESI_DIR;

std::string read(const std::string& file) {
  std::ifstream in(kDir + "/" + file);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

EsiFile load_ok(const std::string& file) {
  Problems problems;
  auto esi = load_esi(kDir + "/" + file, problems);
  EXPECT_TRUE(esi.has_value());
  EXPECT_TRUE(problems.errors().empty()) << (problems.errors().empty() ? "" : problems.errors()[0].to_string());
  EXPECT_TRUE(problems.warnings().empty()) << (problems.warnings().empty() ? "" : problems.warnings()[0].to_string());
  return esi.value_or(EsiFile{});
}

// All problems of a text (errors first), one per line.
struct Outcome {
  bool loaded = false;
  std::string errors;
  std::string warnings;
};
Outcome parse(const std::string& text) {
  Problems problems;
  Outcome o;
  const auto esi = load_esi_text(text, "t.xml", problems);
  o.loaded = esi.has_value();
  for (const auto& d : problems.errors()) o.errors += d.to_string() + "\n";
  for (const auto& d : problems.warnings()) o.warnings += d.to_string() + "\n";
  EXPECT_EQ(o.loaded, !problems.has_errors());
  return o;
}

// A minimal file around one device's elements (the Device element is on line 2).
std::string one_device(const std::string& inner, const std::string& type = R"(<Type ProductCode="#x10">T</Type>)") {
  return "<EtherCATInfo><Vendor><Id>#x2</Id></Vendor><Descriptions><Devices>\n<Device>" + type + "\n" + inner +
         "\n</Device></Devices></Descriptions></EtherCATInfo>\n";
}
// ... and around a dictionary (DataTypes on line 3, Objects on the next).
std::string dictionary(const std::string& data_types, const std::string& objects) {
  return one_device("<Profile><Dictionary><DataTypes>" + data_types + "</DataTypes>\n<Objects>" + objects +
                    "</Objects></Dictionary></Profile>");
}

TEST(Esi, ADriveFileIsReadFieldByField) {
  const EsiFile f = load_ok("esr-triodrive.xml");
  EXPECT_EQ(f.vendor_id, 15U);  // written in decimal
  EXPECT_EQ(f.vendor_name, "ESR Pollmeier GmbH");
  ASSERT_EQ(f.devices.size(), 2U);
  const EsiDevice& d = f.devices[0];
  EXPECT_EQ(d.line, 18);
  EXPECT_EQ(d.product_code, 0x00006755U);
  EXPECT_EQ(d.revision, 1U);
  EXPECT_EQ(d.type, "TrioDrive D/ES");
  EXPECT_EQ(d.name, "ESR TrioDrive D/ES");  // CDATA
  EXPECT_EQ(d.profile_no, 402U);
  ASSERT_TRUE(d.mailbox.has_value());
  EXPECT_TRUE(d.mailbox->coe);
  EXPECT_FALSE(d.mailbox->sdo_info);
  EXPECT_TRUE(d.mailbox->pdo_assign);
  EXPECT_TRUE(d.mailbox->pdo_config);
  EXPECT_FALSE(d.mailbox->complete_access);
  EXPECT_TRUE(d.mailbox->segmented_sdo);
  EXPECT_FALSE(d.mailbox->eoe || d.mailbox->foe || d.mailbox->soe || d.mailbox->aoe);
  ASSERT_EQ(d.sms.size(), 4U);
  EXPECT_EQ(d.sms[0].kind, EsiSmKind::MBoxOut);
  EXPECT_EQ(d.sms[0].min_size, 34U);
  EXPECT_EQ(d.sms[0].max_size, 256U);
  EXPECT_EQ(d.sms[0].default_size, 128U);
  EXPECT_EQ(d.sms[0].start_address, 0x1800U);
  EXPECT_EQ(d.sms[0].control_byte, 0x26U);
  EXPECT_TRUE(d.sms[0].enable);
  EXPECT_EQ(d.sms[1].kind, EsiSmKind::MBoxIn);
  EXPECT_EQ(d.sms[1].start_address, 0x1C00U);  // "#x1c00": lower-case hex
  EXPECT_EQ(d.sms[2].kind, EsiSmKind::Outputs);
  EXPECT_EQ(d.sms[2].text, "Outputs");
  EXPECT_FALSE(d.sms[2].min_size.has_value());
  EXPECT_EQ(d.sms[2].control_byte, 0x64U);
  EXPECT_EQ(d.sms[3].kind, EsiSmKind::Inputs);
  EXPECT_EQ(d.sms[3].start_address, 0x1400U);

  ASSERT_EQ(d.rxpdos.size(), 2U);
  const EsiPdo& rx = d.rxpdos[0];
  EXPECT_EQ(rx.index, 0x1600U);
  EXPECT_EQ(rx.name, "Receive PDO 1");
  EXPECT_FALSE(rx.fixed);
  EXPECT_FALSE(rx.mandatory);
  EXPECT_EQ(rx.sm, 2);
  EXPECT_EQ(rx.line, 104);
  ASSERT_EQ(rx.entries.size(), 2U);
  EXPECT_EQ(rx.entries[0].object, (cia402::ObjectId{0x6040, 0}));
  EXPECT_EQ(rx.entries[0].bits, 16);
  EXPECT_EQ(rx.entries[0].name, "Controlword");
  EXPECT_EQ(rx.entries[0].data_type, "UINT");
  EXPECT_EQ(rx.entries[0].line, 107);
  EXPECT_FALSE(rx.entries[0].padding());
  EXPECT_EQ(rx.entries[1].object, (cia402::ObjectId{0x607A, 0}));
  EXPECT_EQ(rx.bits(), 48);
  EXPECT_EQ(d.rxpdos[1].index, 0x1601U);
  EXPECT_FALSE(d.rxpdos[1].sm.has_value());  // not assigned by default
  EXPECT_TRUE(d.rxpdos[1].entries.empty());
  ASSERT_EQ(d.txpdos.size(), 2U);
  EXPECT_EQ(d.txpdos[0].index, 0x1A00U);
  EXPECT_EQ(d.txpdos[0].sm, 3);
  EXPECT_EQ(d.txpdos[0].bits(), 48);
  EXPECT_TRUE(d.op_modes.empty());

  // The dictionary: 1000h, 1001h, 1018h:0..4, 14 VAR objects of the profile area, 60C1h:0..1.
  EXPECT_TRUE(d.has_dictionary);
  ASSERT_EQ(d.objects.size(), 23U);
  for (std::size_t i = 1; i < d.objects.size(); ++i) EXPECT_LT(d.objects[i - 1].id.key(), d.objects[i].id.key());
  const EsiObject& type = d.objects[0];
  EXPECT_EQ(type.id, (cia402::ObjectId{0x1000, 0}));
  EXPECT_EQ(type.name, "Device type");
  EXPECT_EQ(type.parent, "");
  EXPECT_EQ(type.type, "UDINT");
  EXPECT_EQ(type.data_type, 0x0007);
  EXPECT_EQ(type.bits, 32);
  EXPECT_EQ(type.access, EsiAccess::ReadOnly);
  EXPECT_FALSE(type.rx_mappable || type.tx_mappable);
  EXPECT_EQ(type.default_data, "92010200");

  const EsiObject* vendor = find_esi_object(d.objects, cia402::ObjectId{0x1018, 1});
  ASSERT_NE(vendor, nullptr);
  EXPECT_EQ(vendor->name, "Vendor ID");
  EXPECT_EQ(vendor->parent, "Identity");
  EXPECT_EQ(vendor->type, "UDINT");
  EXPECT_EQ(vendor->bits, 32);
  EXPECT_EQ(vendor->default_data, "0F000000");  // Info/SubItem by name
  EXPECT_EQ(vendor->line, 64);
  const EsiObject* serial = find_esi_object(d.objects, cia402::ObjectId{0x1018, 4});
  ASSERT_NE(serial, nullptr);
  EXPECT_EQ(serial->name, "Serial number");
  EXPECT_EQ(serial->default_data, "");

  const EsiObject* mode = find_esi_object(d.objects, cia402::ObjectId{0x6060, 0});
  ASSERT_NE(mode, nullptr);
  EXPECT_EQ(mode->type, "INT");  // 16 bits on this drive [dunker-ethercat-coe.md quirk 1]
  EXPECT_EQ(mode->data_type, 0x0003);
  EXPECT_EQ(mode->bits, 16);
  EXPECT_EQ(mode->access, EsiAccess::ReadWrite);
  EXPECT_TRUE(mode->rx_mappable);
  EXPECT_FALSE(mode->tx_mappable);
  EXPECT_EQ(mode->line, 77);

  // 60C1h: a record of sub-index 0 and an array (DT60C1ARR) with LBound 1, 1 element; the element's
  // name comes from Info/SubItem by position, its flags from the SubItem.
  const EsiObject* count = find_esi_object(d.objects, cia402::ObjectId{0x60C1, 0});
  ASSERT_NE(count, nullptr);
  EXPECT_EQ(count->name, "SubIndex 000");
  EXPECT_EQ(count->type, "USINT");
  EXPECT_EQ(count->default_data, "01");
  const EsiObject* target = find_esi_object(d.objects, cia402::ObjectId{0x60C1, 1});
  ASSERT_NE(target, nullptr);
  EXPECT_EQ(target->name, "Interpolation target");
  EXPECT_EQ(target->parent, "Interpolation data record");
  EXPECT_EQ(target->type, "DINT");
  EXPECT_EQ(target->data_type, 0x0004);
  EXPECT_EQ(target->bits, 32);
  EXPECT_EQ(target->access, EsiAccess::ReadWrite);
  EXPECT_TRUE(target->rx_mappable);
  EXPECT_EQ(target->line, 87);
  EXPECT_EQ(find_esi_object(d.objects, cia402::ObjectId{0x60C1, 2}), nullptr);

  const EsiDevice& midi = f.devices[1];
  EXPECT_EQ(midi.product_code, 0x00006745U);
  EXPECT_EQ(midi.line, 128);
  EXPECT_EQ(midi.profile_no, 402U);
  EXPECT_FALSE(midi.has_dictionary);
  EXPECT_TRUE(midi.objects.empty());
  EXPECT_EQ(esi_device_text(d), "\"TrioDrive D/ES\" (product 0x00006755, revision 0x00000001)");
}

TEST(Esi, ADcDriveFileIsReadFieldByField) {
  const EsiFile f = load_ok("generic-cia402-dc.xml");
  EXPECT_EQ(f.vendor_id, 0xA5EU);
  EXPECT_EQ(f.vendor_name, "Example Drives Ltd");  // LcId 1033 before the first (1031)
  ASSERT_EQ(f.devices.size(), 2U);
  EXPECT_EQ(f.devices[0].revision, 0x00010000U);
  EXPECT_FALSE(f.devices[0].has_dictionary);
  const EsiDevice& d = f.devices[1];
  EXPECT_EQ(d.product_code, 0x1234U);
  EXPECT_EQ(d.revision, 0x00020000U);
  EXPECT_EQ(d.name, "XD-402 servo drive");
  ASSERT_TRUE(d.mailbox.has_value());
  EXPECT_TRUE(d.mailbox->coe && d.mailbox->eoe && d.mailbox->foe);
  EXPECT_FALSE(d.mailbox->soe || d.mailbox->aoe);
  EXPECT_TRUE(d.mailbox->sdo_info && d.mailbox->pdo_assign && d.mailbox->pdo_config && d.mailbox->complete_access);
  EXPECT_EQ(d.sms[2].default_size, 19U);
  EXPECT_TRUE(d.rxpdos[0].mandatory);  // "true" as well as "1"
  EXPECT_EQ(d.rxpdos[0].entries[5].object, (cia402::ObjectId{0x60C1, 1}));  // SubIndex "#x1"
  EXPECT_EQ(d.rxpdos[0].bits(), 136);
  EXPECT_EQ(d.txpdos[0].bits(), 120);

  ASSERT_EQ(d.op_modes.size(), 2U);
  EXPECT_EQ(d.op_modes[0].name, "DC");
  EXPECT_EQ(d.op_modes[0].desc, "DC-Synchron");
  EXPECT_EQ(d.op_modes[0].assign_activate, 0x0300U);
  EXPECT_EQ(d.op_modes[0].cycle_time_sync0, 0U);
  EXPECT_EQ(d.op_modes[0].cycle_time_sync0_factor, 1);
  EXPECT_EQ(d.op_modes[0].shift_time_sync0, -20000);
  EXPECT_EQ(d.op_modes[0].line, 135);
  EXPECT_EQ(d.op_modes[1].name, "FreeRun");
  EXPECT_EQ(d.op_modes[1].assign_activate, 0U);
  EXPECT_FALSE(d.op_modes[1].cycle_time_sync0.has_value());
  EXPECT_FALSE(d.op_modes[1].shift_time_sync0.has_value());

  const EsiObject* name = find_esi_object(d.objects, cia402::ObjectId{0x1008, 0});
  ASSERT_NE(name, nullptr);
  EXPECT_EQ(name->type, "STRING(12)");
  EXPECT_EQ(name->data_type, 0x0009);
  EXPECT_EQ(name->bits, 96);
  // 1C12h: sub-index 0 and an array of 2 UINT elements named by Info/SubItem in order.
  for (std::uint8_t sub = 0; sub <= 2; ++sub) {
    const EsiObject* o = find_esi_object(d.objects, cia402::ObjectId{0x1C12, sub});
    ASSERT_NE(o, nullptr) << int{sub};
    EXPECT_EQ(o->name, "SubIndex 00" + std::to_string(sub));
    EXPECT_EQ(o->access, EsiAccess::ReadWrite);
    EXPECT_EQ(o->line, 67);
  }
  EXPECT_EQ(find_esi_object(d.objects, cia402::ObjectId{0x1C12, 1})->type, "UINT");
  EXPECT_EQ(find_esi_object(d.objects, cia402::ObjectId{0x1C12, 1})->bits, 16);
  EXPECT_EQ(find_esi_object(d.objects, cia402::ObjectId{0x1C12, 1})->default_data, "0016");
  // 60C1h's elements have no Info names: "SubIndex 00N" as slave stacks name them.
  EXPECT_EQ(find_esi_object(d.objects, cia402::ObjectId{0x60C1, 2})->name, "SubIndex 002");
  EXPECT_EQ(find_esi_object(d.objects, cia402::ObjectId{0x60C1, 2})->bits, 32);
  const EsiObject* tv = find_esi_object(d.objects, cia402::ObjectId{0x60FF, 0});
  ASSERT_NE(tv, nullptr);
  EXPECT_TRUE(tv->rx_mappable && tv->tx_mappable);  // "RT"

  // Revisions of one product; with the revision, one of them.
  EXPECT_EQ(find_esi_devices(f, 0x1234, std::nullopt).size(), 2U);
  ASSERT_EQ(find_esi_devices(f, 0x1234, 0x00010000).size(), 1U);
  EXPECT_EQ(find_esi_devices(f, 0x1234, 0x00010000)[0], &f.devices[0]);
  EXPECT_TRUE(find_esi_devices(f, 0x1235, std::nullopt).empty());
}

TEST(Esi, ObjectsAreFoundByNameAndSubItemsByObjectColonSub) {
  const EsiFile f = load_ok("generic-cia402-dc.xml");
  const auto& objects = f.devices[1].objects;
  const auto id = [&](std::string_view name) {
    const EsiObject* o = find_esi_object(objects, name);
    return o ? o->id : cia402::ObjectId{0xFFFF, 0xFF};
  };
  EXPECT_EQ(id("Controlword"), (cia402::ObjectId{0x6040, 0}));
  EXPECT_EQ(id("CONTROLWORD"), (cia402::ObjectId{0x6040, 0}));
  EXPECT_EQ(id(" target velocity "), (cia402::ObjectId{0x60FF, 0}));
  EXPECT_EQ(id("Homing speeds:Speed during search for zero"), (cia402::ObjectId{0x6099, 2}));
  EXPECT_EQ(id("homing speeds : speed during search for switch"), (cia402::ObjectId{0x6099, 1}));
  EXPECT_EQ(id("RxPDO assign:SubIndex 001"), (cia402::ObjectId{0x1C12, 1}));
  // A sub-item's name alone, an object with sub-items by its name, and unknown names find nothing.
  EXPECT_EQ(find_esi_object(objects, "Speed during search for zero"), nullptr);
  EXPECT_EQ(find_esi_object(objects, "Homing speeds"), nullptr);
  EXPECT_EQ(find_esi_object(objects, "Homing speeds:"), nullptr);
  EXPECT_EQ(find_esi_object(objects, ""), nullptr);
  // Two objects of one name: both are returned, and the single lookup finds none.
  const Outcome o = parse(dictionary("", R"(<Object><Index>#x2000</Index><Name>Gain</Name><Type>UINT</Type></Object>
<Object><Index>#x2001</Index><Name>gain</Name><Type>UINT</Type></Object>)"));
  ASSERT_TRUE(o.loaded) << o.errors;
  Problems p;
  const auto file = load_esi_text(dictionary("", R"(<Object><Index>#x2000</Index><Name>Gain</Name><Type>UINT</Type></Object>
<Object><Index>#x2001</Index><Name>gain</Name><Type>UINT</Type></Object>)"),
                                  "t.xml", p);
  ASSERT_TRUE(file.has_value());
  EXPECT_EQ(find_esi_objects(file->devices[0].objects, "GAIN").size(), 2U);
  EXPECT_EQ(find_esi_object(file->devices[0].objects, "GAIN"), nullptr);
}

TEST(Esi, AnIoTerminalFileIsReadFieldByField) {
  const EsiFile f = load_ok("beckhoff-el-io.xml");
  EXPECT_EQ(f.vendor_id, 2U);
  EXPECT_EQ(f.vendor_name, "Beckhoff Automation GmbH & Co. KG");  // entity decoded
  ASSERT_EQ(f.devices.size(), 3U);
  const EsiDevice& in = f.devices[0];
  EXPECT_EQ(in.product_code, 0x03EC3052U);
  EXPECT_EQ(in.revision, 0x00100000U);
  EXPECT_EQ(in.type, "EL1004");
  EXPECT_EQ(in.name, "EL1004 4Ch. Dig. Input 24V, 3ms");
  EXPECT_FALSE(in.mailbox.has_value());
  EXPECT_FALSE(in.profile_no.has_value());
  EXPECT_FALSE(in.has_dictionary);
  ASSERT_EQ(in.sms.size(), 1U);
  EXPECT_EQ(in.sms[0].kind, EsiSmKind::Inputs);
  EXPECT_EQ(in.sms[0].control_byte, 0x00U);
  EXPECT_EQ(in.sms[0].start_address, 0x1000U);
  EXPECT_TRUE(in.rxpdos.empty());
  ASSERT_EQ(in.txpdos.size(), 4U);
  for (const auto& p : in.txpdos) {
    EXPECT_TRUE(p.fixed);
    EXPECT_TRUE(p.mandatory);
    EXPECT_EQ(p.sm, 0);
  }
  EXPECT_EQ(in.txpdos[1].index, 0x1A01U);
  EXPECT_EQ(in.txpdos[1].entries[0].object, (cia402::ObjectId{0x6010, 1}));
  EXPECT_EQ(in.txpdos[1].entries[0].bits, 1);
  EXPECT_EQ(in.txpdos[1].entries[0].data_type, "BOOL");
  // The gap: Index 0, no SubIndex, no name.
  ASSERT_EQ(in.txpdos[3].entries.size(), 2U);
  EXPECT_TRUE(in.txpdos[3].entries[1].padding());
  EXPECT_EQ(in.txpdos[3].entries[1].bits, 4);
  EXPECT_EQ(in.txpdos[3].entries[1].name, "");
  EXPECT_EQ(in.txpdos[3].bits(), 5);
  EXPECT_EQ(f.devices[1].revision, 0x00110000U);
  const EsiDevice& out = f.devices[2];
  EXPECT_EQ(out.product_code, 0x07D83052U);
  EXPECT_EQ(out.rxpdos.size(), 8U);
  EXPECT_EQ(out.rxpdos[7].index, 0x1607U);
  EXPECT_EQ(out.rxpdos[7].entries[0].object, (cia402::ObjectId{0x7070, 1}));
  EXPECT_EQ(out.sms[0].control_byte, 0x44U);
  EXPECT_EQ(esi_device_text(out), "\"EL2008\" (product 0x07D83052, revision 0x00100000)");
}

TEST(Esi, NumbersAreHexOrDecimalAndFit) {
  EXPECT_EQ(parse_esi_number("#x0000000F"), 15U);
  EXPECT_EQ(parse_esi_number("#X1a"), 26U);
  EXPECT_EQ(parse_esi_number("0x1A"), 26U);
  EXPECT_EQ(parse_esi_number(" 15 "), 15U);
  EXPECT_EQ(parse_esi_number("#xFFFFFFFFFFFFFFFF"), 0xFFFFFFFFFFFFFFFFULL);
  EXPECT_FALSE(parse_esi_number("#x10000000000000000").has_value());  // 65 bits
  EXPECT_FALSE(parse_esi_number("18446744073709551616").has_value());
  EXPECT_FALSE(parse_esi_number("").has_value());
  EXPECT_FALSE(parse_esi_number("#x").has_value());
  EXPECT_FALSE(parse_esi_number("-1").has_value());
  EXPECT_FALSE(parse_esi_number("+1").has_value());
  EXPECT_FALSE(parse_esi_number("1 2").has_value());
  EXPECT_FALSE(parse_esi_number("#x-1").has_value());
  EXPECT_FALSE(parse_esi_number("12h").has_value());
  EXPECT_EQ(parse_esi_signed("-20000"), -20000);
  EXPECT_EQ(parse_esi_signed("#x10"), 16);
  EXPECT_FALSE(parse_esi_signed("-#x10").has_value());
  EXPECT_FALSE(parse_esi_signed("-").has_value());
  EXPECT_FALSE(parse_esi_signed("#x8000000000000000").has_value());
  EXPECT_EQ(esi_hex32(0x3EC3052), "0x03EC3052");
}

TEST(Esi, MalformedFilesGetOneClearError) {
  EXPECT_EQ(parse("").errors, "t.xml: not well-formed XML (empty document)\n");
  // tinyxml2 names the line where the element left open starts.
  EXPECT_EQ(parse("<EtherCATInfo>\n<Vendor>\n</EtherCATInfo>").errors,
            "t.xml:2:1: not well-formed XML (mismatched element)\n");
  EXPECT_EQ(parse("<EtherCATInfo a=>\n</EtherCATInfo>").errors, "t.xml:1:1: not well-formed XML (parsing attribute)\n");
  EXPECT_EQ(parse("\x01\xff\xfe garbage").errors, "t.xml:1:1: not well-formed XML (parsing text)\n");
  std::string deep;
  for (int i = 0; i < 200; ++i) deep += "<a>";
  EXPECT_EQ(parse("<EtherCATInfo>" + deep).errors, "t.xml:1:1: not well-formed XML (element depth exceeded)\n");
  EXPECT_EQ(parse("<?xml version=\"1.0\"?>\n<EtherCATInfoList/>").errors,
            "t.xml:2:1: the root element is <EtherCATInfoList>, not <EtherCATInfo>: this is not an ESI file (ETG.2000)\n");
  EXPECT_EQ(parse("<EtherCATInfo/>").errors,
            "t.xml:1:1: EtherCATInfo: has no Vendor\nt.xml:1:1: EtherCATInfo: lists no Device\n");
  EXPECT_EQ(parse("<EtherCATInfo><Vendor/><Descriptions>\n<Devices/></Descriptions></EtherCATInfo>").errors,
            "t.xml:1:1: Vendor: has no Id\nt.xml:2:1: Descriptions/Devices: lists no Device\n");
}

TEST(Esi, BadNumbersAndMissingElementsAreErrorsWithTheirPlace) {
  const auto vendor = [](const std::string& id) {
    return parse("<EtherCATInfo><Vendor>\n<Id>" + id + "</Id></Vendor><Descriptions><Devices><Device><Type ProductCode=\"1\"/>"
                 "</Device></Devices></Descriptions></EtherCATInfo>")
        .errors;
  };
  EXPECT_EQ(vendor("#xZZ"), "t.xml:2:1: Vendor/Id: must be a number (decimal or #x hex), got \"#xZZ\"\n");
  EXPECT_EQ(vendor("#x1FFFFFFFF"), "t.xml:2:1: Vendor/Id: \"#x1FFFFFFFF\" is beyond 4294967295 (#xFFFFFFFF)\n");
  EXPECT_EQ(vendor("99999999999999999999999"),
            "t.xml:2:1: Vendor/Id: must be a number (decimal or #x hex), got \"99999999999999999999999\"\n");
  EXPECT_EQ(vendor(""), "t.xml:2:1: Vendor/Id: must be a number (decimal or #x hex), got \"\"\n");

  EXPECT_EQ(parse(one_device("", "")).errors, "t.xml:2:1: Device[1]: has no Type (its product code and revision)\n");
  EXPECT_EQ(parse(one_device("", "<Type>X</Type>")).errors, "t.xml:2:1: Device[1]/Type: has no ProductCode\n");
  EXPECT_EQ(parse(one_device("", R"(<Type ProductCode="#x1" RevisionNo="-1">X</Type>)")).errors,
            "t.xml:2:1: Device[1]/Type/@RevisionNo: must be a number (decimal or #x hex), got \"-1\"\n");
  EXPECT_EQ(parse(one_device(R"(<Profile><ProfileNo>x</ProfileNo></Profile>)")).errors,
            "t.xml:3:1: Device[1]/Profile[1]/ProfileNo: must be a number (decimal or #x hex), got \"x\"\n");
  EXPECT_EQ(parse(one_device(R"(<Sm StartAddress="#x10000" ControlByte="#x100">Outputs</Sm>)")).errors,
            "t.xml:3:1: Device[1]/Sm[1]/@StartAddress: \"#x10000\" is beyond 65535 (#xFFFF)\n"
            "t.xml:3:1: Device[1]/Sm[1]/@ControlByte: \"#x100\" is beyond 255 (#xFF)\n");
  EXPECT_EQ(parse(one_device(R"(<RxPdo Sm="16"><Name>P</Name></RxPdo>)")).errors,
            "t.xml:3:1: Device[1]/RxPdo[1]/@Sm: \"16\" is beyond 15 (#xF)\n"
            "t.xml:3:1: Device[1]/RxPdo[1]: has no Index\n");
  EXPECT_EQ(parse(one_device("<TxPdo><Index>#x1a00</Index>\n<Entry><Index>#x10000</Index><BitLen>0</BitLen></Entry>\n"
                             "<Entry><Index>#x6000</Index><SubIndex>256</SubIndex></Entry>\n"
                             "<Entry><Index>#x6000</Index><BitLen>300</BitLen></Entry></TxPdo>"))
                .errors,
            "t.xml:4:1: Device[1]/TxPdo[1]/Entry[1]/Index: \"#x10000\" is beyond 65535 (#xFFFF)\n"
            "t.xml:4:1: Device[1]/TxPdo[1]/Entry[1]/BitLen: must be 1..255, got 0\n"
            "t.xml:5:1: Device[1]/TxPdo[1]/Entry[2]/SubIndex: \"256\" is beyond 255 (#xFF)\n"
            "t.xml:5:1: Device[1]/TxPdo[1]/Entry[2]: has no BitLen\n"
            "t.xml:6:1: Device[1]/TxPdo[1]/Entry[3]/BitLen: \"300\" is beyond 255 (#xFF)\n");
  EXPECT_EQ(parse(one_device("<Dc><OpMode><Name>DC</Name><CycleTimeSync0 Factor=\"x\">0</CycleTimeSync0>"
                             "<ShiftTimeSync0>#x80000000</ShiftTimeSync0></OpMode>\n<OpMode/></Dc>"))
                .errors,
            "t.xml:3:1: Device[1]/Dc/OpMode[1]: has no AssignActivate\n"
            "t.xml:3:1: Device[1]/Dc/OpMode[1]/CycleTimeSync0/@Factor: must be a number in -2147483648..2147483647, got \"x\"\n"
            "t.xml:3:1: Device[1]/Dc/OpMode[1]/ShiftTimeSync0: must be a number in -2147483648..2147483647, got \"#x80000000\"\n"
            "t.xml:4:1: Device[1]/Dc/OpMode[2]: has no Name\n"
            "t.xml:4:1: Device[1]/Dc/OpMode[2]: has no AssignActivate\n");
}

TEST(Esi, DictionaryErrorsAreExact) {
  EXPECT_EQ(parse(dictionary("", "<Object><Name>A</Name><Type>UINT</Type></Object>\n<Object><Index>#x2000</Index></Object>"))
                .errors,
            "t.xml:4:1: Device[1]/Profile[1]/Dictionary/Objects/Object[1]: has no Index\n"
            "t.xml:5:1: Device[1]/Profile[1]/Dictionary/Objects/Object[2]: has no Type\n");
  EXPECT_EQ(parse(dictionary("", "<Object><Index>#x2000</Index><Type>UINT</Type><BitSize>#x10000</BitSize>"
                                 "<Flags><Access>readwrite</Access></Flags></Object>"))
                .errors,
            "t.xml:4:1: Device[1]/Profile[1]/Dictionary/Objects/Object[1]/Flags/Access: must be ro, rw or wo, got \"readwrite\"\n"
            "t.xml:4:1: Device[1]/Profile[1]/Dictionary/Objects/Object[1]/BitSize: \"#x10000\" is beyond 65535 (#xFFFF)\n");
  EXPECT_EQ(parse(dictionary("<DataType><Name>R</Name>\n<SubItem><Name>no index</Name><Type>UINT</Type></SubItem></DataType>",
                             "<Object><Index>#x2000</Index><Type>R</Type></Object>"))
                .errors,
            "t.xml:4:1: DataType \"R\"/SubItem[1]: has no SubIdx\n");
  EXPECT_EQ(parse(dictionary("<DataType><Name>A</Name><BaseType>UINT</BaseType>\n"
                             "<ArrayInfo><LBound>250</LBound><Elements>10</Elements></ArrayInfo></DataType>",
                             "<Object><Index>#x2000</Index><Type>A</Type></Object>"))
                .errors,
            "t.xml:3:1: DataType \"A\": has elements beyond sub-index 255\n");
  EXPECT_EQ(parse(dictionary("<DataType><Name>A</Name><BaseType>UINT</BaseType>\n<ArrayInfo><LBound>1</LBound></ArrayInfo></DataType>",
                             "<Object><Index>#x2000</Index><Type>A</Type></Object>"))
                .errors,
            "t.xml:4:1: DataType \"A\"/ArrayInfo: has no Elements\n");
}

TEST(Esi, ExpansionIsBoundedPerObjectAndPerDevice) {
  // Two arrays of 200 elements in one record: sub-indices repeat, and past 256 entries it stops.
  const std::string arr = "<DataType><Name>A</Name><BaseType>UINT</BaseType><ArrayInfo><LBound>1</LBound>"
                          "<Elements>200</Elements></ArrayInfo></DataType>";
  EXPECT_EQ(parse(dictionary(arr + "<DataType><Name>R</Name><SubItem><Name>a</Name><Type>A</Type></SubItem>"
                                   "<SubItem><Name>b</Name><Type>A</Type></SubItem></DataType>",
                             "<Object><Index>#x2000</Index><Type>R</Type></Object>"))
                .errors,
            "t.xml:3:1: DataType \"A\": gives object 2000h more than 256 sub-indices\n");
  // 258 objects of 256 entries each: the device's dictionary stops at kMaxEsiEntries.
  std::string objects;
  for (int i = 0; i < 258; ++i)
    objects += "<Object><Index>" + std::to_string(0x2000 + i) + "</Index><Type>R</Type></Object>";
  const std::string full = "<DataType><Name>F</Name><BaseType>UINT</BaseType><ArrayInfo><LBound>1</LBound>"
                           "<Elements>255</Elements></ArrayInfo></DataType><DataType><Name>R</Name><SubItem><SubIdx>0"
                           "</SubIdx><Name>n</Name><Type>USINT</Type></SubItem><SubItem><Name>e</Name><Type>F</Type>"
                           "</SubItem></DataType>";
  EXPECT_EQ(parse(dictionary(full, objects)).errors,
            "t.xml:4:1: Device[1]/Profile[1]/Dictionary/Objects/Object[257]: the dictionary has more than 65536 "
            "entries\n");
}

TEST(Esi, OdditiesOfOtherToolsAreWarnings) {
  const Outcome o = parse(dictionary(
      // a cycle of aliases, which ends as an unknown type
      "<DataType><Name>X</Name><BaseType>Y</BaseType></DataType><DataType><Name>Y</Name><BaseType>X</BaseType></DataType>",
      "<Object><Index>#x2000</Index><Name>Odd</Name><Type>FOO</Type><BitSize>24</BitSize>"
      "<Flags><Access>rw</Access><PdoMapping>X</PdoMapping></Flags></Object>\n"
      "<Object><Index>#x2001</Index><Name>No size</Name><Type>BAR</Type></Object>\n"
      "<Object><Index>#x2000</Index><Name>Again</Name><Type>UINT</Type></Object>\n"
      "<Object><Index>#x2002</Index><Name>Loop</Name><Type>X</Type><BitSize>8</BitSize></Object>"));
  ASSERT_TRUE(o.loaded) << o.errors;
  EXPECT_EQ(o.warnings,
            "t.xml:4:1: Device[1]/Profile[1]/Dictionary/Objects/Object[1]/Flags/PdoMapping: must be R, T, RT or TR, got \"X\"\n"
            "t.xml:4:1: Device[1]/Profile[1]/Dictionary/Objects/Object[1]: Type \"FOO\" is neither an ETG base type nor in "
            "DataTypes; its size is taken from BitSize\n"
            "t.xml:5:1: Device[1]/Profile[1]/Dictionary/Objects/Object[2]: Type \"BAR\" has no size and the object no "
            "BitSize; it is left out\n"
            "t.xml:7:1: Device[1]/Profile[1]/Dictionary/Objects/Object[4]: Type \"X\" is neither an ETG base type nor in "
            "DataTypes; its size is taken from BitSize\n"
            "t.xml:6:1: object 2000h:0 is described again (first at line 4); the first is kept\n");
  Problems p;
  const auto f = load_esi_text(dictionary("", "<Object><Index>#x2000</Index><Name>Odd</Name><Type>FOO</Type><BitSize>24</BitSize>"
                                              "<Flags><Access>rw</Access></Flags></Object>"),
                               "t.xml", p);
  ASSERT_TRUE(f.has_value());
  ASSERT_EQ(f->devices[0].objects.size(), 1U);
  EXPECT_EQ(f->devices[0].objects[0].type, "FOO");
  EXPECT_EQ(f->devices[0].objects[0].data_type, 0);
  EXPECT_EQ(f->devices[0].objects[0].bits, 24);

  EXPECT_EQ(parse(one_device(R"(<RxPdo Fixed="yes"><Index>#x1600</Index></RxPdo>
<Sm>Foo</Sm><Profile><DictionaryFile>dict.xml</DictionaryFile></Profile>)"))
                .warnings,
            "t.xml:4:1: Device[1]/Profile[1]/DictionaryFile: the dictionary in another file (\"dict.xml\") is not read; "
            "objects are not checked\n"
            "t.xml:4:1: Device[1]/Sm[1]: is \"Foo\", none of MBoxOut, MBoxIn, Outputs, Inputs\n"
            "t.xml:3:1: Device[1]/RxPdo[1]/@Fixed: must be true, false, 1 or 0, got \"yes\"; taken as false\n");
  // Many warnings: the first 50 and a count.
  std::string many;
  for (int i = 0; i < 60; ++i)
    many += "<Object><Index>" + std::to_string(0x2000 + i) + "</Index><Type>FOO</Type><BitSize>8</BitSize></Object>";
  Problems q;
  ASSERT_TRUE(load_esi_text(dictionary("", many), "t.xml", q).has_value());
  ASSERT_EQ(q.warnings().size(), 51U);
  EXPECT_EQ(q.warnings().back().to_string(), "t.xml: ... and 10 more warnings");
}

TEST(Esi, FilesAreReadFromDiskWithTheirName) {
  Problems p;
  EXPECT_FALSE(load_esi(kDir + "/no-such.xml", p).has_value());
  ASSERT_EQ(p.errors().size(), 1U);
  EXPECT_EQ(p.errors()[0].to_string(), kDir + "/no-such.xml: cannot open file: No such file or directory");
  // The same text from disk and from memory give the same result.
  Problems a;
  Problems b;
  const auto from_disk = load_esi(kDir + "/beckhoff-el-io.xml", a);
  const auto from_text = load_esi_text(read("beckhoff-el-io.xml"), "x", b);
  ASSERT_TRUE(from_disk && from_text);
  EXPECT_EQ(from_disk->devices.size(), from_text->devices.size());
}

}  // namespace
}  // namespace drivegate::config
