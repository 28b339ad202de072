// CiA 306 EDS/DCF reader: first the INI layer (sections, keys, lines, comments), then the objects, the
// device information and the object lists read from it, each deviation a diagnostic with its line.
#include "loom/drivers/eds.hpp"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>

namespace loom::drivers::eds {

std::string type_name(DataType t) {
  switch (t) {
    case DataType::kBoolean:
      return "BOOLEAN";
    case DataType::kInteger8:
      return "INTEGER8";
    case DataType::kInteger16:
      return "INTEGER16";
    case DataType::kInteger32:
      return "INTEGER32";
    case DataType::kUnsigned8:
      return "UNSIGNED8";
    case DataType::kUnsigned16:
      return "UNSIGNED16";
    case DataType::kUnsigned32:
      return "UNSIGNED32";
    case DataType::kReal32:
      return "REAL32";
    case DataType::kVisibleString:
      return "VISIBLE_STRING";
    case DataType::kOctetString:
      return "OCTET_STRING";
    case DataType::kUnicodeString:
      return "UNICODE_STRING";
    case DataType::kTimeOfDay:
      return "TIME_OF_DAY";
    case DataType::kTimeDifference:
      return "TIME_DIFFERENCE";
    case DataType::kDomain:
      return "DOMAIN";
    case DataType::kInteger24:
      return "INTEGER24";
    case DataType::kReal64:
      return "REAL64";
    case DataType::kInteger40:
      return "INTEGER40";
    case DataType::kInteger48:
      return "INTEGER48";
    case DataType::kInteger56:
      return "INTEGER56";
    case DataType::kInteger64:
      return "INTEGER64";
    case DataType::kUnsigned24:
      return "UNSIGNED24";
    case DataType::kUnsigned40:
      return "UNSIGNED40";
    case DataType::kUnsigned48:
      return "UNSIGNED48";
    case DataType::kUnsigned56:
      return "UNSIGNED56";
    case DataType::kUnsigned64:
      return "UNSIGNED64";
  }
  char buf[24];
  std::snprintf(buf, sizeof buf, "DataType 0x%04X", static_cast<unsigned>(t));
  return buf;
}

unsigned type_bits(DataType t) {
  switch (t) {
    case DataType::kBoolean:
      return 1;
    case DataType::kInteger8:
    case DataType::kUnsigned8:
      return 8;
    case DataType::kInteger16:
    case DataType::kUnsigned16:
      return 16;
    case DataType::kInteger24:
    case DataType::kUnsigned24:
      return 24;
    case DataType::kInteger32:
    case DataType::kUnsigned32:
    case DataType::kReal32:
      return 32;
    case DataType::kInteger40:
    case DataType::kUnsigned40:
      return 40;
    case DataType::kInteger48:
    case DataType::kUnsigned48:
      return 48;
    case DataType::kInteger56:
    case DataType::kUnsigned56:
      return 56;
    case DataType::kInteger64:
    case DataType::kUnsigned64:
    case DataType::kReal64:
      return 64;
    default:
      return 0;
  }
}

bool is_signed_integer(DataType t) {
  switch (t) {
    case DataType::kInteger8:
    case DataType::kInteger16:
    case DataType::kInteger24:
    case DataType::kInteger32:
    case DataType::kInteger40:
    case DataType::kInteger48:
    case DataType::kInteger56:
    case DataType::kInteger64:
      return true;
    default:
      return false;
  }
}

bool is_unsigned_integer(DataType t) {
  switch (t) {
    case DataType::kBoolean:
    case DataType::kUnsigned8:
    case DataType::kUnsigned16:
    case DataType::kUnsigned24:
    case DataType::kUnsigned32:
    case DataType::kUnsigned40:
    case DataType::kUnsigned48:
    case DataType::kUnsigned56:
    case DataType::kUnsigned64:
      return true;
    default:
      return false;
  }
}

bool is_real(DataType t) {
  return t == DataType::kReal32 || t == DataType::kReal64;
}

const char* access_name(Access a) {
  switch (a) {
    case Access::kRo:
      return "ro";
    case Access::kWo:
      return "wo";
    case Access::kRw:
      return "rw";
    case Access::kRwr:
      return "rwr";
    case Access::kRww:
      return "rww";
    case Access::kConst:
      return "const";
  }
  return "?";
}

const char* mapping_kind_name(MappingKind k) {
  switch (k) {
    case MappingKind::kAbsent:
      return "absent";
    case MappingKind::kFixed:
      return "fixed";
    case MappingKind::kDynamic:
      return "dynamic";
  }
  return "?";
}

namespace {

std::uint64_t mask_of(unsigned bits) {
  return bits >= 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << bits) - 1;
}

}  // namespace

std::optional<std::uint64_t> Value::bits(std::uint8_t node_id, DataType type) const {
  const unsigned width = type_bits(type);
  const std::uint64_t add = plus_node_id ? node_id : 0;
  if (const auto* i = std::get_if<std::int64_t>(&v))
    return (static_cast<std::uint64_t>(*i) + add) & mask_of(width);
  if (const auto* u = std::get_if<std::uint64_t>(&v)) return (*u + add) & mask_of(width);
  if (const auto* d = std::get_if<double>(&v)) {
    if (type == DataType::kReal32) {
      const float f = static_cast<float>(*d);
      std::uint32_t b = 0;
      std::memcpy(&b, &f, sizeof b);
      return b;
    }
    std::uint64_t b = 0;
    std::memcpy(&b, d, sizeof b);
    return b;
  }
  return std::nullopt;
}

