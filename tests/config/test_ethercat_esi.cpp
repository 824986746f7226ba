// ESI files in configurations with ethercat buses: `esi:` of an axis' ethercat section and of an
// io: slave, the checks of the device profile against the ESI device (identity, mapped objects,
// fixed PDOs, start-up writes) with their exact messages, and parameter names through the ESI.
// The files are tests/config/esi/ (see test_esi.cpp); variants are written to a temporary
// directory with one change each.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "config/ethercat/bus_type.hpp"
#include "config/ethercat/parameters.hpp"
#include "config/ethercat/plan.hpp"
#include "tests/config/test_support.hpp"

namespace drivegate::config {
namespace {

namespace fs = std::filesystem;
const std::string kDir = DRIVEGATE_TEST_ESI_DIR;

LoadOptions options() {
  LoadOptions o = test::test_options();
  BusTypeInfo t = ethercat_bus_type();
  t.make_bus = [](const BusPlan&) -> std::unique_ptr<core::Bus> { return nullptr; };
  o.bus_types.add(std::move(t));
  return o;
}

std::string read(const std::string& file) {
  std::ifstream in(kDir + "/" + file);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// `text` with `from` replaced by `to` (which must be there once).
std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  EXPECT_EQ(text.find(from, at + 1), std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

std::string config(const std::string& axes, const std::string& io = "") {
  return "gateway: { name: cell }\nbuses:\n  - name: ec0\n    type: ethercat\n    cycle_time: 2ms\n"
         "    options: { transport: sim }\n" +
         (io.empty() ? std::string{} : "    io:\n" + io) + "axes:\n" + axes;
}

std::string esr_axis(const std::string& esi) {
  return "  - { name: x, bus: ec0, address: 1, device: esr-triodrive, mechanics: { encoder_counts_per_rev: 4096 }, "
         "defaults: { mode: ip }, ethercat: { esi: \"" + esi + "\" } }\n";
}
std::string generic_axis(const std::string& esi, const std::string& name = "y", int address = 2) {
  return "  - { name: " + name + ", bus: ec0, address: " + std::to_string(address) +
         ", device: generic-cia402, mechanics: { encoder_counts_per_rev: 4096 }, defaults: { mode: csp }, ethercat: { "
         "esi: \"" + esi + "\" } }\n";
}

class EthercatEsi : public test::TempDir {
 protected:
  // The errors of a config whose esr axis names a variant of the ESR file.
  std::string esr_errors(const std::string& esi_text) {
    write("esr.xml", esi_text);
    return test::errors_of(config(esr_axis((dir_ / "esr.xml").string())), options());
  }
  std::string esi_path(const std::string& file) const { return kDir + "/" + file; }
};

TEST_F(EthercatEsi, AxesAndIoSlavesTakeTheirEsi) {
  const Plan p = load_plan_from_string(
      config(esr_axis(esi_path("esr-triodrive.xml")) + generic_axis(esi_path("generic-cia402-dc.xml")),
             "      - { name: lamps, position: 3, product_code: 0x07D83052, outputs: 1, esi: \"" +
                 esi_path("beckhoff-el-io.xml") + "\" }\n"),
      "t.yaml", options());
  const auto& bus = p.buses.at(0);
  const auto& x = bus.axes.at(0).section<EthercatAxisSpec>();
  EXPECT_EQ(x.esi, esi_path("esr-triodrive.xml"));
  EXPECT_EQ(x.esi_device, "\"TrioDrive D/ES\" (product 0x00006755, revision 0x00000001)");
  EXPECT_EQ(x.esi_objects.size(), 23U);
  // The generic profile lists no identity: the file's one product, its newest revision.
  const auto& y = bus.axes.at(1).section<EthercatAxisSpec>();
  EXPECT_EQ(y.esi_device, "\"XD-402\" (product 0x00001234, revision 0x00020000)");
  EXPECT_EQ(y.esi_objects.size(), 21U);
  const auto& io = bus.section<EthercatBusOptions>().io.at(0);
  EXPECT_EQ(io.esi, esi_path("beckhoff-el-io.xml"));
  EXPECT_EQ(io.esi_device, "\"EL2008\" (product 0x07D83052, revision 0x00100000)");
  EXPECT_EQ(io.vendor_id, 2U);  // from the ESI
  EXPECT_EQ(io.product_code, 0x07D83052U);
}

TEST_F(EthercatEsi, RelativePathsStartAtTheConfigFile) {
  write("drive.xml", read("esr-triodrive.xml"));
  const Plan p = load_plan_from_string(config(esr_axis("drive.xml")), (dir_ / "cell.yaml").string(), options());
  EXPECT_EQ(p.buses.at(0).axes.at(0).section<EthercatAxisSpec>().esi, (dir_ / "drive.xml").string());
  EXPECT_REPORTED(test::errors_of(config(esr_axis("nope.xml")), options(), (dir_ / "cell.yaml").string()),
                  "axes[0].ethercat.esi: file \"" + (dir_ / "nope.xml").string() +
                      "\" does not exist (relative paths start at the config file's directory)");
}

TEST_F(EthercatEsi, ABrokenEsiIsReportedWithItsOwnLines) {
  write("esr.xml", "<EtherCATInfo>\n<Vendor><Id>x</Id></Vendor></EtherCATInfo>");
  const std::string e = test::errors_of(config(esr_axis((dir_ / "esr.xml").string())), options());
  EXPECT_REPORTED(e, (dir_ / "esr.xml").string() + ":2:1: Vendor/Id: must be a number (decimal or #x hex), got \"x\"");
  EXPECT_REPORTED(e, "axes[0].ethercat.esi: ESI \"" + (dir_ / "esr.xml").string() +
                         "\" has errors, listed with its file name");
}

TEST_F(EthercatEsi, TheDeviceMustBeOneOfTheProfilesIdentities) {
  EXPECT_REPORTED(
      test::errors_of(config(esr_axis(esi_path("beckhoff-el-io.xml"))), options()),
      "axes[0].ethercat.esi: ESI \"beckhoff-el-io.xml\" describes vendor 0x00000002: \"EL1004\" (product 0x03EC3052, "
      "revision 0x00100000), \"EL1004\" (product 0x03EC3052, revision 0x00110000), \"EL2008\" (product 0x07D83052, "
      "revision 0x00100000); none is an identity of device \"esr-triodrive\" (vendor 0x0000000F product 0x00006755, "
      "vendor 0x0000000F product 0x00001A63, vendor 0x0000000F product 0x00006745, vendor 0x0000000F product "
      "0x00001A59)");
  // The same product codes from another vendor are not the device either.
  EXPECT_REPORTED(esr_errors(replaced(read("esr-triodrive.xml"), "<Id>15</Id>", "<Id>16</Id>")),
                  "none is an identity of device \"esr-triodrive\"");
  // A profile without identities needs one product in the file, and a CiA 402 one.
  EXPECT_REPORTED(test::errors_of(config(generic_axis(esi_path("esr-triodrive.xml"))), options()),
                  "axes[0].ethercat.esi: ESI \"esr-triodrive.xml\" describes 2 products (vendor 0x0000000F: "
                  "\"TrioDrive D/ES\" (product 0x00006755, revision 0x00000001), \"MidiDrive D/ES\" (product "
                  "0x00006745, revision 0x00000001)); device \"generic-cia402\" lists no identity to choose one by "
                  "(give the profile identities)");
  write("io.xml", replaced(read("generic-cia402-dc.xml"), "<ProfileNo>402</ProfileNo>\n          <AddInfo>2</AddInfo>",
                           "<ProfileNo>5001</ProfileNo>"));
  EXPECT_REPORTED(test::errors_of(config(generic_axis((dir_ / "io.xml").string())), options()),
                  "axes[0].ethercat.esi: ESI \"io.xml\" describes \"XD-402\" (product 0x00001234, revision "
                  "0x00020000) with profile 5001, but device \"generic-cia402\" lists no identity and so takes CiA "
                  "402 drives only");
}

TEST_F(EthercatEsi, MappedObjectsMustBeInTheDictionaryMappableAndOfTheirSize) {
  const std::string esr = read("esr-triodrive.xml");
  EXPECT_REPORTED(esr_errors(replaced(esr, R"(<Object><Index>#x6073</Index><Name>Max current</Name><Type>UINT</Type><BitSize>16</BitSize><Flags><Access>rw</Access><PdoMapping>R</PdoMapping></Flags></Object>)", "")),
                  "axes[0].ethercat.esi: device \"esr-triodrive\" maps 6073h in 1600h, which ESI \"esr.xml\" does not list");
  EXPECT_REPORTED(esr_errors(replaced(esr, R"(<Name>Modes of operation</Name><Type>INT</Type><BitSize>16</BitSize>)",
                                      R"(<Name>Modes of operation</Name><Type>SINT</Type><BitSize>8</BitSize>)")),
                  "axes[0].ethercat.esi: device \"esr-triodrive\" maps 6060h in 1600h, as i16 (16 bits); ESI \"esr.xml\" "
                  "has SINT (8 bits, line 77)");
  EXPECT_REPORTED(esr_errors(replaced(esr, R"(<Name>Target torque</Name><Type>INT</Type><BitSize>16</BitSize><Flags><Access>rw</Access><PdoMapping>R</PdoMapping>)",
                                      R"(<Name>Target torque</Name><Type>INT</Type><BitSize>16</BitSize><Flags><Access>rw</Access>)")),
                  "axes[0].ethercat.esi: device \"esr-triodrive\" maps 6071h in 1600h, which ESI \"esr.xml\" does not "
                  "let map into an RxPDO (PdoMapping none, line 82)");
  EXPECT_REPORTED(esr_errors(replaced(esr, R"(<Name>Position actual internal value</Name><Type>DINT</Type><BitSize>32</BitSize><Flags><Access>ro</Access><PdoMapping>T</PdoMapping>)",
                                      R"(<Name>Position actual internal value</Name><Type>DINT</Type><BitSize>32</BitSize><Flags><Access>ro</Access><PdoMapping>R</PdoMapping>)")),
                  "axes[0].ethercat.esi: device \"esr-triodrive\" maps 6063h in 1A00h, which ESI \"esr.xml\" does not "
                  "let map into a TxPDO (PdoMapping R, line 79)");
  // An object the ESI maps into a TxPDO itself is mappable that way without PdoMapping.
  const std::string e = esr_errors(replaced(esr, R"(<Name>Position actual value</Name><Type>DINT</Type><BitSize>32</BitSize><Flags><Access>ro</Access><PdoMapping>T</PdoMapping>)",
                                            R"(<Name>Position actual value</Name><Type>DINT</Type><BitSize>32</BitSize><Flags><Access>ro</Access>)"));
  EXPECT_EQ(e, "(loaded without error)");
}

TEST_F(EthercatEsi, WithoutADictionaryTheEsisPdosGiveTheSizes) {
  // The MidiDrive has no dictionary and no PDOs: nothing to check against.
  const std::string midi_first =
      replaced(read("esr-triodrive.xml"), R"(<Type ProductCode="#x00006755" RevisionNo="1">)",
               R"(<Type ProductCode="#x00009999" RevisionNo="1">)");
  EXPECT_EQ(esr_errors(midi_first), "(loaded without error)");
  // The TrioDrive without its dictionary: 6040h is 16 bits in the ESI's 1600h.
  std::string no_dictionary = read("esr-triodrive.xml");
  const auto from = no_dictionary.find("<Dictionary>");
  const auto to = no_dictionary.find("</Dictionary>") + std::string{"</Dictionary>"}.size();
  no_dictionary.erase(from, to - from);
  EXPECT_EQ(esr_errors(no_dictionary), "(loaded without error)");
  EXPECT_REPORTED(esr_errors(replaced(no_dictionary, "<BitLen>16</BitLen><Name>Controlword</Name>",
                                      "<BitLen>32</BitLen><Name>Controlword</Name>")),
                  "axes[0].ethercat.esi: device \"esr-triodrive\" maps 6040h in 1600h, as u16 (16 bits); ESI "
                  "\"esr.xml\" maps it with 32 bits (line 37)");  // 70 dictionary lines fewer
}

TEST_F(EthercatEsi, FixedPdosMustBeThoseOfTheProfile) {
  EXPECT_REPORTED(esr_errors(replaced(read("esr-triodrive.xml"), "<RxPdo Sm=\"2\">", "<RxPdo Sm=\"2\" Fixed=\"1\">")),
                  "axes[0].ethercat.esi: device \"esr-triodrive\" maps 1600h as 6040h (16 bits), 6060h (16 bits), "
                  "607Ah (32 bits), 6081h (32 bits), 60C1h:1 (32 bits), 6071h (16 bits), 6073h (16 bits); ESI "
                  "\"esr.xml\" lists 1600h as fixed (line 104) with 6040h (16 bits), 607Ah (32 bits)");
  // A fixed PDO equal to the profile's is fine.
  std::string same = replaced(read("generic-cia402-dc.xml"), "<TxPdo Sm=\"3\" Mandatory=\"true\">",
                              "<TxPdo Sm=\"3\" Mandatory=\"true\" Fixed=\"true\">");
  write("dc.xml", same);
  EXPECT_EQ(test::errors_of(config(generic_axis((dir_ / "dc.xml").string())), options()), "(loaded without error)");
}

TEST_F(EthercatEsi, StartupWritesMustNameWritableObjectsOfTheirSize) {
  const std::string esr = read("esr-triodrive.xml");
  const std::string w = R"(<Name>Abort connection option code</Name><Type>INT</Type><BitSize>16</BitSize><Info><DefaultData>0000</DefaultData></Info><Flags><Access>rw</Access>)";
  EXPECT_REPORTED(esr_errors(replaced(esr, w, replaced(w, "<Access>rw</Access>", "<Access>ro</Access>"))),
                  "axes[0].ethercat.esi: device \"esr-triodrive\" start-up write of 6007h names an object that is ro "
                  "in ESI \"esr.xml\" (line 74)");
  EXPECT_REPORTED(esr_errors(replaced(esr, w, replaced(w, "<Type>INT</Type><BitSize>16</BitSize>", "<Type>DINT</Type><BitSize>32</BitSize>"))),
                  "axes[0].ethercat.esi: device \"esr-triodrive\" start-up write of 6007h writes i16 (16 bits); ESI "
                  "\"esr.xml\" has DINT (32 bits, line 74)");
  EXPECT_REPORTED(esr_errors(replaced(esr, "<Index>#x6007</Index>", "<Index>#x6008</Index>")),
                  "axes[0].ethercat.esi: device \"esr-triodrive\" start-up write of 6007h names an object ESI "
                  "\"esr.xml\" does not list");
}

TEST_F(EthercatEsi, TheSecondAxisOfASlaveIsCheckedAtItsOffsetObjects) {
  // A two-axis variant of the generic profile: axis 1's objects are 800h higher (ETG.6010).
  write("two-axis.yaml", R"(name: two-axis
vendor: test
description: two axes on one slave
modes: [csp]
units:
  position: { per_rev: counts }
  velocity: { unit: position_per_s }
  acceleration: { unit: position_per_s2 }
  torque: { per_rated: 1000 }
ethercat:
  axes: 2
  rxpdos:
    - { index: 0x1600, map: ["0x6040 u16", "0x607A i32"] }
    - { index: 0x1601, map: ["0x6840 u16", "0x687A i32"] }
  txpdos:
    - { index: 0x1A00, map: ["0x6041 u16", "0x6064 i32"] }
    - { index: 0x1A01, map: ["0x6841 u16", "0x6864 i32"] }
)");
  LoadOptions o = options();
  o.device_dirs.push_back(dir_);
  const std::string two = "  - { name: a, bus: ec0, address: 1, device: two-axis, mechanics: { encoder_counts_per_rev: 4096 }, "
                          "ethercat: { axis: 1, esi: \"" + esi_path("generic-cia402-dc.xml") + "\" } }\n";
  const std::string e = test::errors_of(config(two), o);
  // The profile's entries as the slave numbers them: axis 1's in 1601h/1A01h, axis 0's not offset.
  EXPECT_REPORTED(e, "axes[0].ethercat.esi: device \"two-axis\" maps 6840h in 1601h, which ESI \"generic-cia402-dc.xml\" does not list");
  EXPECT_REPORTED(e, "axes[0].ethercat.esi: device \"two-axis\" maps 6864h in 1A01h, which ESI \"generic-cia402-dc.xml\" does not list");
  EXPECT_EQ(e.find("maps 6840h in 1600h"), std::string::npos) << e;
}

TEST_F(EthercatEsi, IoSlavesAreCheckedAgainstTheirEsi) {
  const std::string beckhoff = esi_path("beckhoff-el-io.xml");
  const auto errors = [&](const std::string& io) {
    return test::errors_of(config(generic_axis(esi_path("generic-cia402-dc.xml")), "      - " + io + "\n"), options());
  };
  EXPECT_EQ(errors("{ name: in, position: 3, product_code: 0x03EC3052, inputs: 1, esi: \"" + beckhoff + "\" }"),
            "(loaded without error)");
  EXPECT_REPORTED(errors("{ name: in, position: 3, vendor_id: 3, esi: \"" + beckhoff + "\" }"),
                  "buses[0].io[0].esi: I/O slave \"in\" has vendor_id 0x00000003; ESI \"beckhoff-el-io.xml\" describes "
                  "vendor 0x00000002: \"EL1004\"");
  EXPECT_REPORTED(errors("{ name: in, position: 3, product_code: 0x03EC3053, esi: \"" + beckhoff + "\" }"),
                  "buses[0].io[0].esi: I/O slave \"in\" has product_code 0x03EC3053; ESI \"beckhoff-el-io.xml\" "
                  "describes vendor 0x00000002: \"EL1004\"");
  EXPECT_REPORTED(errors("{ name: in, position: 3, esi: \"" + beckhoff + "\" }"),
                  "buses[0].io[0].esi: ESI \"beckhoff-el-io.xml\" describes 2 products (vendor 0x00000002: \"EL1004\" "
                  "(product 0x03EC3052, revision 0x00100000), \"EL1004\" (product 0x03EC3052, revision 0x00110000), "
                  "\"EL2008\" (product 0x07D83052, revision 0x00100000)); give I/O slave \"in\" the product_code of one");
  EXPECT_REPORTED(errors("{ name: in, position: 3, product_code: 0x03EC3052, inputs: 2, outputs: 1, esi: \"" + beckhoff + "\" }"),
                  "buses[0].io[0].inputs: I/O slave \"in\" has 2 bytes of inputs, but ESI \"beckhoff-el-io.xml\" "
                  "assigns 1 byte of TxPDOs by default (1A00h, 1A01h, 1A02h, 1A03h) to \"EL1004\" (product 0x03EC3052, "
                  "revision 0x00110000)");
  EXPECT_REPORTED(errors("{ name: in, position: 3, product_code: 0x03EC3052, inputs: 2, outputs: 1, esi: \"" + beckhoff + "\" }"),
                  "buses[0].io[0].outputs: I/O slave \"in\" has 1 byte of outputs, but ESI \"beckhoff-el-io.xml\" "
                  "assigns 0 bytes of RxPDOs by default to \"EL1004\" (product 0x03EC3052, revision 0x00110000)");
}

TEST_F(EthercatEsi, ParameterNamesResolveThroughTheEsi) {
  const Plan p = load_plan_from_string(
      config(esr_axis(esi_path("esr-triodrive.xml")) +
             "  - { name: z, bus: ec0, address: 3, device: esr-triodrive, mechanics: { encoder_counts_per_rev: 4096 }, "
             "defaults: { mode: ip } }\n"),
      "t.yaml", options());
  const AxisPlan& x = p.buses.at(0).axes.at(0);
  const auto find = [&](const AxisPlan& a, std::string_view name, cia402::ObjectId id = {}) {
    return find_ethercat_parameter(a, name, id);
  };
  ParameterRef r = find(x, "controlword");
  EXPECT_EQ(r.id, (cia402::ObjectId{0x6040, 0}));
  EXPECT_EQ(r.type, core::ParamType::U16);
  EXPECT_EQ(r.type_source, "the ESI");
  EXPECT_EQ(r.error, "");
  r = find(x, "Identity:Vendor ID");
  EXPECT_EQ(r.id, (cia402::ObjectId{0x1018, 1}));
  EXPECT_EQ(r.type, core::ParamType::U32);
  r = find(x, "interpolation data record : interpolation target");
  EXPECT_EQ(r.id, (cia402::ObjectId{0x60C1, 1}));
  EXPECT_EQ(r.type, core::ParamType::I32);
  // By object: the ESI's type (6081h is UDINT there though the profile maps it as i32).
  r = find(x, "", {0x6081, 0});
  EXPECT_EQ(r.id, (cia402::ObjectId{0x6081, 0}));
  EXPECT_EQ(r.type, core::ParamType::U32);
  EXPECT_EQ(r.type_source, "the ESI");
  r = find(x, "", {0x2000, 5});
  EXPECT_EQ(r.id, (cia402::ObjectId{0x2000, 5}));
  EXPECT_EQ(r.type, core::ParamType::Unknown);
  EXPECT_EQ(r.type_source, "");
  r = find(x, "Max torque");
  EXPECT_FALSE(r.id.has_value());
  EXPECT_EQ(r.error, "axis 'x' has no object named 'Max torque' in its ESI (a sub-item is named OBJECT:SUB)");
  // Without an ESI: no names; types from the device profile.
  const AxisPlan& z = p.buses.at(0).axes.at(1);
  r = find(z, "controlword");
  EXPECT_EQ(r.error, "axis 'z' has no object named 'controlword' (give the axis an ESI file to use names, or use INDEX:SUB)");
  r = find(z, "", {0x6060, 0});
  EXPECT_EQ(r.type, core::ParamType::I16);
  EXPECT_EQ(r.type_source, "device profile esr-triodrive");
  r = find(z, "", {0x6007, 0});
  EXPECT_EQ(r.type, core::ParamType::I16);  // from the start-up write
  // The bus type resolves parameters this way.
  ASSERT_TRUE(p.buses.at(0).type_info && p.buses.at(0).type_info->find_parameter);
  EXPECT_EQ(p.buses.at(0).type_info->find_parameter(x, "Statusword", {}).id, (cia402::ObjectId{0x6041, 0}));
}

TEST_F(EthercatEsi, AmbiguousNamesAskForTheObject) {
  write("dup.xml", replaced(read("esr-triodrive.xml"), "<Name>Max current</Name>", "<Name>Controlword</Name>"));
  const Plan p = load_plan_from_string(config(esr_axis((dir_ / "dup.xml").string())), "t.yaml", options());
  const ParameterRef r = find_ethercat_parameter(p.buses.at(0).axes.at(0), "CONTROLWORD", {});
  EXPECT_FALSE(r.id.has_value());
  EXPECT_EQ(r.error, "'CONTROLWORD' names 2 objects in the ESI of axis 'x' (6040:0, 6073:0); use INDEX:SUB");
}

TEST_F(EthercatEsi, TheEsiKeyIsKnown) {
  EXPECT_REPORTED(test::errors_of(config("  - { name: x, bus: ec0, address: 1, device: esr-triodrive, mechanics: { "
                                         "encoder_counts_per_rev: 4096 }, ethercat: { eds: a.eds } }\n"),
                                  options()),
                  "axes[0].ethercat.eds: unknown field (allowed: axis, esi)");
  EXPECT_REPORTED(test::errors_of(config(generic_axis(esi_path("generic-cia402-dc.xml")),
                                         "      - { name: in, position: 3, file: x }\n"),
                                  options()),
                  "buses[0].io[0].file: unknown field (allowed: name, position, vendor_id, product_code, inputs, outputs, esi)");
}

}  // namespace
}  // namespace drivegate::config
