// A CANopen device description (CiA 306 electronic data sheet, INI form) as plain data: the EDS a
// drive or I/O module ships with, or a DCF (the same form with the values a node is configured to).
// read_eds() is tolerant of what vendors really ship — decimal, hex and octal numbers, `$NODEID+`
// expressions, CompactSubObj arrays, ObjectLinks, DummyUsage, comments (also after a value), missing
// optional sections, object lists whose SupportedObjects count is wrong — and says every deviation as a
// diagnostic naming file:line. Non-strict (the default: the files vendors ship) skips what it cannot read
// with a warning; strict (a file the builder writes, or a tool's output) makes every warning an error.
// A missing mandatory object (0x1000, 0x1001, 0x1018) or an unusable section is an error in both modes.
// Configure-time only (strings, maps); no SocketCAN.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

namespace loom::drivers::eds {

// CiA 301 basic data types (the DataType key's values).
enum class DataType : std::uint16_t {
  kBoolean = 0x0001,
  kInteger8 = 0x0002,
  kInteger16 = 0x0003,
  kInteger32 = 0x0004,
  kUnsigned8 = 0x0005,
  kUnsigned16 = 0x0006,
  kUnsigned32 = 0x0007,
  kReal32 = 0x0008,
  kVisibleString = 0x0009,
  kOctetString = 0x000A,
  kUnicodeString = 0x000B,
  kTimeOfDay = 0x000C,
  kTimeDifference = 0x000D,
  kDomain = 0x000F,
  kInteger24 = 0x0010,
  kReal64 = 0x0011,
  kInteger40 = 0x0012,
  kInteger48 = 0x0013,
  kInteger56 = 0x0014,
  kInteger64 = 0x0015,
  kUnsigned24 = 0x0016,
  kUnsigned40 = 0x0018,
  kUnsigned48 = 0x0019,
  kUnsigned56 = 0x001A,
  kUnsigned64 = 0x001B,
};
// "UNSIGNED16", or "DataType 0x0023" for one this reader does not know.
std::string type_name(DataType t);
// Bits of a value of this type (0 for strings, domains and unknown types).
unsigned type_bits(DataType t);
bool is_signed_integer(DataType t);
bool is_unsigned_integer(DataType t);  // BOOLEAN counts as unsigned (0/1)
bool is_real(DataType t);

// CiA 306 ObjectType key.
enum class ObjectType : std::uint8_t {
  kNull = 0,
  kDomain = 2,
  kDeftype = 5,
  kDefstruct = 6,
  kVar = 7,
  kArray = 8,
  kRecord = 9
};

// CiA 306 AccessType key.
enum class Access : std::uint8_t { kRo, kWo, kRw, kRwr, kRww, kConst };
const char* access_name(Access a);  // "ro", "rww", ...
inline bool readable(Access a) {
  return a != Access::kWo;
}
inline bool writable(Access a) {
  return a == Access::kWo || a == Access::kRw || a == Access::kRwr || a == Access::kRww;
}

// A DefaultValue, ParameterValue, LowLimit or HighLimit read for its entry's DataType. Integers are kept
// as written (signed types as int64, unsigned as uint64; a hex or octal value of a signed type is its bit
// pattern, so 0xFF of an INTEGER8 is −1), reals as double, strings as text. `plus_node_id` = the value was
// "$NODEID+n": the number is n, the node's id is added when the value is resolved.
struct Value {
  std::variant<std::monostate, std::int64_t, std::uint64_t, double, std::string> v;
  bool plus_node_id = false;
  std::string text;  // as written (for messages)