const Entry* Object::entry(std::uint8_t sub) const {
  const auto it = entries.find(sub);
  return it == entries.end() ? nullptr : &it->second;
}

const Object* Description::object(std::uint16_t index) const {
  const auto it = objects.find(index);
  return it == objects.end() ? nullptr : &it->second;
}

const Entry* Description::entry(std::uint16_t index, std::uint8_t sub) const {
  const Object* o = object(index);
  return o == nullptr ? nullptr : o->entry(sub);
}

std::string Description::at(int line) const {
  return line > 0 ? file + ":" + std::to_string(line) : file;
}

bool Description::has_errors() const {
  return std::any_of(diagnostics.begin(), diagnostics.end(),
                     [](const Diagnostic& d) { return d.severity == Severity::kError; });
}

std::string format(const std::string& file, const Diagnostic& d) {
  return (d.line > 0 ? file + ":" + std::to_string(d.line) : file) +
         (d.severity == Severity::kError ? ": error: " : ": warning: ") + d.message;
}

namespace {

// ---- the INI layer -------------------------------------------------------------------------------

struct Key {
  std::string name;  // upper case
  std::string written;
  std::string value;
  int line = 0;
};
struct Section {
  std::string name;  // upper case
  std::string written;
  int line = 0;
  std::vector<Key> keys;
  const Key* find(const std::string& upper) const {
    for (const Key& k : keys) {
      if (k.name == upper) return &k;
    }
    return nullptr;
  }
};

std::string upper(std::string_view s) {
  std::string out(s);
  for (char& c : out) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return out;
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.front()))) s.remove_prefix(1);
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.remove_suffix(1);
  return s;
}

// A value shown in a message: at most 40 characters, control characters escaped.
std::string shown(std::string_view s) {
  std::string out;
  for (const char c : s.substr(0, 40)) {
    if (std::isprint(static_cast<unsigned char>(c))) {
      out += c;
    } else {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\x%02X", static_cast<unsigned char>(c));
      out += buf;
    }
  }
  if (s.size() > 40) out += "...";
  return out;
}

class Reader {
 public:
  Reader(std::string file, ReadOptions options) : options_(options) { d_.file = std::move(file); }

  Description read(std::string_view text) {
    split(text);
    read_device_info();
    read_commissioning();
    read_dummy_usage();
    read_objects();
    read_object_lists();
    check_mandatory();
    check_pdo_counts();
    // In file order (the INI layer's findings were made in a first pass); whole-file ones first.
    std::stable_sort(d_.diagnostics.begin(), d_.diagnostics.end(),
                     [](const Diagnostic& a, const Diagnostic& b) { return a.line < b.line; });
    return std::move(d_);
  }

 private:
  void warn(int line, std::string message) {
    d_.diagnostics.push_back(
        {options_.strict ? Severity::kError : Severity::kWarning, line, std::move(message)});
  }
  void error(int line, std::string message) {
    d_.diagnostics.push_back({Severity::kError, line, std::move(message)});
  }

  void split(std::string_view text) {
    if (text.substr(0, 3) == "\xEF\xBB\xBF") text.remove_prefix(3);  // a UTF-8 byte order mark
    int line = 0;
    Section* current = nullptr;
    bool warned_inline = false;
    while (!text.empty()) {
      ++line;
      const std::size_t nl = text.find('\n');
      std::string_view raw = text.substr(0, nl);
      text.remove_prefix(nl == std::string_view::npos ? text.size() : nl + 1);
      const std::string_view s = trim(raw);
      if (s.empty() || s.front() == ';') continue;
      if (s.front() == '#' || s.substr(0, 2) == "//") {
        warn(line, "comment starting with '" + std::string(s.substr(0, s.front() == '#' ? 1 : 2)) +
                       "' (CiA 306 comments start with ';'): ignored");
        continue;
      }
      if (s.front() == '[') {
        const std::size_t close = s.find(']');
        if (close == std::string_view::npos) {
          error(line, "section header \"" + shown(s) + "\" has no closing ']'");
          current = nullptr;
          continue;
        }
        const std::string_view after = trim(s.substr(close + 1));
        if (!after.empty() && after.front() != ';') warn(line, "text after the section header ignored");
        const std::string written(trim(s.substr(1, close - 1)));
        const std::string name = upper(written);
        if (const auto it = index_.find(name); it != index_.end()) {
          warn(line, "section [" + shown(written) + "] again (first at line " +
                         std::to_string(sections_[it->second].line) + "): this one is ignored");
          current = nullptr;
          continue;
        }
        index_[name] = sections_.size();
        sections_.push_back(Section{name, written, line, {}});
        current = &sections_.back();
        continue;
      }
      const std::size_t eq = s.find('=');
      if (eq == std::string_view::npos) {
        warn(line, "\"" + shown(s) + "\" is neither a section, a key=value nor a comment: ignored");
        continue;
      }
      if (current == nullptr) {
        warn(line, "key outside any section ignored");
        continue;
      }
      const std::string written_key(trim(s.substr(0, eq)));
      std::string key = upper(written_key);
      std::string_view value = trim(s.substr(eq + 1));
      // An inline comment ("PDOMapping=1 ; yes"), as many vendor tools write them; [Comments] lines
      // and names are text and keep theirs.
      const std::string& in = current->name;
      const bool text_key = in == "COMMENTS" || in == "FILEINFO" ||
                            (in.size() > 4 && in.compare(in.size() - 4, 4, "NAME") == 0) ||
                            key.find("NAME") != std::string::npos || key == "DENOTATION" ||
                            key == "ORDERCODE";
      if (!text_key) {
        if (const std::size_t semi = value.find(';'); semi != std::string_view::npos) {
          value = trim(value.substr(0, semi));
          if (!warned_inline) {
            warn(line, "comment after a value (CiA 306 comments are whole lines): the value is \"" +
                           shown(value) + "\"; further ones are not reported");
            warned_inline = true;
          }
        }
      }
      if (key.empty()) {
        warn(line, "key=value line without a key ignored");
        continue;
      }
      if (const Key* k = current->find(key)) {
        warn(line, "key " + shown(written_key) + " again in [" + shown(current->written) +
                       "] (first at line " + std::to_string(k->line) + "): this one is ignored");
        continue;
      }
      current->keys.push_back(Key{std::move(key), written_key, std::string(value), line});
    }
  }

