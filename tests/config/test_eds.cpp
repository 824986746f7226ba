// CiA 306 EDS parsing: objects, sub-indices, lookups, and every malformed line reported with its
// line number.
#include <gtest/gtest.h>

#include "config/eds.hpp"
#include "tests/config/test_support.hpp"

namespace drivegate::config {
namespace {

std::string errors_of(const std::string& text) {
  Problems problems;
  const auto objects = parse_eds_text(text, "x.eds", problems);
  EXPECT_EQ(objects.has_value(), !problems.has_errors());
  std::string out;
  for (const auto& d : problems.errors()) out += d.to_string() + "\n";
  return out;
}

TEST(Eds, IntegerTypesOfParameterRequests) {
  EXPECT_EQ(eds_integer_type(0x0001), cia402::DataType::U8);  // BOOLEAN travels as a byte
  EXPECT_EQ(eds_integer_type(0x0002), cia402::DataType::I8);
  EXPECT_EQ(eds_integer_type(0x0003), cia402::DataType::I16);
  EXPECT_EQ(eds_integer_type(0x0004), cia402::DataType::I32);
  EXPECT_EQ(eds_integer_type(0x0005), cia402::DataType::U8);
  EXPECT_EQ(eds_integer_type(0x0006), cia402::DataType::U16);
  EXPECT_EQ(eds_integer_type(0x0007), cia402::DataType::U32);
  EXPECT_FALSE(eds_integer_type(0x0008));  // REAL32: 4 bytes, but not an integer
  EXPECT_FALSE(eds_integer_type(0x0010));  // INTEGER24
  EXPECT_FALSE(eds_integer_type(0x0015));  // INTEGER64
}

TEST(Eds, TheTestFileParses) {
  Problems problems;
  const auto objects = parse_eds(DRIVEGATE_TEST_DEVICE_DIR "/akd-canopen.eds", problems);
  ASSERT_TRUE(objects) << problems.errors().front().to_string();
  // VARs and the sub-indices of arrays/records; the ARRAY/RECORD headers themselves are not entries.
  EXPECT_EQ(find_eds_object(*objects, cia402::ObjectId{0x608F, 0})->name, "Highest sub-index supported");
  const EdsObject* cw = find_eds_object(*objects, cia402::ObjectId{0x6040, 0});
  ASSERT_NE(cw, nullptr);
  EXPECT_EQ(cw->name, "Controlword");
  EXPECT_EQ(cw->data_type, 0x0006);
  EXPECT_EQ(cw->access, EdsAccess::ReadWriteWrite);
  EXPECT_TRUE(cw->pdo_mapping);
  EXPECT_TRUE(cw->writable());
  const EdsObject* ip = find_eds_object(*objects, cia402::ObjectId{0x60C1, 1});
  ASSERT_NE(ip, nullptr);
  EXPECT_EQ(ip->parent, "Interpolation data record");
  EXPECT_EQ(eds_type_bits(ip->data_type), 32);
  EXPECT_FALSE(find_eds_object(*objects, cia402::ObjectId{0x6099, 1}));
  EXPECT_TRUE(std::is_sorted(objects->begin(), objects->end(),
                             [](const EdsObject& a, const EdsObject& b) { return a.id.key() < b.id.key(); }));
}

TEST(Eds, EntriesAndAttributes) {
  Problems problems;
  const auto objects = parse_eds_text(R"(; comment
[FileInfo]
FileName=x.eds

[1018]
ParameterName=Identity object
ObjectType=0x9
SubNumber=2

[1018sub0]
ParameterName=Highest sub-index supported
ObjectType=0x7
DataType=0x0005
AccessType=ro
DefaultValue=1
PDOMapping=0

[1018SUB1]
parametername=Vendor-ID
DATATYPE=7
accesstype=RO
DefaultValue=0x6A

[1008]
ParameterName=Manufacturer device name
DataType=0x0009
AccessType=const

[6060]
ParameterName=Modes of operation
ObjectType=0x7
DataType=0x0002
AccessType=rww
PDOMapping=1
LowLimit=-3
HighLimit=0x0A

[1400sub1]
ParameterName=COB-ID used by RPDO
DataType=0x0007
AccessType=rw
LowLimit=$NODEID+0x200
[1400]
ParameterName=RPDO communication parameter
ObjectType=0x9
)",
                                      "x.eds", problems);
  ASSERT_TRUE(objects) << problems.errors().front().to_string();
  ASSERT_EQ(objects->size(), 5U);
  const EdsObject* vendor = find_eds_object(*objects, cia402::ObjectId{0x1018, 1});
  ASSERT_NE(vendor, nullptr);
  EXPECT_EQ(vendor->name, "Vendor-ID");
  EXPECT_EQ(vendor->data_type, 0x0007);
  EXPECT_EQ(eds_integer_type(vendor->data_type), cia402::DataType::U32);
  EXPECT_EQ(vendor->access, EdsAccess::ReadOnly);  // keys and access values are case-insensitive
  EXPECT_FALSE(vendor->pdo_mapping);               // PDOMapping left out: not mappable
  EXPECT_EQ(vendor->default_value, "0x6A");
  EXPECT_EQ(vendor->line, 18);
  const EdsObject* name = find_eds_object(*objects, cia402::ObjectId{0x1008, 0});
  ASSERT_NE(name, nullptr);  // ObjectType left out: a VAR
  EXPECT_EQ(eds_type_name(name->data_type), "VISIBLE_STRING");
  EXPECT_FALSE(eds_type_bits(name->data_type));
  EXPECT_FALSE(eds_integer_type(name->data_type));  // no parameter request carries a string
  EXPECT_FALSE(name->writable());
  const EdsObject* mode = find_eds_object(*objects, cia402::ObjectId{0x6060, 0});
  ASSERT_NE(mode, nullptr);
  EXPECT_EQ(mode->low_limit, -3);
  EXPECT_EQ(mode->high_limit, 10);
  // A limit relative to the node-ID is kept out of the numeric limits.
  EXPECT_FALSE(find_eds_object(*objects, cia402::ObjectId{0x1400, 1})->low_limit);
}

TEST(Eds, LookupByNameIsCaseInsensitiveAndUnique) {
  Problems problems;
  const auto objects = parse_eds(DRIVEGATE_TEST_DEVICE_DIR "/akd-canopen.eds", problems);
  ASSERT_TRUE(objects);
  const EdsObject* sw = find_eds_object(*objects, "statusWORD");
  ASSERT_NE(sw, nullptr);
  EXPECT_EQ(sw->id, (cia402::ObjectId{0x6041, 0}));
  // "Shaft revolutions" is a sub-index of both 6091h and 6092h: ambiguous alone, unique with its parent.
  EXPECT_EQ(find_eds_object(*objects, "Shaft revolutions"), nullptr);
  const EdsObject* feed = find_eds_object(*objects, "feed constant.shaft revolutions");
  ASSERT_NE(feed, nullptr);
  EXPECT_EQ(feed->id, (cia402::ObjectId{0x6092, 2}));
  EXPECT_EQ(find_eds_object(*objects, "no such object"), nullptr);
  EXPECT_EQ(find_eds_object(*objects, "Gear ratio.Feed"), nullptr);
}

TEST(Eds, EveryProblemHasItsLine) {
  const std::string e = errors_of(R"(Junk before any section
[6040]
ParameterName=Controlword
DataType=0x0006
AccessType=rw
PDOMapping=1
DataType=0x0007
[6041]
ParameterName=Statusword
DataType=0x0042
AccessType=readonly
PDOMapping=yes
[6041]
[6042sub1]
ParameterName=Orphan
DataType=0x0003
AccessType=rw
[6043]
ObjectType=0x3
[6044
[6045subZZ]
[6046]
DataType=0x0006
AccessType=ro
no equals sign here
LowLimit=10
HighLimit=5
[6047]
ParameterName=Broken limit
DataType=0x0006
AccessType=rw
HighLimit=lots
)");
  EXPECT_REPORTED(e, "x.eds:1:1: text before the first section: \"Junk before any section\"");
  EXPECT_REPORTED(e, "x.eds:7:1: [6040].DataType: given twice (first at line 4)");
  EXPECT_REPORTED(e, "x.eds:10:1: [6041].DataType: must be a CiA 301 data type such as 0x0007 (UNSIGNED32)");
  EXPECT_REPORTED(e, "x.eds:11:1: [6041].AccessType: must be one of ro, wo, rw, rwr, rww, const, got \"readonly\"");
  EXPECT_REPORTED(e, "x.eds:12:1: [6041].PDOMapping: must be 0 or 1, got \"yes\"");
  EXPECT_REPORTED(e, "x.eds:13:1: [6041]: section given twice (first at line 8)");
  EXPECT_REPORTED(e, "x.eds:14:1: [6042sub1]: sub-index without its object: there is no [6042] section");
  EXPECT_REPORTED(e, "x.eds:19:1: [6043].ObjectType: must be 0x7 (VAR), 0x8 (ARRAY), 0x9 (RECORD)");
  EXPECT_REPORTED(e, "x.eds:20:1: section header must end with ']', got \"[6044\"");
  EXPECT_REPORTED(e, "x.eds:21:1: [6045subZZ]: sub-index must be hex 0..FF");
  EXPECT_REPORTED(e, "x.eds:22:1: [6046]: missing ParameterName");
  EXPECT_REPORTED(e, "x.eds:25:1: [6046]: expected KEY=VALUE, got \"no equals sign here\"");
  EXPECT_REPORTED(e, "x.eds:26:1: [6046].LowLimit: must not exceed HighLimit (5), got 10");
  EXPECT_REPORTED(e, "x.eds:32:1: [6047].HighLimit: must be an integer (decimal or 0x hex), got \"lots\"");
}

TEST(Eds, MissingAttributesOfAVar) {
  const std::string e = errors_of("[6040]\nParameterName=Controlword\n");
  EXPECT_REPORTED(e, "x.eds:1:1: [6040]: missing DataType");
  EXPECT_REPORTED(e, "x.eds:1:1: [6040]: missing AccessType");
}

TEST(Eds, UnreadableFile) {
  Problems problems;
  EXPECT_FALSE(parse_eds("/nonexistent/drive.eds", problems));
  ASSERT_EQ(problems.errors().size(), 1U);
  EXPECT_NE(problems.errors()[0].to_string().find("/nonexistent/drive.eds: cannot open file"), std::string::npos);
}

TEST(Eds, BinaryGarbageIsReportedNotFatal) {
  std::string junk = "[6040]\n";
  for (int i = 0; i < 256; ++i) junk += static_cast<char>(i);
  junk += "\n[\n]\n=\n[]\n[sub]\n[0000sub]\n";
  Problems problems;
  EXPECT_FALSE(parse_eds_text(junk, "junk.eds", problems));
  EXPECT_TRUE(problems.has_errors());
}

}  // namespace
}  // namespace drivegate::config
