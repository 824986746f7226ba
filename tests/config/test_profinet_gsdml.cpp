// GSDML files: the reader on tests/config/gsdml/drivegate-test-io.xml (a small file written for
// these tests) and broken variants with their exact messages.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "config/profinet/gsdml.hpp"
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

}  // namespace
}  // namespace drivegate::config