  const Section* section(const std::string& upper_name) const {
    const auto it = index_.find(upper_name);
    return it == index_.end() ? nullptr : &sections_[it->second];
  }

  // ---- numbers and values --------------------------------------------------------------------------

  // An integer as CiA 306 writes them: decimal, 0x hex, or octal with a leading 0; an optional sign.
  // Returns false (and why) for anything else or an overflow of 64 bits.
  static bool parse_integer(std::string_view s, bool& negative, std::uint64_t& magnitude, bool& bit_pattern,
                            std::string& why) {
    s = trim(s);
    negative = false;
    bit_pattern = false;
    if (!s.empty() && (s.front() == '-' || s.front() == '+')) {
      negative = s.front() == '-';
      s.remove_prefix(1);
      s = trim(s);
    }
    unsigned base = 10;
    if (s.size() > 2 && s[0] == '0' && (s[1] == 'x' || s[1] == 'X')) {
      base = 16;
      s.remove_prefix(2);
      bit_pattern = true;
    } else if (s.size() > 1 && s[0] == '0') {
      base = 8;
      s.remove_prefix(1);
      bit_pattern = true;
    }
    if (s.empty()) {
      why = "no digits";
      return false;
    }
    magnitude = 0;
    for (const char c : s) {
      unsigned digit = 0;
      if (c >= '0' && c <= '9') {
        digit = static_cast<unsigned>(c - '0');
      } else if (c >= 'a' && c <= 'f') {
        digit = static_cast<unsigned>(c - 'a' + 10);
      } else if (c >= 'A' && c <= 'F') {
        digit = static_cast<unsigned>(c - 'A' + 10);
      } else {
        digit = 99;
      }
      if (digit >= base) {
        why = base == 8 ? "not an octal number (a leading 0 means octal)" : "not a number";
        return false;
      }
      if (magnitude > (std::numeric_limits<std::uint64_t>::max() - digit) / base) {
        why = "more than 64 bits";
        return false;
      }
      magnitude = magnitude * base + digit;
    }
    return true;
  }

  // An unsigned key (DataType, SubNumber, NrOfRXPDO, ...), at most `max`.
  static std::optional<std::uint64_t> parse_unsigned(std::string_view s, std::uint64_t max) {
    bool negative = false, pattern = false;
    std::uint64_t m = 0;
    std::string why;
    if (!parse_integer(s, negative, m, pattern, why) || negative || m > max) return std::nullopt;
    return m;
  }

