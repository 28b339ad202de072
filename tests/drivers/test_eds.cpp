// The EDS/DCF reader (CiA 306) on files written the way vendors write them (tests/drivers/eds/, each
// written by hand from the standard's rules) and on small broken texts. Expected values are worked out by
// hand from the files (hex, octal, $NODEID arithmetic, two's complement); expected lines are found by
// searching the file's text, not by the reader.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>

#include "loom/drivers/eds.hpp"
#include "text_file.hpp"

namespace loom::drivers::eds {
namespace {

std::string path_of(const std::string& name) {
  return std::string(LOOM_EDS_DIR) + "/" + name;
}

std::string text_of(const std::string& name) {
  return loom::test::read_text_file(path_of(name));
}

// The 1-based line of the first line of `text` that contains `needle` (after `after`, when given).
int line_of(const std::string& text, const std::string& needle, const std::string& after = "") {
  std::size_t from = after.empty() ? 0 : text.find(after);
  const std::size_t at = text.find(needle, from);
  if (at == std::string::npos) return -1;
  int line = 1;
  for (std::size_t i = 0; i < at; ++i) line += text[i] == '\n' ? 1 : 0;
  return line;
}

std::vector<std::string> messages(const Description& d) {
  std::vector<std::string> out;
  for (const Diagnostic& g : d.diagnostics) out.push_back(format(d.file, g));
  return out;
}

std::int64_t int_of(const Value& v) {
  return std::get<std::int64_t>(v.v);
}
std::uint64_t uint_of(const Value& v) {
  return std::get<std::uint64_t>(v.v);
}

TEST(EdsReader, AVendorsDynamicDriveWithCrlfMixedCaseInlineCommentAndOctal) {
  const std::string name = "acme_ax400_dynamic.eds";
  const std::string text = text_of(name);
  const Description d = read_eds(text, name);
  // Three deviations, each a warning at its line; nothing an error.
  ASSERT_EQ(d.diagnostics.size(), 3u) << ::testing::PrintToString(messages(d));
  EXPECT_FALSE(d.has_errors());
  EXPECT_EQ(d.diagnostics[0].line, line_of(text, "SupportedObjects=31"));
  EXPECT_NE(d.diagnostics[0].message.find("SupportedObjects = 31 but 35 objects are listed"),
            std::string::npos);
  EXPECT_EQ(d.diagnostics[1].line, line_of(text, "DefaultValue=0", "[1017]"));  // 0 below LowLimit 10
  EXPECT_EQ(d.diagnostics[2].line, line_of(text, "; mapped in RPDO1"));
  EXPECT_EQ(format(d.file, d.diagnostics[0]),
            name + ":" + std::to_string(line_of(text, "SupportedObjects=31")) +
                ": warning: [OptionalObjects]: SupportedObjects = 31 but 35 "
                "objects are listed");

  EXPECT_EQ(d.objects.size(), 38u);  // 3 mandatory + 35 optional sections
  // [DeviceInfo]: hex, decimal (4198964 = 0x401234).
  EXPECT_EQ(d.device.vendor_number, 0x4A2u);
  EXPECT_EQ(d.device.product_number, 0x401234u);
  EXPECT_EQ(d.device.revision_number, 0x20001u);
  EXPECT_EQ(d.device.nr_of_rxpdo, 4);
  EXPECT_EQ(d.device.nr_of_txpdo, 4);
  EXPECT_EQ(d.device.granularity, 8);
  EXPECT_EQ(d.device.baud_rates_kbit, (std::vector<std::uint32_t>{125, 250, 500, 1000}));
  EXPECT_TRUE(d.device.lss_supported);
  EXPECT_FALSE(d.dummy_usage.at(0x0001));
  EXPECT_TRUE(d.dummy_usage.at(0x0007));

  // $NODEID+0x200 for node 5 is 0x205; RPDO2 (0x1401) $NODEID+0x300 for node 127 is 0x37F.
  const Entry* cob = d.entry(0x1400, 1);
  ASSERT_NE(cob, nullptr);
  EXPECT_TRUE(cob->default_value.plus_node_id);
  EXPECT_EQ(cob->default_value.bits(5, cob->type), 0x205u);
  EXPECT_EQ(d.entry(0x1401, 1)->default_value.bits(127, DataType::kUnsigned32), 0x37Fu);
  // LowLimit=012 is octal: 10.
  EXPECT_EQ(uint_of(d.entry(0x1017, 0)->low_limit), 10u);
  // INTEGER32 LowLimit=0x80000000 is the bit pattern of -2^31; HighLimit 0x7FFFFFFF = 2^31 - 1.
  EXPECT_EQ(int_of(d.entry(0x607A, 0)->low_limit), -2147483648LL);
  EXPECT_EQ(int_of(d.entry(0x607A, 0)->high_limit), 2147483647LL);
  // 0x60C2:02 LowLimit=-6 in decimal.
  EXPECT_EQ(int_of(d.entry(0x60C2, 2)->low_limit), -6);
  // Lower-case keys, "RO": the statusword is ro and mappable; the inline comment left PDOMapping=1.
  const Entry* sw = d.entry(0x6041, 0);
  ASSERT_NE(sw, nullptr);
  EXPECT_EQ(sw->access, Access::kRo);
  EXPECT_EQ(sw->type, DataType::kUnsigned16);
  EXPECT_TRUE(sw->pdo_mapping);
  EXPECT_TRUE(d.entry(0x6040, 0)->pdo_mapping);
  EXPECT_EQ(d.entry(0x6040, 0)->access, Access::kRww);
  // [1018SUB1] in upper case is the same section name as [1018sub1].
  EXPECT_EQ(d.entry(0x1018, 1)->default_value.bits(0, DataType::kUnsigned32), 0x4A2u);
  // 0x6502 = 0xA5: PP (0), PV (2), HM (5), CSP (7).
  EXPECT_EQ(uint_of(d.entry(0x6502, 0)->default_value), 0xA5u);

  // Every PDO has writable mapping objects: dynamic; the default RPDO1 mapping is {0x6040/16, 0x607A/32}.
  const std::vector<PdoDescription> p = pdos(d);
  ASSERT_EQ(p.size(), 8u);
  for (const PdoDescription& x : p) EXPECT_EQ(x.kind, MappingKind::kDynamic) << x.number;
  ASSERT_EQ(p[0].mapping.size(), 2u);
  EXPECT_EQ(p[0].mapping[0].index, 0x6040);
  EXPECT_EQ(p[0].mapping[0].bits, 16);
  EXPECT_EQ(p[0].mapping[1].index, 0x607A);
  EXPECT_EQ(p[0].mapping[1].bits, 32);
  EXPECT_EQ(p[0].transmission_type, 255);
  EXPECT_TRUE(p[0].transmission_type_writable);
  EXPECT_TRUE(p[4].mapping.size() == 2 && p[4].mapping[1].index == 0x6064);
}

TEST(EdsReader, StrictModeMakesEveryDeviationAnError) {
  const std::string name = "acme_ax400_dynamic.eds";
  const Description d = read_eds(text_of(name), name, ReadOptions{true});
  ASSERT_EQ(d.diagnostics.size(), 3u);
  EXPECT_TRUE(d.has_errors());
  for (const Diagnostic& g : d.diagnostics) EXPECT_EQ(g.severity, Severity::kError);
}

TEST(EdsReader, ASmallVendorsFixedMappingDriveWithoutFileInfoOrObjectTypes) {
  const std::string name = "brick_bx2_fixed.eds";
  const std::string text = text_of(name);
  const Description d = read_eds_file(path_of(name));
  ASSERT_EQ(d.diagnostics.size(), 2u) << ::testing::PrintToString(messages(d));
  EXPECT_FALSE(d.has_errors());
  EXPECT_EQ(d.diagnostics[0].line, line_of(text, "NrOfTXPDO=3"));
  EXPECT_NE(d.diagnostics[0].message.find("NrOfTXPDO = 3 but the file has 2"), std::string::npos);
  EXPECT_EQ(d.diagnostics[1].line, line_of(text, "[1018]"));
  EXPECT_NE(d.diagnostics[1].message.find("no ObjectType but sub-index sections"), std::string::npos);
  EXPECT_EQ(d.object(0x1018)->type, ObjectType::kRecord);
  EXPECT_EQ(d.device.vendor_number, 2844u);  // decimal
  // "0x180+$NODEID" for node 3: 0x183.
  EXPECT_EQ(d.entry(0x1800, 1)->default_value.bits(3, DataType::kUnsigned32), 0x183u);
  // INTEGER8 "0xFD" is -3 (two's complement).
  EXPECT_EQ(int_of(d.entry(0x60C2, 2)->default_value), -3);
  // Mapping objects ro/const: fixed; entries written in decimal: 1614872592 = 0x60410010 (0x6041:00, 16 bit),
  // 1617166368 = 0x60640020 (0x6064:00, 32 bit).
  const std::vector<PdoDescription> p = pdos(d);
  ASSERT_EQ(p.size(), 3u);
  EXPECT_TRUE(p[0].receive);
  EXPECT_EQ(p[0].kind, MappingKind::kFixed);
  EXPECT_EQ(p[1].kind, MappingKind::kFixed);
  EXPECT_EQ(p[2].kind, MappingKind::kFixed);  // const entries
  ASSERT_EQ(p[1].mapping.size(), 2u);
  EXPECT_EQ(p[1].mapping[0].index, 0x6041);
  EXPECT_EQ(p[1].mapping[0].sub, 0);
  EXPECT_EQ(p[1].mapping[0].bits, 16);
  EXPECT_EQ(p[1].mapping[1].index, 0x6064);
  EXPECT_EQ(p[1].mapping[1].bits, 32);
  EXPECT_EQ(p[1].transmission_type, 1);
  EXPECT_FALSE(p[1].transmission_type_writable);
}

TEST(EdsReader, CompactSubObjNamesObjectLinksAndDummyUsage) {
  const std::string name = "tecto_io16.eds";
  const std::string text = text_of(name);
  const Description d = read_eds(text, name);
  EXPECT_TRUE(d.diagnostics.empty()) << ::testing::PrintToString(messages(d));
  const Object* in = d.object(0x6000);
  ASSERT_NE(in, nullptr);
  EXPECT_EQ(in->type, ObjectType::kArray);
  EXPECT_EQ(in->compact_sub_obj, 2);
  ASSERT_EQ(in->entries.size(), 3u);  // sub 0 (the count) and subs 1, 2
  EXPECT_EQ(uint_of(in->entry(0)->default_value), 2u);
  EXPECT_EQ(in->entry(0)->access, Access::kRo);
  EXPECT_EQ(in->entry(1)->name, "Inputs 1-8");
  EXPECT_EQ(in->entry(2)->name, "Inputs 9-16");
  EXPECT_EQ(in->entry(2)->type, DataType::kUnsigned8);
  EXPECT_TRUE(in->entry(2)->pdo_mapping);
  EXPECT_EQ(in->object_links, (std::vector<std::uint16_t>{0x6002, 0x6100}));
  // Without a [XXXXName] section the subs are named after the object.
  EXPECT_EQ(d.entry(0x6401, 2)->name, "Read analog input 16-bit2");
  EXPECT_EQ(d.entry(0x6401, 2)->type, DataType::kInteger16);
  EXPECT_EQ(d.entry(0x6206, 2)->default_value.bits(0, DataType::kUnsigned8), 0xFFu);
  EXPECT_EQ(d.dummy_usage.size(), 5u);
  EXPECT_TRUE(d.dummy_usage.at(0x0005));
  EXPECT_EQ(d.device.nr_of_txpdo, 3);
}

Description read(const std::string& text, bool strict = false) {
  return read_eds(text, "t.eds", ReadOptions{strict});
}

// The three mandatory objects and nothing else: the base of the broken texts below.
const char* const kMinimal =
    "[1000]\nParameterName=Device type\nDataType=0x0007\nAccessType=ro\nDefaultValue=0x00000191\n"
    "[1001]\nParameterName=Error register\nDataType=0x0005\nAccessType=ro\n"
    "[1018]\nParameterName=Identity\nObjectType=9\nSubNumber=2\n"
    "[1018sub0]\nParameterName=n\nDataType=5\nAccessType=ro\nDefaultValue=1\n"
    "[1018sub1]\nParameterName=Vendor-ID\nDataType=7\nAccessType=ro\nDefaultValue=0x777\n";

TEST(EdsReader, MissingOptionalSectionsAreWarningsMissingMandatoryObjectsErrors) {
  const Description ok = read(kMinimal);
  EXPECT_FALSE(ok.has_errors());
  // kMinimal's 23 lines: [1000] 1..5, [1001] 6..9, [1018] 10..13, [1018sub0] 14..18, [1018sub1] 19..23.
  // No [DeviceInfo] (line 0) and three objects in no object list (lines 1, 6, 10).
  ASSERT_EQ(ok.diagnostics.size(), 4u) << ::testing::PrintToString(messages(ok));
  EXPECT_EQ(ok.diagnostics[0].line, 0);
  EXPECT_EQ(ok.diagnostics[1].line, 1);
  EXPECT_EQ(ok.diagnostics[2].line, 6);
  EXPECT_EQ(ok.diagnostics[3].line, 10);

  std::string no_identity(kMinimal);
  no_identity.erase(no_identity.find("[1018]"));
  for (const bool strict : {false, true}) {
    const Description d = read(no_identity, strict);
    EXPECT_TRUE(d.has_errors());
    ASSERT_GE(d.diagnostics.size(), 2u);  // after "no [DeviceInfo]", also about the whole file
    EXPECT_EQ(format(d.file, d.diagnostics[1]),
              "t.eds: error: mandatory object 0x1018 (identity object) is missing (CiA 301)");
  }
}

TEST(EdsReader, NumbersAsCia306WritesThem) {
  const auto value = [](const std::string& type, const std::string& text) {
    const Description d = read(std::string(kMinimal) + "[2000]\nParameterName=x\nDataType=" + type +
                               "\nAccessType=rw\nDefaultValue=" + text + "\n");
    const Entry* e = d.entry(0x2000, 0);
    return std::make_pair(e == nullptr ? Value{} : e->default_value, messages(d));
  };
  EXPECT_EQ(uint_of(value("0x0007", "0x1F").first), 31u);
  EXPECT_EQ(uint_of(value("0x0007", "017").first), 15u);  // octal
  EXPECT_EQ(uint_of(value("0x0007", "0").first), 0u);
  EXPECT_EQ(uint_of(value("0x0007", "4294967295").first), 4294967295u);
  EXPECT_EQ(int_of(value("0x0002", "-128").first), -128);
  EXPECT_EQ(int_of(value("0x0002", "0x80").first), -128);
  EXPECT_EQ(int_of(value("0x0003", "0xFFFF").first), -1);
  EXPECT_EQ(int_of(value("0x0015", "-9223372036854775808").first), std::numeric_limits<std::int64_t>::min());
  EXPECT_EQ(uint_of(value("0x001B", "0xFFFFFFFFFFFFFFFF").first), ~std::uint64_t{0});
  EXPECT_EQ(std::get<double>(value("0x0008", "1.5").first.v), 1.5);
  EXPECT_EQ(std::get<std::string>(value("0x0009", "AX 400").first.v), "AX 400");
  // $NODEID forms, in any case and spacing.
  const Value a = value("0x0007", "$NodeId + 0x180").first;
  EXPECT_TRUE(a.plus_node_id);
  EXPECT_EQ(a.bits(0x7F, DataType::kUnsigned32), 0x1FFu);
  EXPECT_EQ(value("0x0007", "$NODEID").first.bits(9, DataType::kUnsigned32), 9u);
  // Out of range or malformed: a warning naming the key, the value kept empty.
  for (const auto& [type, text] :
       std::vector<std::pair<std::string, std::string>>{{"0x0002", "128"},
                                                        {"0x0005", "256"},
                                                        {"0x0005", "-1"},
                                                        {"0x0007", "09"},
                                                        {"0x0007", "0x"},
                                                        {"0x0007", "12abc"},
                                                        {"0x0007", "$NODEID-1"},
                                                        {"0x0007", "$NODEID+$NODEID"},
                                                        {"0x0005", "$NODEID+0x81"},
                                                        {"0x0008", "nan"},
                                                        {"0x0007", "99999999999999999999999"}}) {
    const auto [v, m] = value(type, text);
    EXPECT_TRUE(v.empty()) << text;
    const bool named = std::any_of(m.begin(), m.end(), [&](const std::string& s) {
      return s.find("DefaultValue = \"" + text + "\" is not a") != std::string::npos &&
             s.find("t.eds:28:") == 0;
    });
    EXPECT_TRUE(named) << text << " " << ::testing::PrintToString(m);
  }
}

TEST(EdsReader, BrokenLinesAreNamedAndNonStrictSkipsWhatItCannotRead) {
  const std::string text =
      std::string(kMinimal) +
      "# a shell comment\n"                                                      // 24
      "[2000]\nParameterName=bad type\nDataType=word\nAccessType=rw\n"           // 25..28
      "[2001]\nParameterName=bad access\nDataType=7\nAccessType=readonly\n"      // 29..32
      "[2002]\nParameterName=twice\nDataType=7\nAccessType=ro\nAccessType=rw\n"  // 33..37
      "[2003sub1]\nParameterName=orphan\n"                                       // 38..39
      "just text\n"                                                              // 40
      "[2004\n";                                                                 // 41
  const Description d = read(text);
  const std::vector<std::string> m = messages(d);
  const auto has = [&](const std::string& s) {
    return std::any_of(m.begin(), m.end(), [&](const std::string& x) { return x.find(s) == 0; });
  };
  EXPECT_TRUE(has("t.eds:24: warning: comment starting with '#'")) << ::testing::PrintToString(m);
  EXPECT_TRUE(has("t.eds:27: warning: 0x2000: DataType = \"word\" is not a number: skipped"));
  EXPECT_TRUE(
      has("t.eds:32: warning: 0x2001: AccessType = \"readonly\" is none of ro, wo, rw, rwr, rww, const"));
  EXPECT_TRUE(has("t.eds:37: warning: key AccessType again in [2002] (first at line 36)"));
  EXPECT_TRUE(has("t.eds:38: warning: [2003sub1] has no object section [2003]"));
  EXPECT_TRUE(has("t.eds:40: warning: \"just text\" is neither a section"));
  EXPECT_TRUE(has("t.eds:41: error: section header \"[2004\" has no closing ']'"));
  EXPECT_EQ(d.object(0x2000), nullptr);
  EXPECT_EQ(d.object(0x2001), nullptr);
  EXPECT_EQ(d.entry(0x2002, 0)->access, Access::kRo);  // the first wins
}

TEST(EdsReader, SubNumberMismatchAndADcfsCommissioningAndParameterValues) {
  const std::string text = std::string(kMinimal) +
                           "[DeviceComissioning]\nNodeID=0x0A\nBaudrate=500\nNodeName=crank\n"  // 24..27
                           "[1017]\nParameterName=hb\nDataType=6\nAccessType=rw\nDefaultValue=0\n"
                           "ParameterValue=100\n"                                         // 28..33
                           "[1016]\nParameterName=consumer\nObjectType=8\nSubNumber=3\n"  // 34..37
                           "[1016sub0]\nParameterName=n\nDataType=5\nAccessType=ro\nDefaultValue=1\n"
                           "[1016sub1]\nParameterName=c1\nDataType=7\nAccessType=rw\nDefaultValue=0\n";
  const Description d = read(text);
  EXPECT_FALSE(d.has_errors());
  EXPECT_EQ(d.commissioning.node_id, 10);
  EXPECT_EQ(d.commissioning.baud_rate_kbit, 500u);
  EXPECT_EQ(d.commissioning.node_name, "crank");
  const Entry* hb = d.entry(0x1017, 0);
  EXPECT_EQ(uint_of(hb->value()), 100u);  // ParameterValue over DefaultValue
  EXPECT_EQ(hb->value_line(), 33);
  const std::vector<std::string> m = messages(d);
  EXPECT_NE(std::find(m.begin(), m.end(),
                      "t.eds:37: warning: 0x1016: SubNumber = 3 but 2 sub-index sections follow"),
            m.end())
      << ::testing::PrintToString(m);
}

TEST(EdsReader, AnUnreadableFileIsOneError) {
  const Description d = read_eds_file(path_of("no_such_file.eds"));
  ASSERT_EQ(d.diagnostics.size(), 1u);
  EXPECT_TRUE(d.has_errors());
  EXPECT_EQ(format(d.file, d.diagnostics[0]), path_of("no_such_file.eds") + ": error: cannot open the file");
}

}  // namespace
}  // namespace loom::drivers::eds
