// GSDML files: the reader on tests/config/gsdml/drivegate-test-io.xml (a small file written for
// these tests), broken variants with their exact messages, and `gsdml:` of an IO device entry.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "config/profinet/gsdml.hpp"
#include "config/profinet/plan.hpp"
#include "tests/config/test_support.hpp"

namespace drivegate::config {
namespace {

const std::string kDir = DRIVEGATE_TEST_GSDML_DIR;
const std::string kFile = kDir + "/drivegate-test-io.xml";

std::string read(const std::string& file) {
  std::ifstream in(file);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// `text` with `from` replaced by `to` (which must be there).
std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

// The errors of reading `text` as g.xml, one a line.
std::string errors_of_gsdml(const std::string& text) {
  Problems problems;
  const auto file = load_gsdml_text(text, "g.xml", problems);
  EXPECT_FALSE(file.has_value());
  std::string out;
  for (const auto& d : problems.errors()) out += d.to_string() + "\n";
  return out;
}

TEST(ProfinetGsdml, ReadsIdentityDapModulesAndIoLengths) {
  Problems problems;
  const auto f = load_gsdml(kFile, problems);
  ASSERT_TRUE(f.has_value());
  EXPECT_FALSE(problems.has_errors());
  EXPECT_EQ(f->vendor_id, 0x0FEEU);
  EXPECT_EQ(f->device_id, 0x0042U);
  ASSERT_EQ(f->daps.size(), 1U);
  EXPECT_EQ(f->daps[0].id, "DAP_1");
  EXPECT_EQ(f->daps[0].ident, 0x100U);
  ASSERT_EQ(f->modules.size(), 3U);
  const GsdmlModule* di = find_gsdml_module(f->modules, "DI_16");
  ASSERT_NE(di, nullptr);
  EXPECT_EQ(di->ident, 0x210U);
  ASSERT_EQ(di->submodules.size(), 1U);
  EXPECT_EQ(di->submodules[0].ident, 0x11U);
  EXPECT_EQ(di->submodules[0].input_bytes, 2);
  EXPECT_EQ(di->submodules[0].output_bytes, 0);
  const GsdmlModule* aio = find_gsdml_module(f->modules, "AIO_2");
  ASSERT_NE(aio, nullptr);
  ASSERT_EQ(aio->submodules.size(), 2U);
  EXPECT_EQ(aio->submodules[0].input_bytes, 7);  // 2 x Integer16 + OctetString of 3
  EXPECT_EQ(aio->submodules[1].output_bytes, 8);  // 2 x Float32
  EXPECT_EQ(aio->submodules[1].fixed_subslot, 2);
  EXPECT_EQ(find_gsdml_module(f->modules, "DI_32"), nullptr);
}

TEST(ProfinetGsdml, BrokenFilesAreRefusedWithTheirLines) {
  const std::string good = read(kFile);
  EXPECT_EQ(errors_of_gsdml("<ISO15745Profile><ProfileBody>"), "g.xml:1:1: not well-formed XML (mismatched element)\n");
  EXPECT_EQ(errors_of_gsdml("<EtherCATInfo/>"),
            "g.xml:1:1: the root element is <EtherCATInfo>, not <ISO15745Profile>: this is not a GSDML file\n");
  EXPECT_EQ(errors_of_gsdml(replaced(good, R"(ModuleItem ID="DO_8" ModuleIdentNumber="0x00000220")", R"(ModuleItem ID="DO_8")")),
            "g.xml:54:1: ModuleList/ModuleItem[2]: has no ModuleIdentNumber\n");
  EXPECT_EQ(errors_of_gsdml(replaced(good, R"(SubmoduleIdentNumber="0x00000011")", "")),
            "g.xml:46:1: ModuleList/ModuleItem[1]/VirtualSubmoduleList/VirtualSubmoduleItem[1]: has no SubmoduleIdentNumber\n");
  EXPECT_EQ(errors_of_gsdml(replaced(good, R"(VendorID="0x0FEE")", R"(VendorID="0x10000")")),
            "g.xml:18:1: ProfileBody/DeviceIdentity: VendorID must be a number in 0..65535 (decimal or 0x hex), got \"0x10000\"\n");
  EXPECT_EQ(errors_of_gsdml(replaced(good, R"(DataType="OctetString" Length="3")", R"(DataType="OctetString" Length="2000")")),
            "g.xml:73:1: ModuleList/ModuleItem[3]/VirtualSubmoduleList/VirtualSubmoduleItem[1]/IOData/Input/DataItem[3]: "
            "Length must be a number in 0..1440 (decimal or 0x hex), got \"2000\"\n");
  EXPECT_EQ(errors_of_gsdml(replaced(good, R"(DataType="OctetString" Length="3")", R"(DataType="OctetString")")),
            "g.xml:73:1: ModuleList/ModuleItem[3]/VirtualSubmoduleList/VirtualSubmoduleItem[1]/IOData/Input/DataItem[3]: "
            "has no Length\n");
  EXPECT_EQ(errors_of_gsdml(replaced(good, R"(DataType="Float32" TextId="T_Ao1")", R"(DataType="Float128" TextId="T_Ao1")")),
            "g.xml:81:1: ModuleList/ModuleItem[3]/VirtualSubmoduleList/VirtualSubmoduleItem[2]/IOData/Output/DataItem[1]: "
            "DataType \"Float128\" is not a GSDML data type with a known size\n");
  // Items that each fit but together pass what one frame carries.
  std::string big = good;
  for (int i = 0; i < 2; ++i)
    big = replaced(big, R"(<DataItem DataType="Integer16" TextId="T_Ai)" + std::to_string(i + 1) + R"("/>)",
                   R"(<DataItem DataType="OctetString" Length="1000" TextId="T_Big"/>)");
  EXPECT_EQ(errors_of_gsdml(big),
            "g.xml:72:1: ModuleList/ModuleItem[3]/VirtualSubmoduleList/VirtualSubmoduleItem[1]/IOData/Input/DataItem[2]: "
            "the data reach 2000 octets, more than the 1440 one frame can carry\n");
  const std::string no_dap = replaced(replaced(good, "<DeviceAccessPointItem ID", "<DeviceAccessPointItemX ID"),
                                      "</DeviceAccessPointItem>", "</DeviceAccessPointItemX>");
  EXPECT_EQ(errors_of_gsdml(no_dap),
            "g.xml:26:1: ProfileBody/ApplicationProcess/DeviceAccessPointList: lists no DeviceAccessPointItem\n");
}

TEST(ProfinetGsdml, AMissingFileIsReported) {
  Problems problems;
  EXPECT_FALSE(load_gsdml(kDir + "/nope.xml", problems).has_value());
  ASSERT_EQ(problems.errors().size(), 1U);
  EXPECT_NE(problems.errors()[0].to_string().find("nope.xml"), std::string::npos) << problems.errors()[0].to_string();
}

class ProfinetGsdmlConfig : public test::TempDir {
 protected:
  std::string config(const std::string& io) const {
    return R"(gateway: { name: cell }
buses:
  - name: pn0
    type: profinet
    cycle_time: 1ms
    options: { interface: eth1 }
    devices:
      - { station: io-block, ip: 192.168.0.20 }
    io:
)" + io;
  }
};

TEST_F(ProfinetGsdmlConfig, IoDevicesTakeIdentsAndLengthsFromTheGsdml) {
  const auto file = write("cell.yaml", config("      - { name: panel, station: io-block, gsdml: " + kFile +
                                              ", slots: [{ slot: 1, module: AIO_2 }, { slot: 3, module: DO_8 }] }\n"));
  const Plan p = load_plan(file.string(), test::test_options());
  const auto& io = p.buses[0].section<ProfinetBusOptions>().io.at(0);
  EXPECT_EQ(io.dap_ident, 0x100U);
  EXPECT_EQ(io.gsdml, kFile);
  ASSERT_EQ(io.submodules.size(), 3U);
  EXPECT_EQ(io.submodules[0].slot, 1);
  EXPECT_EQ(io.submodules[0].subslot, 1);
  EXPECT_EQ(io.submodules[0].module_ident, 0x230U);
  EXPECT_EQ(io.submodules[0].submodule_ident, 0x21U);
  EXPECT_EQ(io.submodules[0].input_bytes, 7);
  EXPECT_EQ(io.submodules[1].subslot, 2);
  EXPECT_EQ(io.submodules[1].output_bytes, 8);
  EXPECT_EQ(io.submodules[2].slot, 3);
  EXPECT_EQ(io.submodules[2].gsdml_id, "DO_8");
}

TEST_F(ProfinetGsdmlConfig, GsdmlProblemsAreReported) {
  write("broken.xml", "<ISO15745Profile>\n<ProfileBody>\n");
  const auto file = write("cell.yaml", config(
      "      - { name: a, station: io-block, gsdml: broken.xml, slots: [{ slot: 1, module_ident: 1, submodule_ident: 1 }] }\n"
      "      - { name: b, station: io-block, gsdml: missing.xml, slots: [{ slot: 1, module_ident: 1, submodule_ident: 1 }] }\n"
      "      - { name: c, station: io-block, gsdml: " + kFile + ", dap: DAP_2, slots: [{ slot: 1, module: DI_61 }] }\n"
      "      - { name: d, station: io-block, gsdml: " + kFile + ", dap_ident: 1, slots: [{ slot: 1, module: DI_16, inputs: 2 }] }\n"));
  const std::string e = test::errors_of(read(file.string()), test::test_options(), file.string());
  EXPECT_REPORTED(e, (dir_ / "broken.xml").string() + ":2:1: not well-formed XML (parsing)");
  EXPECT_REPORTED(e, "buses[0].io[0].gsdml: GSDML \"" + (dir_ / "broken.xml").string() + "\" has errors, listed with its file name");
  EXPECT_REPORTED(e, "buses[0].io[1].gsdml: file \"" + (dir_ / "missing.xml").string() +
                         "\" does not exist (relative paths start at the config file's directory)");
  EXPECT_REPORTED(e, "buses[0].io[2].dap: the GSDML lists no device access point \"DAP_2\" (DAPs: DAP_1)");
  EXPECT_REPORTED(e, "buses[0].io[2].slots[0].module: the GSDML lists no module \"DI_61\", did you mean \"DI_16\"? "
                     "(modules: DI_16, DO_8, AIO_2)");
  EXPECT_REPORTED(e, "buses[0].io[3].dap_ident: comes from the GSDML's DAP; give dap to choose one");
  EXPECT_REPORTED(e, "buses[0].io[3].slots[0].inputs: comes from the GSDML module; give either module or the idents and lengths");
}

}  // namespace
}  // namespace drivegate::config