  // A value of `type` ("" = empty). False with the reason when it cannot be one.
  static bool parse_value(std::string_view text, DataType type, Value& out, std::string& why) {
    out = Value{};
    out.text = std::string(text);
    text = trim(text);
    if (text.empty()) return true;
    if (is_signed_integer(type) || is_unsigned_integer(type)) {
      std::string_view number = text;
      // "$NODEID", "$NODEID+n", "n+$NODEID" (case as written varies: $NodeId).
      const std::string up = upper(text);
      if (const std::size_t at = up.find("$NODEID"); at != std::string::npos) {
        out.plus_node_id = true;
        std::string_view before = trim(text.substr(0, at));
        std::string_view after = trim(text.substr(at + 7));
        if (!before.empty() && !after.empty()) {
          why = "$NODEID between two terms";
          return false;
        }
        if (!before.empty()) {
          if (before.back() != '+') {
            why = "only \"n+$NODEID\" or \"$NODEID+n\" is an expression";
            return false;
          }
          number = trim(before.substr(0, before.size() - 1));
        } else if (!after.empty()) {
          if (after.front() != '+') {
            why = "only \"$NODEID+n\" or \"n+$NODEID\" is an expression";
            return false;
          }
          number = trim(after.substr(1));
        } else {
          number = "0";
        }
        if (number.find('$') != std::string_view::npos) {
          why = "$NODEID twice";
          return false;
        }
      }
      bool negative = false, pattern = false;
      std::uint64_t m = 0;
      if (!parse_integer(number, negative, m, pattern, why)) return false;
      const unsigned width = type_bits(type);
      if (is_unsigned_integer(type)) {
        if (negative && m != 0) {
          why = "negative for an unsigned type";
          return false;
        }
        if (m > mask_of(width) || (out.plus_node_id && m + 127 > mask_of(width))) {
          why = "out of range of " + type_name(type);
          return false;
        }
        out.v = m;
        return true;
      }
      const std::uint64_t max_pos = mask_of(width - 1);
      std::int64_t value = 0;
      if (pattern && !negative) {
        // A hex or octal signed value is its bit pattern (0xFF of an INTEGER8 is -1).
        if (m > mask_of(width)) {
          why = "out of range of " + type_name(type);
          return false;
        }
        const std::uint64_t sign = std::uint64_t{1} << (width - 1);
        value = static_cast<std::int64_t>((m & sign) != 0 ? (m | ~mask_of(width)) : m);  // sign-extended
      } else if (negative) {
        if (m > max_pos + 1) {
          why = "out of range of " + type_name(type);
          return false;
        }
        value = m == max_pos + 1 ? -static_cast<std::int64_t>(max_pos) - 1 : -static_cast<std::int64_t>(m);
      } else {
        if (m > max_pos) {
          why = "out of range of " + type_name(type);
          return false;
        }
        value = static_cast<std::int64_t>(m);
      }
      out.v = value;
      return true;
    }
    if (is_real(type)) {
      const std::string copy(text);
      char* end = nullptr;
      errno = 0;
      const double d = std::strtod(copy.c_str(), &end);
      if (end != copy.c_str() + copy.size() || !std::isfinite(d) || errno == ERANGE) {
        why = "not a finite number";
        return false;
      }
      if (type == DataType::kReal32 && std::fabs(d) > std::numeric_limits<float>::max()) {
        why = "out of range of REAL32";
        return false;
      }
      out.v = d;
      return true;
    }
    out.v = std::string(text);
    return true;
  }

  // -1: a < b, 0, 1; nullopt when they cannot be compared (strings, $NODEID, empty).
  static std::optional<int> compare(const Value& a, const Value& b) {
    if (a.plus_node_id || b.plus_node_id) return std::nullopt;
    const auto as_long_double = [](const Value& x) -> std::optional<long double> {
      if (const auto* i = std::get_if<std::int64_t>(&x.v)) return static_cast<long double>(*i);
      if (const auto* u = std::get_if<std::uint64_t>(&x.v)) return static_cast<long double>(*u);
      if (const auto* d = std::get_if<double>(&x.v)) return static_cast<long double>(*d);
      return std::nullopt;
    };
    const auto x = as_long_double(a), y = as_long_double(b);
    if (!x || !y) return std::nullopt;
    return *x < *y ? -1 : (*x > *y ? 1 : 0);
  }

  // ---- sections ------------------------------------------------------------------------------------

  void read_device_info() {
    const Section* s = section("DEVICEINFO");
    if (s == nullptr) {
      warn(0, "no [DeviceInfo] section: vendor, product and PDO counts unknown");
      return;
    }
    DeviceInfo& di = d_.device;
    di.line = s->line;
    for (const Key& k : s->keys) {
      const auto u32 = [&](std::optional<std::uint32_t>& out, int& line) {
        if (k.value.empty()) return;
        if (const auto v = parse_unsigned(k.value, 0xFFFFFFFFU)) {
          out = static_cast<std::uint32_t>(*v);
          line = k.line;
        } else {
          warn(k.line, k.written + " = \"" + shown(k.value) + "\" is not an UNSIGNED32: ignored");
        }
      };
      const auto u16 = [&](std::uint16_t& out, int& line, std::uint64_t max) {
        if (const auto v = parse_unsigned(k.value, max)) {
          out = static_cast<std::uint16_t>(*v);
          line = k.line;
        } else {
          warn(k.line, k.written + " = \"" + shown(k.value) + "\" is not a number 0.." + std::to_string(max) +
                           ": ignored");
        }
      };
      int unused = 0;
      if (k.name == "VENDORNAME") {
        di.vendor_name = k.value;
      } else if (k.name == "PRODUCTNAME") {
        di.product_name = k.value;
      } else if (k.name == "ORDERCODE") {
        di.order_code = k.value;
      } else if (k.name == "VENDORNUMBER") {
        u32(di.vendor_number, di.vendor_line);
      } else if (k.name == "PRODUCTNUMBER") {
        u32(di.product_number, di.product_line);
      } else if (k.name == "REVISIONNUMBER") {
        u32(di.revision_number, di.revision_line);
      } else if (k.name == "NROFRXPDO") {
        u16(di.nr_of_rxpdo, di.rxpdo_line, 512);
      } else if (k.name == "NROFTXPDO") {
        u16(di.nr_of_txpdo, di.txpdo_line, 512);
      } else if (k.name == "GRANULARITY") {
        std::uint16_t g = 8;
        u16(g, unused, 64);
        di.granularity = static_cast<std::uint8_t>(g);
      } else if (k.name == "LSS_SUPPORTED") {
        di.lss_supported = parse_unsigned(k.value, 1).value_or(0) == 1;
      } else if (k.name.rfind("BAUDRATE_", 0) == 0) {
        const auto rate = parse_unsigned(std::string_view(k.name).substr(9), 1000);
        if (rate && parse_unsigned(k.value, 1).value_or(0) == 1) {
          di.baud_rates_kbit.push_back(static_cast<std::uint32_t>(*rate));
        }
      }
    }
  }

