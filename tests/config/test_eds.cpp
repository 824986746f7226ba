// CiA 306 EDS parsing: objects, sub-indices, lookups, the number forms, data types, limits and
// CompactSubObj arrays CiA 306 allows, and the deviations of files in the wild, each a warning with
// its file, line and key. The files under tests/config/eds/ are the corpus (also fuzz/corpus/eds).
#include <gtest/gtest.h>

#include <fstream>
#include <limits>
#include <sstream>

#include "config/canopen/eds.hpp"
#include "core/param_value.hpp"
#include "tests/config/test_support.hpp"

namespace drivegate::config {
namespace {

// The objects of load_eds / load_eds_text; nullopt when the file has errors.
std::optional<std::vector<EdsObject>> objects_of_file(const std::string& file, Problems& problems) {
  auto eds = load_eds(file, problems);
  if (!eds) return std::nullopt;
  return std::move(eds->objects);
}

std::optional<std::vector<EdsObject>> objects_of_text(std::string_view text, const std::string& label,
                                                      Problems& problems) {
  auto eds = load_eds_text(text, label, problems);
  if (!eds) return std::nullopt;
  return std::move(eds->objects);
}

// Errors and warnings of parsing `text` as x.eds, one per line.
struct Report {
  std::optional<std::vector<EdsObject>> objects;
  std::string errors;
  std::string warnings;
};

Report report_of(const std::string& text) {
  Problems problems;
  Report r;
  r.objects = objects_of_text(text, "x.eds", problems);
  EXPECT_EQ(r.objects.has_value(), !problems.has_errors());
  for (const auto& d : problems.errors()) r.errors += d.to_string() + "\n";
  for (const auto& d : problems.warnings()) r.warnings += d.to_string() + "\n";
  return r;
}

std::string errors_of(const std::string& text) { return report_of(text).errors; }

std::string corpus(const std::string& name) { return std::string{DRIVEGATE_TEST_EDS_DIR} + "/" + name; }

std::string warnings_text(const Problems& problems) {
  std::string out;
  for (const auto& d : problems.warnings()) out += d.to_string() + "\n";
  return out;
}

std::optional<std::int64_t> low(const EdsObject* o) {
  return o && o->low_limit ? o->low_limit->value.as_int64() : std::nullopt;
}
std::optional<std::int64_t> high(const EdsObject* o) {
  return o && o->high_limit ? o->high_limit->value.as_int64() : std::nullopt;
}

TEST(Eds, IntegerTypesOfParameterRequests) {
  // A parameter request carries the type of the EDS object (core::param_type_from_cia), whatever its size.
  EXPECT_EQ(core::param_type_from_cia(0x0001), core::ParamType::Bool);
  EXPECT_EQ(core::param_type_from_cia(0x0002), core::ParamType::I8);
  EXPECT_EQ(core::param_type_from_cia(0x0003), core::ParamType::I16);
  EXPECT_EQ(core::param_type_from_cia(0x0004), core::ParamType::I32);
  EXPECT_EQ(core::param_type_from_cia(0x0005), core::ParamType::U8);
  EXPECT_EQ(core::param_type_from_cia(0x0006), core::ParamType::U16);
  EXPECT_EQ(core::param_type_from_cia(0x0007), core::ParamType::U32);
  EXPECT_EQ(core::param_type_from_cia(0x0008), core::ParamType::R32);
  EXPECT_EQ(core::param_type_from_cia(0x0010), core::ParamType::I24);
  EXPECT_EQ(core::param_type_from_cia(0x0015), core::ParamType::I64);
  EXPECT_EQ(core::param_type_from_cia(0x001B), core::ParamType::U64);
  EXPECT_EQ(core::param_type_from_cia(0x0040), core::ParamType::Unknown);  // vendor-defined
}

TEST(Eds, TheTestFileParses) {
  Problems problems;
  const auto objects = objects_of_file(DRIVEGATE_TEST_DEVICE_DIR "/akd-canopen.eds", problems);
  ASSERT_TRUE(objects) << problems.errors().front().to_string();
  EXPECT_TRUE(problems.warnings().empty()) << warnings_text(problems);
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
  const auto objects = objects_of_text(R"(; comment
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
  EXPECT_TRUE(problems.warnings().empty()) << warnings_text(problems);
  ASSERT_EQ(objects->size(), 5U);
  const EdsObject* vendor = find_eds_object(*objects, cia402::ObjectId{0x1018, 1});
  ASSERT_NE(vendor, nullptr);
  EXPECT_EQ(vendor->name, "Vendor-ID");
  EXPECT_EQ(vendor->data_type, 0x0007);
  EXPECT_EQ(core::param_type_from_cia(vendor->data_type), core::ParamType::U32);
  EXPECT_EQ(vendor->access, EdsAccess::ReadOnly);  // keys and access values are case-insensitive
  EXPECT_FALSE(vendor->pdo_mapping);               // PDOMapping left out: not mappable
  EXPECT_EQ(vendor->default_value, "0x6A");
  EXPECT_EQ(vendor->line, 18);
  const EdsObject* name = find_eds_object(*objects, cia402::ObjectId{0x1008, 0});
  ASSERT_NE(name, nullptr);  // ObjectType left out: a VAR
  EXPECT_EQ(eds_type_name(name->data_type), "VISIBLE_STRING");
  EXPECT_FALSE(eds_type_bits(name->data_type));
  EXPECT_EQ(core::param_type_from_cia(name->data_type), core::ParamType::VisibleString);
  EXPECT_FALSE(name->writable());
  const EdsObject* mode = find_eds_object(*objects, cia402::ObjectId{0x6060, 0});
  ASSERT_NE(mode, nullptr);
  EXPECT_EQ(low(mode), -3);
  EXPECT_EQ(high(mode), 10);
  EXPECT_EQ(mode->high_limit->text, "0x0A");
  // A limit relative to the node-ID is kept with its constant part.
  const EdsObject* cob = find_eds_object(*objects, cia402::ObjectId{0x1400, 1});
  ASSERT_TRUE(cob && cob->low_limit);
  EXPECT_TRUE(cob->low_limit->value.plus_node_id);
  EXPECT_EQ(cob->low_limit->value.for_node(5).as_int64(), 0x205);
  EXPECT_FALSE(cob->high_limit);
}

TEST(Eds, LookupByNameIsCaseInsensitiveAndUnique) {
  Problems problems;
  const auto objects = objects_of_file(DRIVEGATE_TEST_DEVICE_DIR "/akd-canopen.eds", problems);
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

// What used to refuse the file is now a warning naming file, line and key; the file loads with the
// objects it can use.
TEST(Eds, EveryDeviationIsAWarningWithItsLine) {
  const Report r = report_of(R"(Junk before any section
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
  ASSERT_TRUE(r.objects) << r.errors;
  const std::string& w = r.warnings;
  EXPECT_REPORTED(w, "x.eds:1:1: text before the first section, ignored: \"Junk before any section\"");
  EXPECT_REPORTED(w, "x.eds:7:1: [6040].DataType: given twice (first at line 4); the later value \"0x0007\" wins");
  EXPECT_REPORTED(w, "x.eds:11:1: [6041].AccessType: must be one of ro, wo, rw, rwr, rww, const, got \"readonly\"; "
                     "the object is skipped");
  EXPECT_REPORTED(w, "x.eds:13:1: [6041]: section given twice (first at line 8); its keys are merged into the first");
  EXPECT_REPORTED(w, "x.eds:14:1: [6042sub1]: sub-index without its object: there is no [6042] section");
  EXPECT_REPORTED(w, "x.eds:19:1: [6043].ObjectType: must be 0x7 (VAR), 0x8 (ARRAY), 0x9 (RECORD), 0x2 (DOMAIN), "
                     "0x0, 0x5 or 0x6, got \"0x3\"; the object is skipped");
  EXPECT_REPORTED(w, "x.eds:20:1: section header without ']': \"[6044\"; its lines are ignored");
  EXPECT_REPORTED(w, "x.eds:21:1: [6045subZZ]: sub-index must be hex 0..FF (as in [1018sub1]); the section is ignored");
  EXPECT_REPORTED(w, "x.eds:22:1: [6046].ParameterName: missing; the object cannot be found by name");
  EXPECT_REPORTED(w, "x.eds:25:1: [6046]: expected KEY=VALUE, got \"no equals sign here\"; ignored");
  EXPECT_REPORTED(w, "x.eds:26:1: [6046].LowLimit: is above HighLimit (5): 10; both are kept as written");
  EXPECT_REPORTED(w, "x.eds:32:1: [6047].HighLimit: must be a number (decimal, 0x hex or octal, a REAL such as 4.5, "
                     "or $NODEID+X), got \"lots\"; ignored");
  EXPECT_EQ(r.errors, "");
  const auto& objects = *r.objects;
  EXPECT_EQ(find_eds_object(objects, cia402::ObjectId{0x6040, 0})->data_type, 0x0007);  // the last one wins
  EXPECT_FALSE(find_eds_object(objects, cia402::ObjectId{0x6041, 0}));                   // no usable AccessType
  EXPECT_EQ(find_eds_object(objects, cia402::ObjectId{0x6042, 1})->parent, "");
  EXPECT_FALSE(find_eds_object(objects, cia402::ObjectId{0x6043, 0}));
  const EdsObject* unnamed = find_eds_object(objects, cia402::ObjectId{0x6046, 0});
  ASSERT_NE(unnamed, nullptr);
  EXPECT_EQ(low(unnamed), 10);
  EXPECT_EQ(high(unnamed), 5);
  EXPECT_FALSE(find_eds_object(objects, cia402::ObjectId{0x6047, 0})->high_limit);
}

// An object without a usable DataType or AccessType is skipped; a file left with no object at all
// is refused, and then its warnings are errors so that the refusal says why.
TEST(Eds, AFileWithNoUsableObjectIsRefusedWithItsReasons) {
  const std::string e = errors_of("[6040]\nParameterName=Controlword\n");
  EXPECT_REPORTED(e, "x.eds:1:1: [6040].DataType: missing; the object is skipped");
  EXPECT_REPORTED(e, "x.eds:1:1: [6040].AccessType: missing; the object is skipped");
  EXPECT_REPORTED(e, "x.eds: lists no usable object (1 skipped, see above); is it a CiA 306 EDS file?");
  EXPECT_REPORTED(errors_of("gateway: { name: g }\nbuses: []\n"),
                  "x.eds:1:1: text before the first section, ignored: \"gateway: { name: g }\"");
  EXPECT_REPORTED(errors_of(""), "x.eds: lists no usable object; is it a CiA 306 EDS file?");
}

TEST(Eds, SkippedObjectsAreListed) {
  Problems problems;
  const auto eds = load_eds(corpus("in-the-wild.eds"), problems);
  ASSERT_TRUE(eds);
  const EdsSkipped* s = find_eds_skipped(eds->skipped, cia402::ObjectId{0x6061, 0});
  ASSERT_NE(s, nullptr);
  EXPECT_EQ(s->line, 52);
  EXPECT_EQ(s->reason, "DataType \"INTEGER8\" is not a data type code");
  EXPECT_EQ(find_eds_skipped(eds->skipped, cia402::ObjectId{0x6064, 0})->reason, "AccessType \"readonly\" is unknown");
  EXPECT_EQ(find_eds_skipped(eds->skipped, cia402::ObjectId{0x2002, 7})->line, 128);  // [2002subZZ]: any sub-index
  EXPECT_FALSE(find_eds_skipped(eds->skipped, cia402::ObjectId{0x6060, 0}));
}

TEST(Eds, UnreadableFile) {
  Problems problems;
  EXPECT_FALSE(objects_of_file("/nonexistent/drive.eds", problems));
  ASSERT_EQ(problems.errors().size(), 1U);
  EXPECT_NE(problems.errors()[0].to_string().find("/nonexistent/drive.eds: cannot open file"), std::string::npos);
}

TEST(Eds, BinaryGarbageIsReportedNotFatal) {
  std::string junk = "[6040]\n";
  for (int i = 0; i < 256; ++i) junk += static_cast<char>(i);
  junk += "\n[\n]\n=\n[]\n[sub]\n[0000sub]\n";
  Problems problems;
  EXPECT_FALSE(objects_of_text(junk, "junk.eds", problems));
  EXPECT_TRUE(problems.has_errors());
}

TEST(Eds, NumberForms) {
  const auto i64 = [](std::string_view text, std::uint16_t type = 0) {
    const auto n = parse_eds_number(text, type);
    return n && !n->plus_node_id ? n->as_int64() : std::nullopt;
  };
  EXPECT_EQ(i64("42"), 42);
  EXPECT_EQ(i64("-42"), -42);
  EXPECT_EQ(i64("+42"), 42);
  EXPECT_EQ(i64("0x2A"), 42);
  EXPECT_EQ(i64("0X2a"), 42);
  EXPECT_EQ(i64("052"), 42);  // octal
  EXPECT_EQ(i64("0"), 0);
  EXPECT_EQ(i64("00"), 0);
  EXPECT_EQ(i64("08"), 8);  // not octal: read as decimal (the parser warns)
  EXPECT_EQ(i64("-0x10"), -16);
  EXPECT_EQ(i64("  7  "), 7);
  EXPECT_EQ(i64("-9223372036854775808"), std::numeric_limits<std::int64_t>::min());
  EXPECT_FALSE(parse_eds_number("-9223372036854775809"));
  EXPECT_EQ(parse_eds_number("18446744073709551615")->as_uint64(), std::numeric_limits<std::uint64_t>::max());
  EXPECT_FALSE(parse_eds_number("18446744073709551616"));
  EXPECT_FALSE(parse_eds_number("0x10000000000000000"));
  EXPECT_DOUBLE_EQ(parse_eds_number("4.5")->as_double(), 4.5);
  EXPECT_DOUBLE_EQ(parse_eds_number("-1e3")->as_double(), -1000.0);
  EXPECT_TRUE(parse_eds_number("-1e3")->is_real());
  EXPECT_DOUBLE_EQ(parse_eds_number(".25")->as_double(), 0.25);
  EXPECT_DOUBLE_EQ(parse_eds_number("0.5")->as_double(), 0.5);
  for (const char* bad : {"", "x", "0x", "0xG1", "1.2.3", "inf", "nan", "-inf", "1e999", "0x1.8p3", "--1", "+-1", "1 2",
                          "UNSIGNED8", "$NODEID*2", "$NODEID+$NODEID", "2+$NODEID+1", "$NODEID+1.5", "$NODEID 5"})
    EXPECT_FALSE(parse_eds_number(bad)) << bad;
  // Two's complement of hex and octal values of signed types; decimal and unsigned stay as written.
  EXPECT_EQ(i64("0xFF", 0x0002), -1);
  EXPECT_EQ(i64("0x7F", 0x0002), 127);
  EXPECT_EQ(i64("0xFF", 0x0005), 255);
  EXPECT_EQ(i64("0x8000", 0x0003), -32768);
  EXPECT_EQ(i64("0xFFFFFFFF", 0x0004), -1);
  EXPECT_EQ(i64("0xFFFFFF", 0x0010), -1);               // INTEGER24
  EXPECT_EQ(i64("0x8000000000", 0x0012), -549755813888);  // INTEGER40
  EXPECT_EQ(i64("0xFFFFFFFFFFFFFFF6", 0x0015), -10);
  EXPECT_EQ(parse_eds_number("0xFFFFFFFFFFFFFFF6", 0x001B)->as_uint64(), 18446744073709551606ULL);
  EXPECT_EQ(i64("255", 0x0002), 255);          // decimal: out of range, not reinterpreted
  EXPECT_EQ(i64("0x1FF", 0x0002), 0x1FF);      // wider than the type: kept
}

TEST(Eds, NodeIdFormulas) {
  for (const char* text : {"$NODEID+0x180", "0x180+$NODEID", "$nodeid + 0x180", "0x180 + $NodeId", "  $NODEID+384 "}) {
    const auto n = parse_eds_number(text, 0x0007);
    ASSERT_TRUE(n) << text;
    EXPECT_TRUE(n->plus_node_id) << text;
    EXPECT_EQ(n->as_int64(), 0x180) << text;
    EXPECT_EQ(n->for_node(3).as_int64(), 0x183) << text;
    EXPECT_FALSE(n->for_node(3).plus_node_id) << text;
  }
  EXPECT_EQ(parse_eds_number("$NODEID")->for_node(127).as_int64(), 127);
  EXPECT_EQ(parse_eds_number("$NODEID-1")->for_node(5).as_int64(), 4);
  // Unrelated to the node-ID, for_node() changes nothing.
  EXPECT_EQ(parse_eds_number("0x180")->for_node(3).as_int64(), 0x180);
  // A node-relative number has no order against a plain one.
  EXPECT_EQ(compare(*parse_eds_number("$NODEID+1"), *parse_eds_number("5")), std::partial_ordering::unordered);
  EXPECT_EQ(compare(*parse_eds_number("$NODEID+1"), *parse_eds_number("$NODEID+5")), std::partial_ordering::less);
}

TEST(Eds, LimitsCompareAcrossRepresentations) {
  const auto n = [](std::string_view text, std::uint16_t type = 0) { return *parse_eds_number(text, type); };
  EXPECT_EQ(compare(n("-1"), n("0xFFFFFFFFFFFFFFFF")), std::partial_ordering::less);  // i64 vs u64
  EXPECT_EQ(compare(n("0xFFFFFFFFFFFFFFFF"), n("1")), std::partial_ordering::greater);
  EXPECT_EQ(compare(n("4.5"), n("4")), std::partial_ordering::greater);
  EXPECT_EQ(compare(n("4"), n("4.0")), std::partial_ordering::equivalent);
  EXPECT_EQ(compare(n("0x80", 0x0002), n("0x7F", 0x0002)), std::partial_ordering::less);
  EXPECT_EQ(n("0x10"), n("16"));
  EXPECT_EQ(n("020"), n("16"));
}

TEST(Eds, NumbersInEveryFieldAndForm) {
  Problems problems;
  const auto objects = objects_of_file(corpus("numbers.eds"), problems);
  ASSERT_TRUE(objects) << problems.errors().front().to_string();
  EXPECT_TRUE(problems.warnings().empty()) << warnings_text(problems);
  const EdsObject* type = find_eds_object(*objects, cia402::ObjectId{0x1000, 0});
  ASSERT_NE(type, nullptr);
  EXPECT_EQ(type->data_type, 0x0007);  // DataType=7
  EXPECT_FALSE(type->pdo_mapping);     // PDOMapping=0x0
  const EdsObject* hb = find_eds_object(*objects, cia402::ObjectId{0x1017, 0});
  ASSERT_NE(hb, nullptr);
  EXPECT_FALSE(hb->pdo_mapping);  // PDOMapping=00
  EXPECT_EQ(low(hb), 0);
  EXPECT_EQ(high(hb), 0xFFFF);  // HighLimit=0177777
  // [1200sub0] DataType=05 (octal 5), ObjectType=0x07.
  EXPECT_EQ(find_eds_object(*objects, cia402::ObjectId{0x1200, 0})->data_type, 0x0005);
  const EdsObject* rx = find_eds_object(*objects, cia402::ObjectId{0x1200, 1});
  ASSERT_TRUE(rx && rx->low_limit && rx->high_limit);
  EXPECT_EQ(rx->default_value, "$NODEID+0x600");  // verbatim
  EXPECT_TRUE(rx->low_limit->value.plus_node_id);
  EXPECT_EQ(rx->low_limit->text, "$NODEID+0x600");
  EXPECT_EQ(rx->high_limit->text, "0x600+$nodeid");
  EXPECT_EQ(rx->low_limit->value.for_node(0x21).as_int64(), 0x621);
  EXPECT_EQ(rx->high_limit->value.for_node(0x21).as_int64(), 0x621);
  const EdsObject* tx = find_eds_object(*objects, cia402::ObjectId{0x1200, 2});
  ASSERT_TRUE(tx && tx->low_limit && tx->high_limit);
  EXPECT_EQ(tx->default_value, "0x580 + $NodeId");
  EXPECT_EQ(tx->low_limit->value.for_node(1).as_int64(), 0x581);
  EXPECT_EQ(tx->high_limit->value.for_node(1).as_int64(), 0x600);
  // ObjectType=011 is octal 9: a RECORD, whose entries are its sub-indices.
  const EdsObject* tt = find_eds_object(*objects, cia402::ObjectId{0x1400, 2});
  ASSERT_NE(tt, nullptr);
  EXPECT_EQ(tt->parent, "RPDO communication parameter");
  EXPECT_EQ(high(tt), 255);  // 0377
  EXPECT_EQ(tt->default_value, "0xFF");
  const EdsObject* cw = find_eds_object(*objects, "Controlword");
  ASSERT_NE(cw, nullptr);
  EXPECT_EQ(cw->data_type, 0x0006);  // 0X6
  EXPECT_TRUE(cw->pdo_mapping);      // 0x1
  const EdsObject* mode = find_eds_object(*objects, cia402::ObjectId{0x6060, 0});
  EXPECT_EQ(low(mode), -3);
  EXPECT_EQ(high(mode), 10);  // 012
  EXPECT_EQ(objects->size(), 10U);
}

struct TypeRow {
  std::uint8_t sub;
  std::uint16_t code;
  const char* name;
  std::optional<std::uint8_t> bits;
  EdsTypeKind kind;
};

TEST(Eds, EveryStandardDataType) {
  Problems problems;
  const auto objects = objects_of_file(corpus("types.eds"), problems);
  ASSERT_TRUE(objects) << problems.errors().front().to_string();
  EXPECT_TRUE(problems.warnings().empty()) << warnings_text(problems);
  using K = EdsTypeKind;
  const TypeRow rows[] = {
      {0x01, 0x0001, "BOOLEAN", 8, K::Boolean},
      {0x02, 0x0002, "INTEGER8", 8, K::SignedInteger},
      {0x03, 0x0003, "INTEGER16", 16, K::SignedInteger},
      {0x04, 0x0004, "INTEGER32", 32, K::SignedInteger},
      {0x05, 0x0005, "UNSIGNED8", 8, K::UnsignedInteger},
      {0x06, 0x0006, "UNSIGNED16", 16, K::UnsignedInteger},
      {0x07, 0x0007, "UNSIGNED32", 32, K::UnsignedInteger},
      {0x08, 0x0008, "REAL32", 32, K::Real},
      {0x09, 0x0009, "VISIBLE_STRING", std::nullopt, K::String},
      {0x0A, 0x000A, "OCTET_STRING", std::nullopt, K::String},
      {0x0B, 0x000B, "UNICODE_STRING", std::nullopt, K::String},
      {0x0C, 0x000C, "TIME_OF_DAY", 48, K::Time},
      {0x0D, 0x000D, "TIME_DIFFERENCE", 48, K::Time},
      {0x0E, 0x000F, "DOMAIN", std::nullopt, K::Domain},
      {0x0F, 0x0010, "INTEGER24", 24, K::SignedInteger},
      {0x10, 0x0011, "REAL64", 64, K::Real},
      {0x11, 0x0012, "INTEGER40", 40, K::SignedInteger},
      {0x12, 0x0013, "INTEGER48", 48, K::SignedInteger},
      {0x13, 0x0014, "INTEGER56", 56, K::SignedInteger},
      {0x14, 0x0015, "INTEGER64", 64, K::SignedInteger},
      {0x15, 0x0016, "UNSIGNED24", 24, K::UnsignedInteger},
      {0x16, 0x0018, "UNSIGNED40", 40, K::UnsignedInteger},
      {0x17, 0x0019, "UNSIGNED48", 48, K::UnsignedInteger},
      {0x18, 0x001A, "UNSIGNED56", 56, K::UnsignedInteger},
      {0x19, 0x001B, "UNSIGNED64", 64, K::UnsignedInteger},
  };
  for (const auto& row : rows) {
    const EdsObject* o = find_eds_object(*objects, cia402::ObjectId{0x2000, row.sub});
    ASSERT_NE(o, nullptr) << row.name;
    EXPECT_EQ(o->data_type, row.code) << row.name;
    EXPECT_EQ(eds_type_name(o->data_type), row.name);
    EXPECT_TRUE(o->name.ends_with(row.name)) << o->name;
    EXPECT_EQ(eds_type_bits(o->data_type), row.bits) << row.name;
    EXPECT_EQ(eds_type_kind(o->data_type), row.kind) << row.name;
  }
  // Vendor-defined and other codes are kept, with no size.
  const auto vendor = find_eds_object(*objects, cia402::ObjectId{0x2001, 0});
  ASSERT_NE(vendor, nullptr);
  EXPECT_EQ(vendor->data_type, 0x0040);
  EXPECT_TRUE(vendor->pdo_mapping);
  EXPECT_EQ(eds_type_name(0x0040), "0x0040 (vendor-defined)");
  EXPECT_EQ(eds_type_kind(0x0040), EdsTypeKind::VendorDefined);
  EXPECT_FALSE(eds_type_bits(0x0040));
  EXPECT_EQ(core::param_type_from_cia(0x0040), core::ParamType::Unknown);
  EXPECT_EQ(find_eds_object(*objects, cia402::ObjectId{0x2002, 0})->data_type, 0x005F);
  EXPECT_EQ(eds_type_name(0x005F), "0x005F (vendor-defined)");
  EXPECT_EQ(find_eds_object(*objects, cia402::ObjectId{0x2003, 0})->data_type, 0x0060);
  EXPECT_EQ(eds_type_name(0x0060), "0x0060 (device-profile-defined)");
  EXPECT_EQ(find_eds_object(*objects, cia402::ObjectId{0x2004, 0})->data_type, 0x1234);
  EXPECT_EQ(eds_type_name(0x1234), "0x1234 (unknown)");
  EXPECT_EQ(eds_type_kind(0x1234), EdsTypeKind::Unknown);
  EXPECT_EQ(eds_type_name(0x0017), "0x0017 (unknown)");  // reserved
  EXPECT_EQ(eds_type_name(0x0023), "IDENTITY");
  EXPECT_EQ(eds_type_kind(0x0020), EdsTypeKind::Complex);
  // A DOMAIN object (ObjectType=0x2) without a DataType is of type DOMAIN.
  const EdsObject* image = find_eds_object(*objects, "Firmware image");
  ASSERT_NE(image, nullptr);
  EXPECT_EQ(image->data_type, 0x000F);
  EXPECT_EQ(image->access, EdsAccess::WriteOnly);
}

TEST(Eds, IntegerAndRealLimitsSurvive) {
  Problems problems;
  const auto objects = objects_of_file(corpus("types.eds"), problems);
  ASSERT_TRUE(objects);
  const auto at = [&](std::uint16_t index) { return find_eds_object(*objects, cia402::ObjectId{index, 0}); };
  const EdsObject* current = at(0x2100);  // REAL32 -1e3 .. 4.5
  ASSERT_TRUE(current && current->low_limit && current->high_limit);
  EXPECT_TRUE(current->low_limit->value.is_real());
  EXPECT_DOUBLE_EQ(current->low_limit->value.as_double(), -1000.0);
  EXPECT_DOUBLE_EQ(current->high_limit->value.as_double(), 4.5);
  EXPECT_EQ(current->high_limit->text, "4.5");
  EXPECT_FALSE(current->high_limit->value.as_int64());
  EXPECT_DOUBLE_EQ(at(0x2101)->low_limit->value.as_double(), -1.5e300);
  EXPECT_DOUBLE_EQ(at(0x2101)->high_limit->value.as_double(), 0.25);
  const EdsObject* energy = at(0x2102);  // UNSIGNED64 up to 0xFFFFFFFFFFFFFFF6
  ASSERT_TRUE(energy && energy->high_limit);
  EXPECT_EQ(energy->high_limit->value.as_uint64(), 0xFFFFFFFFFFFFFFF6ULL);
  EXPECT_FALSE(energy->high_limit->value.as_int64());
  EXPECT_TRUE(std::holds_alternative<std::uint64_t>(energy->high_limit->value.value));
  EXPECT_EQ(low(at(0x2103)), std::numeric_limits<std::int64_t>::min());
  EXPECT_EQ(high(at(0x2103)), std::numeric_limits<std::int64_t>::max());
  EXPECT_EQ(low(at(0x2104)), -10);  // 0xFFFFFFFFFFFFFFF6 on INTEGER64
  EXPECT_EQ(at(0x2104)->low_limit->text, "0xFFFFFFFFFFFFFFF6");
  EXPECT_EQ(low(at(0x2105)), -128);  // 0x80 on INTEGER8
  EXPECT_EQ(high(at(0x2105)), 127);
  EXPECT_EQ(low(at(0x2106)), -8388608);  // 0x800000 on INTEGER24
  EXPECT_EQ(low(at(0x2107)), -32768);    // 0100000 on INTEGER16
  EXPECT_EQ(low(at(0x2108)), 0x8000);    // 0x8000 on UNSIGNED16
  EXPECT_EQ(high(at(0x2108)), 0xFFFF);
}

TEST(Eds, CompactSubObjArrays) {
  Problems problems;
  const auto objects = objects_of_file(corpus("compact.eds"), problems);
  ASSERT_TRUE(objects) << problems.errors().front().to_string();
  EXPECT_TRUE(problems.warnings().empty()) << warnings_text(problems);
  const auto at = [&](std::uint16_t index, std::uint8_t sub) { return find_eds_object(*objects, cia402::ObjectId{index, sub}); };
  // Sub-index 0: the number of entries.
  const EdsObject* count = at(0x1003, 0);
  ASSERT_NE(count, nullptr);
  EXPECT_EQ(count->name, "NrOfEntries");
  EXPECT_EQ(count->parent, "Pre-defined error field");
  EXPECT_EQ(count->data_type, 0x0005);
  EXPECT_EQ(count->access, EdsAccess::ReadOnly);
  EXPECT_FALSE(count->pdo_mapping);
  EXPECT_EQ(count->default_value, "4");
  EXPECT_EQ(count->line, 17);
  // 1..4 typed from the ARRAY, named by [1003Name] or after the ARRAY, defaults from [1003Value].
  const char* names[] = {"Newest error", "Second newest error", "Pre-defined error field3", "Pre-defined error field4"};
  const char* defaults[] = {"0", "0", "0", "0x00001000"};
  for (std::uint8_t i = 1; i <= 4; ++i) {
    const EdsObject* e = at(0x1003, i);
    ASSERT_NE(e, nullptr) << int{i};
    EXPECT_EQ(e->name, names[i - 1]);
    EXPECT_EQ(e->parent, "Pre-defined error field");
    EXPECT_EQ(e->data_type, 0x0007);
    EXPECT_EQ(e->access, EdsAccess::ReadOnly);
    EXPECT_FALSE(e->pdo_mapping);
    EXPECT_EQ(e->default_value, defaults[i - 1]);
  }
  EXPECT_FALSE(at(0x1003, 5));
  EXPECT_EQ(find_eds_object(*objects, "second NEWEST error"), at(0x1003, 2));
  EXPECT_EQ(find_eds_object(*objects, "NrOfEntries"), nullptr);  // one per ARRAY
  EXPECT_EQ(find_eds_object(*objects, "Consumer heartbeat time.NrOfEntries"), at(0x1016, 0));
  // Without [xxxxName]/[xxxxValue]: every entry named after the ARRAY, with its default and limits.
  for (std::uint8_t i = 1; i <= 3; ++i) {
    const EdsObject* e = at(0x1016, i);
    ASSERT_NE(e, nullptr);
    EXPECT_EQ(e->name, "Consumer heartbeat time" + std::to_string(i));
    EXPECT_EQ(e->access, EdsAccess::ReadWrite);
    EXPECT_EQ(e->default_value, "0x00000000");
    EXPECT_EQ(low(e), 0);
    EXPECT_EQ(high(e), 0x7FFFFF);
  }
  EXPECT_EQ(at(0x1016, 0)->default_value, "3");
  EXPECT_FALSE(at(0x1016, 4));
  // CompactSubObj=0x02: mappable REAL32 entries with REAL limits.
  const EdsObject* ai2 = find_eds_object(*objects, "Analog input 2 (V)");
  ASSERT_NE(ai2, nullptr);
  EXPECT_EQ(ai2->id, (cia402::ObjectId{0x2010, 2}));
  EXPECT_TRUE(ai2->pdo_mapping);
  EXPECT_EQ(ai2->data_type, 0x0008);
  EXPECT_DOUBLE_EQ(ai2->low_limit->value.as_double(), -10.0);
  EXPECT_DOUBLE_EQ(ai2->high_limit->value.as_double(), 10.0);
  // [6040ObjectLinks] and [DummyUsage] are read past.
  EXPECT_NE(at(0x6040, 0), nullptr);
  EXPECT_NE(at(0x6041, 0), nullptr);
  EXPECT_EQ(objects->size(), 5U + 4U + 3U + 1U + 1U);
}

TEST(Eds, CompactSubObjDeviations) {
  const Report r = report_of(R"([1003]
ParameterName=Errors
ObjectType=0x8
DataType=0x0007
AccessType=ro
CompactSubObj=2
[1003sub2]
ParameterName=Explicit second
DataType=0x0007
AccessType=ro
[1003Value]
NrOfEntries=2
1=1
01=2
x=3
[2000]
ParameterName=A record
ObjectType=0x9
CompactSubObj=3
[2001]
ParameterName=Too many
ObjectType=0x8
DataType=0x0005
AccessType=rw
CompactSubObj=300
[2002]
ParameterName=No type
ObjectType=0x8
AccessType=rw
CompactSubObj=2
[2002Name]
1=First
[2003Name]
1=Nobody's
)");
  ASSERT_TRUE(r.objects) << r.errors;
  const std::string& w = r.warnings;
  EXPECT_REPORTED(w, "x.eds:6:1: [1003].CompactSubObj: sub-index 2 is also given by a section at line 7, which is used");
  EXPECT_REPORTED(w, "x.eds:12:1: [1003Value].NrOfEntries: is 2 but 1 entries follow");
  EXPECT_REPORTED(w, "x.eds:14:1: [1003Value].01: sub-index 1 given twice (first at line 13); the first wins");
  EXPECT_REPORTED(w, "x.eds:15:1: [1003Value].x: unknown key, ignored (expected NrOfEntries or a sub-index 1..2)");
  EXPECT_REPORTED(w, "x.eds:19:1: [2000].CompactSubObj: is for ARRAYs (0x8) only, ignored on a RECORD");
  EXPECT_REPORTED(w, "x.eds:25:1: [2001].CompactSubObj: must be 1..254 entries, got \"300\"; the sub-indices are not created");
  EXPECT_REPORTED(w, "x.eds:26:1: [2002].DataType: missing; the CompactSubObj sub-indices are not created");
  EXPECT_REPORTED(w, "x.eds:33:1: [2003Name]: ignored: object 2003h is not an ARRAY with CompactSubObj");
  const auto& objects = *r.objects;
  EXPECT_EQ(find_eds_object(objects, cia402::ObjectId{0x1003, 2})->name, "Explicit second");
  EXPECT_EQ(find_eds_object(objects, cia402::ObjectId{0x1003, 1})->default_value, "1");
  EXPECT_FALSE(find_eds_object(objects, cia402::ObjectId{0x2001, 1}));
  EXPECT_FALSE(find_eds_object(objects, cia402::ObjectId{0x2002, 1}));
  EXPECT_EQ(objects.size(), 3U);
}

// The in-the-wild file: UTF-8 BOM, CRLF, odd whitespace, comments, unknown sections and keys,
// duplicates, PDOMapping spelt otherwise, limits in the wrong order, unusable objects.
TEST(Eds, InTheWildFileLoadsWithWarnings) {
  Problems problems;
  const std::string file = corpus("in-the-wild.eds");
  const auto objects = objects_of_file(file, problems);
  ASSERT_TRUE(objects) << problems.errors().front().to_string();
  const auto w = [&file](const std::string& rest) { return file + ":" + rest + "\n"; };
  EXPECT_EQ(warnings_text(problems),
            w("11:1: [ToolSettings]: unknown section, ignored") +
                w("21:1: [1000].StorageLocation: unknown key, ignored (also in 1 more section)") +
                w("28:1: [1001].PDOMapping: given twice (first at line 27); the later value \"1\" wins") +
                w("35:1: [6040].PDOMapping: should be 0 or 1, got \"yes\"; read as 1 (mappable)") +
                w("41:1: [6041].PDOMapping: should be 0 or 1, got \"2\"; read as 1 (mappable)") +
                w("48:1: [6060].LowLimit: is above HighLimit (-3): 10; both are kept as written") +
                w("50:1: [6060].DefaultValue: \"08\" starts with 0, which CiA 306 reads as octal, but is not octal; "
                  "read as decimal") +
                w("54:1: [6061].DataType: must be a CiA 301 data type code such as 0x0007 (UNSIGNED32) or a vendor "
                  "type 0x0040..0x005F, got \"INTEGER8\"; the object is skipped") +
                w("60:1: [6064].AccessType: must be one of ro, wo, rw, rwr, rww, const, got \"readonly\"; the object "
                  "is skipped") +
                w("68:1: [607A].LowLimit: must be a number (decimal, 0x hex or octal, a REAL such as 4.5, or "
                  "$NODEID+X), got \"lots\"; ignored") +
                w("75:1: [6098]: expected KEY=VALUE, got \"this line has no equals sign\"; ignored") +
                w("80:1: [60FE].SubNumber: is 3 but the file has 2 [60FEsubN] sections") +
                w("100:1: [6502]: section given twice (first at line 94); its keys are merged into the first, later "
                  "values win") +
                w("105:1: [DummyUsage].Dummy0006: should be 0 or 1, got \"yes\"; ignored") +
                w("115:1: [1010Name].NrOfEntries: is 3 but 2 entries follow") +
                w("118:1: [1010Name].3: CompactSubObj=2 has no sub-index 3; ignored") +
                w("120:1: [6502Value]: ignored: object 6502h is not an ARRAY with CompactSubObj (CiA 306 §4.6.7)") +
                w("123:1: [2001sub1]: sub-index without its object: there is no [2001] section; kept without a parent") +
                w("128:1: [2002subZZ]: sub-index must be hex 0..FF (as in [1018sub1]); the section is ignored") +
                w("131:1: section header without ']': \"[2003\"; its lines are ignored"));
  const auto at = [&](std::uint16_t index, std::uint8_t sub = 0) {
    return find_eds_object(*objects, cia402::ObjectId{index, sub});
  };
  // The BOM and the odd whitespace do not get into names or values; CRLF counts as one line.
  const EdsObject* type = at(0x1000);
  ASSERT_NE(type, nullptr);
  EXPECT_EQ(type->name, "Device type");
  EXPECT_EQ(type->access, EdsAccess::ReadOnly);
  EXPECT_EQ(type->default_value, "0x00020192");
  EXPECT_EQ(type->line, 14);
  EXPECT_TRUE(at(0x1001)->pdo_mapping);                  // the later PDOMapping=1
  EXPECT_EQ(at(0x6040)->data_type, 0x0006);              // "0x0006 ; UNSIGNED16"
  EXPECT_TRUE(at(0x6040)->pdo_mapping);                  // yes
  EXPECT_TRUE(at(0x6041)->pdo_mapping);                  // 2
  EXPECT_EQ(low(at(0x6060)), 10);                        // kept as written
  EXPECT_EQ(high(at(0x6060)), -3);
  EXPECT_EQ(at(0x6060)->default_value, "08");
  EXPECT_FALSE(at(0x6061));
  EXPECT_FALSE(at(0x6064));
  EXPECT_FALSE(at(0x607A)->low_limit);
  EXPECT_EQ(high(at(0x607A)), 0x7FFFFFFF);
  EXPECT_EQ(at(0x6098)->data_type, 0x0002);
  EXPECT_EQ(at(0x60FE, 1)->parent, "Digital outputs");
  EXPECT_EQ(at(0x6502)->default_value, "0x00000025");  // merged from the second [6502]
  EXPECT_EQ(at(0x1010, 2)->name, "Save communication parameters");
  EXPECT_FALSE(at(0x1010, 3));
  EXPECT_EQ(at(0x2001, 1)->name, "Orphan entry");
  EXPECT_FALSE(at(0x2003));
  EXPECT_EQ(objects->size(), 14U);
}

TEST(Eds, LineEndsAndByteOrderMark) {
  // LF, CRLF and a lone CR each end one line; a BOM before the first section is not text.
  const Report r = report_of("\xEF\xBB\xBF[6040]\r\nParameterName=Controlword\rDataType=0x0006\nAccessType=rw\r\n"
                             "\r\n[6041]\nParameterName=Statusword\nDataType=0x0006\nAccessType=ro\nDefaultValue=0x\n");
  ASSERT_TRUE(r.objects) << r.errors;
  EXPECT_EQ(r.warnings,
            "x.eds:10:1: [6041].DefaultValue: is not a number, which a UNSIGNED16 object needs: \"0x\"; kept as written\n");
  ASSERT_EQ(r.objects->size(), 2U);
  EXPECT_EQ((*r.objects)[0].name, "Controlword");
  EXPECT_EQ((*r.objects)[1].line, 6);
}

TEST(Eds, TooManyWarningsAreCounted) {
  std::string text = "[6040]\nParameterName=Controlword\nDataType=0x0006\nAccessType=rw\n";
  for (int i = 0; i < 60; ++i) text += "[Vendor" + std::to_string(i) + "]\n";
  Problems problems;
  ASSERT_TRUE(objects_of_text(text, "x.eds", problems));
  ASSERT_EQ(problems.warnings().size(), kMaxEdsWarnings + 1);
  EXPECT_EQ(problems.warnings().back().to_string(), "x.eds: 10 more warnings about this file not shown");
}

// Every corpus file stays loadable as written (the fuzz seeds are copies of these).
TEST(Eds, CorpusFilesLoad) {
  for (const char* name : {"numbers.eds", "types.eds", "compact.eds", "in-the-wild.eds"}) {
    Problems problems;
    EXPECT_TRUE(load_eds(corpus(name), problems)) << name;
    EXPECT_FALSE(problems.has_errors()) << name;
  }
}

}  // namespace
}  // namespace drivegate::config