  bool empty() const { return std::holds_alternative<std::monostate>(v); }
  // The raw bits an SDO write of this value carries (little-endian, type_bits() wide) for a node id;
  // nullopt for strings, reals written as text and empty values.
  std::optional<std::uint64_t> bits(std::uint8_t node_id, DataType type) const;
};

// A line of the file, for messages ("vendor.eds:123").
struct Where {
  int line = 0;  // 1-based; 0 = not in the file (a default of the standard)
};

// One sub-index (or a VAR object as sub 0).
struct Entry {
  std::uint16_t index = 0;
  std::uint8_t sub = 0;
  std::string name;
  DataType type = DataType::kUnsigned8;
  Access access = Access::kRo;
  bool pdo_mapping = false;
  Value low_limit, high_limit, default_value, parameter_value;
  // Lines of the section and of its keys (0 = key absent).
  int line = 0;
  int type_line = 0, access_line = 0, pdo_line = 0, default_line = 0, parameter_line = 0, low_line = 0,
      high_line = 0;
  // The value the node is configured to: ParameterValue when given (a DCF), else DefaultValue.
  const Value& value() const { return parameter_value.empty() ? default_value : parameter_value; }
  int value_line() const { return parameter_value.empty() ? default_line : parameter_line; }
};

struct Object {
  std::uint16_t index = 0;
  std::string name;
  ObjectType type = ObjectType::kVar;
  int line = 0;
  std::uint8_t sub_number = 0;       // SubNumber as written (0 for a VAR)
  std::uint8_t compact_sub_obj = 0;  // CompactSubObj: subs 1..n generated from the object's own keys
  std::vector<std::uint16_t> object_links;
  std::map<std::uint8_t, Entry> entries;  // a VAR's one entry is sub 0
  const Entry* entry(std::uint8_t sub) const;
};

struct DeviceInfo {
  int line = 0;  // of [DeviceInfo]; 0 = section absent
  std::string vendor_name, product_name, order_code;
  std::optional<std::uint32_t> vendor_number, product_number, revision_number;
  int vendor_line = 0, product_line = 0, revision_line = 0;
  std::uint8_t granularity = 8;  // PDO mapping granularity in bits (0 = no mapping can be changed)
  std::uint16_t nr_of_rxpdo = 0, nr_of_txpdo = 0;
  int rxpdo_line = 0, txpdo_line = 0;
  bool lss_supported = false;
  std::vector<std::uint32_t> baud_rates_kbit;  // the BaudRate_n=1 keys
};

// [DeviceComissioning] of a DCF (sic: CiA 306's spelling).
struct Commissioning {
  int line = 0;  // 0 = section absent (an EDS)
  std::uint8_t node_id = 0;
  std::uint32_t baud_rate_kbit = 0;
  std::string node_name;
};

enum class Severity : std::uint8_t { kWarning, kError };

struct Diagnostic {
  Severity severity = Severity::kWarning;
  int line = 0;  // 0 = about the whole file
  std::string message;
};
// "vendor.eds:12: warning: ..." (or "vendor.eds: error: ..." for line 0).
std::string format(const std::string& file, const Diagnostic& d);

struct Description {
  std::string file;  // as given to read_eds(), for messages
  DeviceInfo device;
  Commissioning commissioning;
  std::map<std::uint16_t, bool> dummy_usage;  // 0x0001..0x0007 → may be mapped as a gap
  std::map<std::uint16_t, Object> objects;
  std::vector<Diagnostic> diagnostics;

  const Object* object(std::uint16_t index) const;
  const Entry* entry(std::uint16_t index, std::uint8_t sub) const;
  // "vendor.eds:123".
  std::string at(int line) const;
  bool has_errors() const;
};

struct ReadOptions {
  bool strict = false;  // every warning of a non-strict read is an error
};

// Configure-time only. Reads `text` (the file's contents; `file` names it in messages). Never throws for
// any input; the description holds every diagnostic, and has_errors() says whether it may be used.
Description read_eds(std::string_view text, std::string file, ReadOptions options = {});
// Configure-time only. The same from a file on disk (an unreadable file is one error diagnostic).
Description read_eds_file(const std::string& path, ReadOptions options = {});

// Whether a PDO's mapping can be written (CiA 301: the mapping object's sub 0 and entries writable).
enum class MappingKind : std::uint8_t { kAbsent, kFixed, kDynamic };
const char* mapping_kind_name(MappingKind k);  // "absent", "fixed", "dynamic"

struct MapEntry {
  std::uint16_t index = 0;
  std::uint8_t sub = 0;
  std::uint8_t bits = 0;
};
struct PdoDescription {
  bool receive = false;  // RPDO (0x14xx/0x16xx) or TPDO (0x18xx/0x1Axx)
  int number = 1;        // 1-based
  MappingKind kind = MappingKind::kAbsent;
  int line = 0;  // the mapping object's section (or the communication object's when no mapping)
  // The mapping the description gives (DefaultValue, or ParameterValue of a DCF), as the node starts.
  std::vector<MapEntry> mapping;
  std::optional<std::uint8_t> transmission_type;  // 0x14xx/0x18xx:02 value
  bool transmission_type_writable = false;
  bool cob_id_writable = false;
};
// Configure-time only. Every PDO the description has (a communication object 0x1400+n / 0x1800+n),
// in order, RPDOs first.
std::vector<PdoDescription> pdos(const Description& d);

}  // namespace loom::drivers::eds