  void read_commissioning() {
    const Section* s = section("DEVICECOMISSIONING");
    if (s == nullptr) s = section("DEVICECOMMISSIONING");  // the common misspelling of the misspelling
    if (s == nullptr) return;
    Commissioning& c = d_.commissioning;
    c.line = s->line;
    for (const Key& k : s->keys) {
      if (k.name == "NODEID") {
        if (const auto v = parse_unsigned(k.value, 127); v && *v >= 1) {
          c.node_id = static_cast<std::uint8_t>(*v);
        } else {
          error(k.line, "NodeID = \"" + shown(k.value) + "\" is not a node id 1..127");
        }
      } else if (k.name == "BAUDRATE") {
        c.baud_rate_kbit = static_cast<std::uint32_t>(parse_unsigned(k.value, 1000).value_or(0));
      } else if (k.name == "NODENAME") {
        c.node_name = k.value;
      }
    }
  }

  void read_dummy_usage() {
    const Section* s = section("DUMMYUSAGE");
    if (s == nullptr) return;
    for (const Key& k : s->keys) {
      // 0 = not a DummyNNNN key (data types 0x0001..0x001F only).
      const std::uint64_t index =
          k.name.rfind("DUMMY", 0) == 0 ? parse_unsigned("0x" + k.name.substr(5), 0xFFFF).value_or(0) : 0;
      const std::uint64_t v = parse_unsigned(k.value, 1).value_or(2);
      if (index < 1 || index > 0x1F || v > 1) {
        warn(k.line, k.written + " = \"" + shown(k.value) + "\" is not DummyNNNN=0|1: ignored");
        continue;
      }
      d_.dummy_usage[static_cast<std::uint16_t>(index)] = v == 1;
    }
  }

  // "1018" → 0x1018; "1018SUB2" → (0x1018, 2) etc. Section names are upper case here.
  static bool hex4(std::string_view s, std::uint16_t& out) {
    if (s.size() != 4) return false;
    const auto v = parse_unsigned("0x" + std::string(s), 0xFFFF);
    if (!v) return false;
    out = static_cast<std::uint16_t>(*v);
    return true;
  }

  // The keys of one entry (a VAR object's section, a sub-section, or a CompactSubObj array's section).
  bool read_entry(const Section& s, Entry& e, const std::string& what) {
    e.line = s.line;
    if (const Key* k = s.find("PARAMETERNAME")) e.name = k->value;
    const Key* type = s.find("DATATYPE");
    const Key* access = s.find("ACCESSTYPE");
    if (type == nullptr) {
      warn(s.line, what + " has no DataType: skipped");
      return false;
    }
    const auto t = parse_unsigned(type->value, 0xFFFF);
    if (!t) {
      warn(type->line, what + ": DataType = \"" + shown(type->value) + "\" is not a number: skipped");
      return false;
    }
    e.type = static_cast<DataType>(*t);
    e.type_line = type->line;
    if (type_bits(e.type) == 0 && !(*t >= 0x9 && *t <= 0xF)) {
      warn(type->line,
           what + ": DataType " + type_name(e.type) + " is not a CiA 301 basic type: read as text");
    }
    if (access == nullptr) {
      warn(s.line, what + " has no AccessType: skipped");
      return false;
    }
    const std::string a = upper(access->value);
    static const std::pair<const char*, Access> kAccess[] = {
        {"RO", Access::kRo},   {"WO", Access::kWo},   {"RW", Access::kRw},
        {"RWR", Access::kRwr}, {"RWW", Access::kRww}, {"CONST", Access::kConst}};
    bool known = false;
    for (const auto& [name, value] : kAccess) {
      if (a == name) {
        e.access = value;
        known = true;
      }
    }
    if (!known) {
      warn(access->line, what + ": AccessType = \"" + shown(access->value) +
                             "\" is none of ro, wo, rw, rwr, rww, const: skipped");
      return false;
    }
    e.access_line = access->line;
    if (const Key* k = s.find("PDOMAPPING")) {
      const auto v = parse_unsigned(k->value, 1);
      if (!v) {
        warn(k->line, what + ": PDOMapping = \"" + shown(k->value) + "\" is not 0 or 1: taken as 0");
      } else {
        e.pdo_mapping = *v == 1;
      }
      e.pdo_line = k->line;
    }
    read_values(s, e, what);
    return true;
  }

  void read_value(const Key* k, DataType type, Value& out, int& line, const std::string& what) {
    if (k == nullptr) return;
    std::string why;
    Value v;
    if (!parse_value(k->value, type, v, why)) {
      warn(k->line, what + ": " + shown(k->written) + " = \"" + shown(k->value) + "\" is not a " +
                        type_name(type) + " (" + why + "): ignored");
      return;
    }
    out = std::move(v);
    line = k->line;
  }

  void read_values(const Section& s, Entry& e, const std::string& what) {
    read_value(s.find("LOWLIMIT"), e.type, e.low_limit, e.low_line, what);
    read_value(s.find("HIGHLIMIT"), e.type, e.high_limit, e.high_line, what);
    read_value(s.find("DEFAULTVALUE"), e.type, e.default_value, e.default_line, what);
    read_value(s.find("PARAMETERVALUE"), e.type, e.parameter_value, e.parameter_line, what);
    check_limits(e, what);
  }

  void check_limits(const Entry& e, const std::string& what) {
    if (const auto c = compare(e.low_limit, e.high_limit); c && *c > 0) {
      warn(e.low_line, what + ": LowLimit " + e.low_limit.text + " is above HighLimit " + e.high_limit.text);
    }
    const auto outside = [&](const Value& v, int line, const char* key) {
      const auto lo = compare(v, e.low_limit);
      const auto hi = compare(v, e.high_limit);
      if ((lo && *lo < 0) || (hi && *hi > 0)) {
        warn(line, what + ": " + key + " " + shown(v.text) + " is outside LowLimit..HighLimit " +
                       shown(e.low_limit.empty() ? "-" : e.low_limit.text) + ".." +
                       shown(e.high_limit.empty() ? "-" : e.high_limit.text));
      }
    };
    outside(e.default_value, e.default_line, "DefaultValue");
    outside(e.parameter_value, e.parameter_line, "ParameterValue");
  }

  static std::string name_of(std::uint16_t index) {
    char buf[16];
    std::snprintf(buf, sizeof buf, "0x%04X", index);
    return buf;
  }
  static std::string name_of(std::uint16_t index, std::uint8_t sub) {
    char buf[16];
    std::snprintf(buf, sizeof buf, "0x%04X:%02X", index, sub);
    return buf;
  }

  void read_objects() {
    // Sub-sections first, grouped by object, so an object can find its own.
    std::map<std::uint16_t, std::map<std::uint8_t, const Section*>> subs;
    for (const Section& s : sections_) {
      const std::size_t at = s.name.find("SUB");
      std::uint16_t index = 0;
      if (at != 4 || !hex4(std::string_view(s.name).substr(0, 4), index)) continue;
      const std::string_view rest = std::string_view(s.name).substr(7);
      const auto sub =
          rest.empty() || rest.size() > 2 ? std::nullopt : parse_unsigned("0x" + std::string(rest), 0xFF);
      if (!sub) {
        warn(s.line, "[" + shown(s.written) + "] is not a sub-index section [XXXXsubNN]: ignored");
        continue;
      }
      subs[index][static_cast<std::uint8_t>(*sub)] = &s;
    }
    for (const Section& s : sections_) {
      std::uint16_t index = 0;
      if (!hex4(s.name, index)) continue;
      read_object(s, index, subs[index]);
      subs.erase(index);
    }
    for (const auto& [index, by_sub] : subs) {
      for (const auto& [sub, s] : by_sub) {
        warn(s->line,
             "[" + shown(s->written) + "] has no object section [" + name_of(index).substr(2) + "]: ignored");
      }
    }
  }

  void read_object(const Section& s, std::uint16_t index,
                   const std::map<std::uint8_t, const Section*>& subs) {
    Object o;
    o.index = index;
    o.line = s.line;
    const std::string what = name_of(index);
    if (const Key* k = s.find("PARAMETERNAME")) {
      o.name = k->value;
    } else {
      warn(s.line, what + " has no ParameterName");
    }
    if (const Key* k = s.find("OBJECTTYPE")) {
      const auto t = parse_unsigned(k->value, 0xFF);
      static const std::set<std::uint64_t> kKnown{0, 2, 5, 6, 7, 8, 9};
      if (!t || kKnown.count(*t) == 0) {
        warn(k->line, what + ": ObjectType = \"" + shown(k->value) + "\" is none of 0, 2, 5-9: skipped");
        return;
      }
      o.type = static_cast<ObjectType>(*t);
    } else if (!subs.empty()) {
      // Vendors leave ObjectType out of records too; CiA 306's default (VAR) cannot have sub-sections.
      warn(s.line, what + " has no ObjectType but sub-index sections: read as a RECORD");
      o.type = ObjectType::kRecord;
    }
    if (const Section* links = section(name_of(index).substr(2) + "OBJECTLINKS")) read_links(*links, o);

    if (o.type == ObjectType::kVar || o.type == ObjectType::kDomain || o.type == ObjectType::kNull) {
      if (!subs.empty())
        warn(subs.begin()->second->line, what + " is a VAR but has sub-index sections: ignored");
      if (o.type == ObjectType::kDomain && s.find("DATATYPE") == nullptr) {
        Entry e;
        e.index = index;
        e.name = o.name;
        e.type = DataType::kDomain;
        e.line = s.line;
        if (const Key* k = s.find("ACCESSTYPE"))
          e.access = upper(k->value) == "RO" ? Access::kRo : Access::kRw;
        o.entries[0] = std::move(e);
      } else {
        Entry e;
        e.index = index;
        if (!read_entry(s, e, what)) return;
        o.entries[0] = std::move(e);
      }
      d_.objects[index] = std::move(o);
      return;
    }
    if (o.type == ObjectType::kDeftype || o.type == ObjectType::kDefstruct) {
      d_.objects[index] = std::move(o);  // data type definitions: nothing the loom configures
      return;
    }
    // ARRAY or RECORD.
    const Key* number = s.find("SUBNUMBER");
    const Key* compact = s.find("COMPACTSUBOBJ");
    if (number != nullptr) {
      if (const auto n = parse_unsigned(number->value, 0xFF)) {
        o.sub_number = static_cast<std::uint8_t>(*n);
      } else {
        warn(number->line, what + ": SubNumber = \"" + shown(number->value) + "\" is not a number 0..255");
      }
    }
    if (compact != nullptr && parse_unsigned(compact->value, 0xFE).value_or(0) > 0) {
      read_compact(s, o, *compact, what);
    } else {
      if (compact != nullptr && !parse_unsigned(compact->value, 0xFE)) {
        warn(compact->line,
             what + ": CompactSubObj = \"" + shown(compact->value) + "\" is not 0..254: ignored");
      }
      for (const auto& [sub, ss] : subs) {
        Entry e;
        e.index = index;
        e.sub = sub;
        if (read_entry(*ss, e, name_of(index, sub))) o.entries[sub] = std::move(e);
      }
      if (number == nullptr) {
        warn(s.line, what + " is an " + (o.type == ObjectType::kArray ? "ARRAY" : "RECORD") +
                         " without SubNumber (it has " + std::to_string(subs.size()) +
                         " sub-index sections)");
      } else if (o.sub_number != subs.size()) {
        warn(number->line, what + ": SubNumber = " + std::to_string(o.sub_number) + " but " +
                               std::to_string(subs.size()) + " sub-index sections follow");
      }
      if (o.entries.count(0) == 0 && !subs.empty()) {
        warn(s.line, what + " has no sub-index 0 (the number of entries)");
      }
    }
    d_.objects[index] = std::move(o);
  }

  // CompactSubObj=n: sub 0 = n (UNSIGNED8, ro); subs 1..n share the object's DataType, AccessType,
  // PDOMapping, limits and DefaultValue; names from [XXXXName], DCF values from [XXXXValue].
  void read_compact(const Section& s, Object& o, const Key& compact, const std::string& what) {
    const auto n = static_cast<std::uint8_t>(*parse_unsigned(compact.value, 0xFE));
    if (o.type != ObjectType::kArray) warn(compact.line, what + ": CompactSubObj on a non-ARRAY object");
    o.compact_sub_obj = n;
    Entry templ;
    templ.index = o.index;
    if (!read_entry(s, templ, what)) return;
    Entry count;
    count.index = o.index;
    count.name = "Number of entries";
    count.type = DataType::kUnsigned8;
    count.access = Access::kRo;
    count.line = s.line;
    count.default_value.v = std::uint64_t{n};
    count.default_value.text = std::to_string(n);
    count.default_line = compact.line;
    o.entries[0] = std::move(count);
    const Section* names = section(name_of(o.index).substr(2) + "NAME");
    const Section* values = section(name_of(o.index).substr(2) + "VALUE");
    for (unsigned sub = 1; sub <= n; ++sub) {
      Entry e = templ;
      e.sub = static_cast<std::uint8_t>(sub);
      e.name = o.name + std::to_string(sub);
      if (names != nullptr) {
        if (const Key* k = names->find(std::to_string(sub))) e.name = k->value;
      }
      if (values != nullptr) {
        if (const Key* k = values->find(std::to_string(sub))) {
          e.parameter_value = Value{};
          e.parameter_line = 0;
          read_value(k, e.type, e.parameter_value, e.parameter_line, name_of(o.index, e.sub));
        }
      }
      o.entries[e.sub] = std::move(e);
    }
    for (const Section* list : {names, values}) {
      if (list == nullptr) continue;
      for (const Key& k : list->keys) {
        if (k.name == "NROFENTRIES") continue;
        const auto sub = parse_unsigned(k.name, 0xFF);
        if (!sub || *sub < 1 || *sub > n) {
          warn(k.line, "[" + shown(list->written) + "] names sub-index " + shown(k.name) +
                           ", not one of 1.." + std::to_string(n) + " (CompactSubObj): ignored");
        }
      }
    }
  }

  void read_links(const Section& s, Object& o) {
    for (const Key& k : s.keys) {
      if (k.name == "OBJECTLINKS") continue;
      const auto link = parse_unsigned(k.value, 0xFFFF);
      if (!link) {
        warn(k.line, "ObjectLinks: \"" + shown(k.value) + "\" is not an object index: ignored");
        continue;
      }
      o.object_links.push_back(static_cast<std::uint16_t>(*link));
    }
  }

  void read_object_lists() {
    std::set<std::uint16_t> listed;
    for (const char* name : {"MANDATORYOBJECTS", "OPTIONALOBJECTS", "MANUFACTUREROBJECTS"}) {
      const Section* s = section(name);
      if (s == nullptr) continue;
      const Key* count = s->find("SUPPORTEDOBJECTS");
      std::size_t entries = 0;
      for (const Key& k : s->keys) {
        if (k.name == "SUPPORTEDOBJECTS") continue;
        if (!parse_unsigned(k.name, 0xFFFF)) {
          warn(k.line, "[" + s->written + "]: key " + shown(k.name) + " is not a list position: ignored");
          continue;
        }
        ++entries;
        const auto index = parse_unsigned(k.value, 0xFFFF);
        if (!index) {
          warn(k.line, "[" + s->written + "]: \"" + shown(k.value) + "\" is not an object index: ignored");
          continue;
        }
        listed.insert(static_cast<std::uint16_t>(*index));
        if (d_.objects.count(static_cast<std::uint16_t>(*index)) == 0) {
          warn(k.line, "[" + s->written + "] lists " + name_of(static_cast<std::uint16_t>(*index)) +
                           " but the file has no usable section for it");
        }
      }
      if (count == nullptr) {
        warn(s->line, "[" + s->written + "] has no SupportedObjects count");
      } else if (const auto n = parse_unsigned(count->value, 0xFFFF); !n || *n != entries) {
        warn(count->line, "[" + s->written + "]: SupportedObjects = " + shown(count->value) + " but " +
                              std::to_string(entries) + " objects are listed");
      }
    }
    for (const auto& [index, o] : d_.objects) {
      if (listed.count(index) == 0 && index >= 0x1000) {
        warn(o.line, "[" + name_of(index).substr(2) + "] is in no object list ([MandatoryObjects], " +
                         "[OptionalObjects], [ManufacturerObjects]): read anyway");
      }
    }
  }

  void check_mandatory() {
    static const std::pair<std::uint16_t, const char*> kMandatory[] = {
        {0x1000, "device type"}, {0x1001, "error register"}, {0x1018, "identity object"}};
    for (const auto& [index, name] : kMandatory) {
      if (d_.objects.count(index) == 0) {
        error(0, "mandatory object " + name_of(index) + " (" + name + ") is missing (CiA 301)");
      }
    }
    if (const Object* id = d_.object(0x1018); id != nullptr && id->entry(1) == nullptr) {
      error(id->line, "0x1018 (identity object) has no sub-index 1 (vendor-ID), which CiA 301 requires");
    }
  }

  void check_pdo_counts() {
    if (d_.device.line == 0) return;
    int rx = 0, tx = 0;
    for (const PdoDescription& p : pdos(d_)) (p.receive ? rx : tx) += 1;
    if (d_.device.rxpdo_line > 0 && rx != d_.device.nr_of_rxpdo) {
      warn(d_.device.rxpdo_line, "NrOfRXPDO = " + std::to_string(d_.device.nr_of_rxpdo) +
                                     " but the file has " + std::to_string(rx) +
                                     " RPDO communication objects (0x1400..)");
    }
    if (d_.device.txpdo_line > 0 && tx != d_.device.nr_of_txpdo) {
      warn(d_.device.txpdo_line, "NrOfTXPDO = " + std::to_string(d_.device.nr_of_txpdo) +
                                     " but the file has " + std::to_string(tx) +
                                     " TPDO communication objects (0x1800..)");
    }
  }

  ReadOptions options_;
  Description d_;
  std::vector<Section> sections_;
  std::map<std::string, std::size_t> index_;
};

}  // namespace

Description read_eds(std::string_view text, std::string file, ReadOptions options) {
  return Reader(std::move(file), options).read(text);
}

Description read_eds_file(const std::string& path, ReadOptions options) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    Description d;
    d.file = path;
    d.diagnostics.push_back({Severity::kError, 0, "cannot open the file"});
    return d;
  }
  std::ostringstream text;
  text << in.rdbuf();
  return read_eds(text.str(), path, options);
}

std::vector<PdoDescription> pdos(const Description& d) {
  std::vector<PdoDescription> out;
  for (const bool receive : {true, false}) {
    const std::uint16_t comm_base = receive ? 0x1400 : 0x1800;
    const std::uint16_t map_base = receive ? 0x1600 : 0x1A00;
    // The communication objects present, in order (a walk of the map's range, not 512 lookups).
    for (auto it = d.objects.lower_bound(comm_base); it != d.objects.end() && it->first < comm_base + 0x200;
         ++it) {
      const int n = it->first - comm_base;
      const Object* comm = &it->second;
      PdoDescription p;
      p.receive = receive;
      p.number = n + 1;
      p.line = comm->line;
      if (const Entry* id = comm->entry(1)) p.cob_id_writable = writable(id->access);
      if (const Entry* tt = comm->entry(2)) {
        p.transmission_type_writable = writable(tt->access);
        if (const auto b = tt->value().bits(0, tt->type)) p.transmission_type = static_cast<std::uint8_t>(*b);
      }
      const Object* map = d.object(static_cast<std::uint16_t>(map_base + n));
      if (map == nullptr) {
        p.kind = MappingKind::kFixed;  // a PDO whose mapping is not described cannot be re-mapped through it
        out.push_back(std::move(p));
        continue;
      }
      p.line = map->line;
      const Entry* count = map->entry(0);
      bool dynamic = d.device.granularity > 0 && count != nullptr && writable(count->access);
      std::uint64_t n_entries = 0;
      if (count != nullptr) n_entries = count->value().bits(0, count->type).value_or(0);
      for (const auto& [sub, e] : map->entries) {
        if (sub == 0) continue;
        dynamic = dynamic && writable(e.access);
        if (sub > n_entries) continue;
        const auto v = e.value().bits(0, e.type);
        if (!v) continue;
        p.mapping.push_back(MapEntry{static_cast<std::uint16_t>(*v >> 16),
                                     static_cast<std::uint8_t>((*v >> 8) & 0xFF),
                                     static_cast<std::uint8_t>(*v & 0xFF)});
      }
      p.kind = dynamic ? MappingKind::kDynamic : MappingKind::kFixed;
      out.push_back(std::move(p));
    }
  }
  return out;
}

}  // namespace loom::drivers::eds
