// TomlReader: parse errors and value errors share one format so a technician can jump to the line.
#include "loom/config/toml_reader.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <vector>

namespace loom::firmware {
namespace {

std::string where(const std::string& source, const toml::source_region& r) {
  std::ostringstream os;
  os << source << ":" << r.begin.line << ":" << r.begin.column;
  return os.str();
}

std::string show_value(const toml::node& n) {
  std::ostringstream os;
  if (n.is_string()) {
    os << '"' << n.as_string()->get() << '"';
  } else if (n.is_table()) {
    os << "{...}";
  } else if (n.is_array()) {
    os << "[...]";
  } else {
    n.visit([&](auto&& v) {
      if constexpr (toml::is_value<decltype(v)>) os << v.get();
    });
  }
  return os.str();
}

void collect_keys(const toml::table& t, const std::string& prefix,
                  std::vector<std::pair<std::string, const toml::node*>>& out) {
  for (const auto& [k, v] : t) {
    const std::string path = prefix.empty() ? std::string(k.str()) : prefix + "." + std::string(k.str());
    if (const auto* sub = v.as_table()) {
      collect_keys(*sub, path, out);
    } else {
      out.emplace_back(path, &v);
    }
  }
}

// toml++ recurses once per dotted-key segment and per nested array/inline table: a hostile file
// (40,000 dots) would overflow the stack. No loom config needs more than a few levels.
constexpr int kMaxKeyDepth = 16;
constexpr int kMaxNesting = 32;

void check_depth(const std::string& text, const std::string& source) {
  int line = 1, col = 0, dots = 0, nesting = 0;
  bool in_string = false, in_comment = false, in_key = true;
  char quote = 0;
  for (char ch : text) {
    ++col;
    if (ch == '\n') {
      ++line, col = 0, dots = 0, in_comment = false, in_key = nesting == 0;
      if (quote == '"' || quote == '\'') in_string = false, quote = 0;  // single-line strings end here
      continue;
    }
    if (in_comment) continue;
    if (in_string) {
      if (ch == quote) in_string = false, quote = 0;
      continue;
    }
    if (ch == '"' || ch == '\'') {
      in_string = true, quote = ch;
    } else if (ch == '#') {
      in_comment = true;
    } else if (ch == '=') {
      in_key = false;
    } else if (ch == '.' && in_key) {
      if (++dots >= kMaxKeyDepth) {
        throw ConfigError(source + ":" + std::to_string(line) + ":" + std::to_string(col) +
                          ": key nested deeper than " + std::to_string(kMaxKeyDepth) + " levels");
      }
    } else if ((ch == '[' || ch == '{') && !in_key) {
      if (++nesting > kMaxNesting) {
        throw ConfigError(source + ":" + std::to_string(line) + ":" + std::to_string(col) +
                          ": arrays/inline tables nested deeper than " + std::to_string(kMaxNesting) +
                          " levels");
      }
    } else if ((ch == ']' || ch == '}') && !in_key && nesting > 0) {
      --nesting;
    }
  }
}

// toml++ 3.3.0 (Debian 12) has undefined behaviour on non-ASCII text where it looks for whitespace
// (marzer/tomlplusplus#295: impl::is_non_ascii_horizontal_whitespace reaches __builtin_unreachable() for
// most code points in U+00A1..U+FEFE). So the text is checked before toml++ sees it: it must be valid UTF-8,
// and non-ASCII is allowed only where TOML allows it and toml++ never asks "is this whitespace?": inside
// basic/literal strings (single- and multi-line) and comments. Two places inside multi-line basic strings
// are whitespace lookups too and are refused: the character after a backslash, and the first character
// after a line-ending backslash (toml++ skips the whitespace that follows it).
std::string hex_code_point(char32_t c) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "U+%04X", static_cast<unsigned>(c));
  return buf;
}

std::string hex_byte(unsigned char b) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "0x%02X", static_cast<unsigned>(b));
  return buf;
}

// Decodes one UTF-8 sequence at text[i]; returns its length, or 0 with `why` set when it is invalid.
std::size_t decode_utf8(const std::string& text, std::size_t i, char32_t& cp, std::string& why) {
  const auto at = [&](std::size_t k) { return static_cast<unsigned char>(text[k]); };
  const unsigned char b0 = at(i);
  if (b0 < 0x80) {
    cp = b0;
    return 1;
  }
  std::size_t len = 0;
  char32_t min = 0;
  if (b0 >= 0xC2 && b0 <= 0xDF) {
    len = 2, min = 0x80, cp = b0 & 0x1FU;
  } else if (b0 >= 0xE0 && b0 <= 0xEF) {
    len = 3, min = 0x800, cp = b0 & 0x0FU;
  } else if (b0 >= 0xF0 && b0 <= 0xF4) {
    len = 4, min = 0x10000, cp = b0 & 0x07U;
  } else {
    why = b0 < 0xC0 ? "invalid UTF-8: stray continuation byte " + hex_byte(b0)
                    : "invalid UTF-8: byte " + hex_byte(b0) + " never starts a character";
    return 0;
  }
  for (std::size_t k = 1; k < len; ++k) {
    if (i + k >= text.size() || (at(i + k) & 0xC0U) != 0x80) {
      why = "invalid UTF-8: sequence starting with " + hex_byte(b0) + " cut short";
      return 0;
    }
    cp = (cp << 6) | (at(i + k) & 0x3FU);
  }
  if (cp < min) {
    why = "invalid UTF-8: overlong encoding of " + hex_code_point(cp);
  } else if (cp >= 0xD800 && cp <= 0xDFFF) {
    why = "invalid UTF-8: encoded surrogate " + hex_code_point(cp);
  } else if (cp > 0x10FFFF) {
    why = "invalid UTF-8: code point beyond U+10FFFF";
  } else {
    return len;
  }
  return 0;
}

// Where a quote opens a string as toml++ reads a line: at the start of a key or of a value. Inside a bare
// token it is just another character — and toml++ walks a bare value (a number, a date, or garbage) to
// its terminator asking "is this whitespace?" of every character, so a quote there must not make the
// check treat what follows it as string content (`x = --x="χ`, found by fuzz_loom_config).
class TokenContext {
 public:
  void new_line() { *this = TokenContext{}; }
  bool quote_opens_string() const {
    return !in_bare_ && (before_ == 0 || before_ == '=' || before_ == '[' || before_ == ',' ||
                         before_ == '{' || before_ == '.');
  }
  void string_closed() {
    in_bare_ = false;
    before_ = '"';
  }
  void take(char ch) {
    const bool blank = ch == ' ' || ch == '\t' || ch == '\r';
    if (in_bare_) {
      // A bare key is [A-Za-z0-9_-]; a bare value runs to whitespace , ] } (or a comment, seen earlier).
      const bool key_char = std::isalnum(static_cast<unsigned char>(ch)) != 0 || ch == '_' || ch == '-';
      const bool ends = bare_is_key_ ? !key_char : (blank || ch == ',' || ch == ']' || ch == '}');
      if (!ends) {
        before_ = ch;
        return;
      }
      in_bare_ = false;
    }
    if (blank) return;
    switch (ch) {
      case '=':
        key_next_ = false;
        break;
      case ',':
        key_next_ = braces_ > 0;
        break;
      case '{':
        ++braces_;
        key_next_ = true;
        break;
      case '}':
        if (braces_ > 0) --braces_;
        break;
      case '[':
      case ']':
      case '.':
        break;
      default:
        in_bare_ = true;
        bare_is_key_ = key_next_;
        break;
    }
    before_ = ch;
  }

 private:
  bool in_bare_ = false;      // inside a bare token
  bool bare_is_key_ = false;  // ... a key (ended by any non-key character) or a value (ended by a terminator)
  bool key_next_ = true;      // the next token is a key: at the line's start, after { and after , inside { }
  int braces_ = 0;
  char before_ = 0;  // the last character outside strings on this line, 0 at its start
};

void check_text(const std::string& text, const std::string& source) {
  enum class In { kToml, kComment, kBasic, kLiteral, kMultiBasic, kMultiLiteral };
  In in = In::kToml;
  bool escaped = false;      // the previous character was a backslash in a basic string
  bool line_ending = false;  // after a multi-line string's `\` + space/tab: only space/tab until the break
  bool skipping = false;     // after a line-ending backslash: toml++ skips whitespace and line breaks
  TokenContext tokens;
  std::size_t line = 1, col = 0;
  const auto fail = [&](const std::string& why) {
    throw ConfigError(source + ":" + std::to_string(line) + ":" + std::to_string(col) + ": " + why);
  };
  const auto run = [&](std::size_t i, char q) {
    std::size_t n = 0;
    while (i + n < text.size() && text[i + n] == q) ++n;
    return n;
  };
  std::size_t i = 0;
  // A byte order mark at the start is allowed (toml++ skips it; some editors write one).
  if (text.compare(0, 3, "\xEF\xBB\xBF") == 0) i = 3;
  while (i < text.size()) {
    char32_t cp = 0;
    std::string why;
    ++col;
    const std::size_t len = decode_utf8(text, i, cp, why);
    if (len == 0) fail(why);
    const char ch = static_cast<char>(cp);  // meaningful only when cp < 0x80
    const bool ascii = cp < 0x80;
    if (cp == '\n') {
      ++line, col = 0;
      tokens.new_line();
      if (in == In::kComment || in == In::kBasic || in == In::kLiteral) in = In::kToml;  // (single-line ends)
      if ((escaped && in == In::kMultiBasic) || line_ending) skipping = true;  // a line-ending backslash
      escaped = line_ending = false;
      i += 1;
      continue;
    }
    switch (in) {
      case In::kToml:
        if (!ascii) fail("non-ASCII character " + hex_code_point(cp) + " outside a string or comment");
        if (ch == '#') {
          in = In::kComment;
        } else if ((ch == '"' || ch == '\'') && tokens.quote_opens_string()) {
          const bool multi = run(i, ch) >= 3;
          in =
              ch == '"' ? (multi ? In::kMultiBasic : In::kBasic) : (multi ? In::kMultiLiteral : In::kLiteral);
          if (multi) i += 2, col += 2;
        } else {
          tokens.take(ch);
        }
        break;
      case In::kComment:
        break;
      case In::kLiteral:
        if (ch == '\'') in = In::kToml, tokens.string_closed();
        break;
      case In::kMultiLiteral:
        if (ch == '\'') {
          const std::size_t n = run(i, '\'');
          if (n >= 3) {
            const std::size_t take = std::min<std::size_t>(n, 5);
            i += take - 1, col += take - 1;
            in = In::kToml, tokens.string_closed();
          }
        }
        break;
      case In::kBasic:
      case In::kMultiBasic:
        if (escaped) {
          escaped = false;
          if (!ascii) {
            fail("non-ASCII character " + hex_code_point(cp) +
                 " after a backslash in a string (not a TOML escape)");
          }
          if (in == In::kMultiBasic && (ch == ' ' || ch == '\t')) line_ending = true;
          if (in == In::kMultiBasic && ch == '\r') skipping = true;
          break;
        }
        if (line_ending) {
          if (!ascii) {
            fail("non-ASCII character " + hex_code_point(cp) +
                 " after a line-ending backslash (only spaces and tabs may follow it on its line)");
          }
          line_ending = false;
          if (ch == ' ' || ch == '\t') {
            line_ending = true;
            break;
          }
          if (ch == '\r') {
            skipping = true;
            break;
          }
          // anything else: toml++ refuses it ("line-ending backslashes must be the last ...")
        }
        if (skipping) {
          if (ch == ' ' || ch == '\t' || ch == '\r') break;
          if (!ascii) {
            fail("non-ASCII character " + hex_code_point(cp) +
                 " first after a line-ending backslash (toml++ 3.3.0 cannot parse it there; write it as \\u" +
                 hex_code_point(cp).substr(2) + ")");
          }
          skipping = false;
        }
        if (ch == '\\') {
          escaped = true;
        } else if (ch == '"') {
          if (in == In::kBasic) {
            in = In::kToml, tokens.string_closed();
          } else if (const std::size_t n = run(i, '"'); n >= 3) {
            const std::size_t take = std::min<std::size_t>(n, 5);
            i += take - 1, col += take - 1;
            in = In::kToml, tokens.string_closed();
          } else {
            i += n - 1, col += n - 1;
          }
        }
        break;
    }
    i += len;
  }
}

// Edit distance, for "did you mean".
std::size_t distance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> prev(b.size() + 1), cur(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) prev[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    cur[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, prev[j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1)});
    }
    std::swap(prev, cur);
  }
  return prev[b.size()];
}

}  // namespace

std::string read_config_file(const std::string& path, long max_bytes, const char* what) {
  const auto kMaxBytes = static_cast<off_t>(max_bytes);
  // O_NONBLOCK: opening a FIFO must not wait for a writer; the type check below refuses it anyway.
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
  if (fd < 0) throw ConfigError(path + ": cannot open: " + std::strerror(errno));
  struct stat st {};
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    ::close(fd);
    throw ConfigError(path + ": not a regular file");
  }
  if (st.st_size > kMaxBytes) {
    ::close(fd);
    throw ConfigError(path + ": " + std::to_string(st.st_size) + " bytes: larger than any " + what +
                      " (limit " + std::to_string(max_bytes >> 20) + " MiB)");
  }
  std::string text(static_cast<std::size_t>(st.st_size), '\0');
  std::size_t got = 0;
  while (got < text.size()) {
    const ssize_t n = ::read(fd, text.data() + got, text.size() - got);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      const int err = errno;
      ::close(fd);
      throw ConfigError(path + ": cannot read" +
                        (n < 0 ? std::string(": ") + std::strerror(err) : ": file shrank"));
    }
    got += static_cast<std::size_t>(n);
  }
  ::close(fd);
  return text;
}

std::string positive(double v) {
  return v > 0.0 && std::isfinite(v) ? "" : "must be positive and finite";
}
std::string in_range(double v, double lo, double hi) {
  if (v >= lo && v <= hi) return "";
  std::ostringstream os;
  os << "must be in [" << lo << ", " << hi << "]";
  return os.str();
}
std::string non_negative(double v) {
  return v >= 0.0 && std::isfinite(v) ? "" : "must be >= 0 and finite";
}

std::string TomlReader::show(const toml::node& n) const {
  // The value as the user wrote it (1e-320 stays 1e-320), when it sits on one line.
  const auto& r = n.source();
  if (r.begin.line == r.end.line && r.begin.line >= 1 && r.begin.line <= lines_.size() && !n.is_table()) {
    const std::string& line = lines_[r.begin.line - 1];
    // toml++ counts columns in code points; the line is UTF-8 (checked), so step over continuation bytes.
    const auto byte_of = [&line](std::size_t column) {
      std::size_t b = 0;
      for (std::size_t c = 1; c < column && b < line.size(); ++c) {
        ++b;
        while (b < line.size() && (static_cast<unsigned char>(line[b]) & 0xC0U) == 0x80) ++b;
      }
      return b;
    };
    if (r.begin.column >= 1 && r.end.column > r.begin.column) {
      const std::size_t begin = byte_of(r.begin.column), end = byte_of(r.end.column);
      if (end > begin && end <= line.size()) return line.substr(begin, end - begin);
    }
  }
  return show_value(n);
}

TomlReader::TomlReader(const std::string& text, std::string source) : source_(std::move(source)) {
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines_.push_back(line);
  if (text.find('\0') != std::string::npos)
    throw ConfigError(source_ + ":1:1: not a text file (contains NUL bytes)");
  check_text(text, source_);
  check_depth(text, source_);
  try {
    root_ = toml::parse(text, source_);
  } catch (const toml::parse_error& e) {
    throw ConfigError(where(source_, e.source()) + ": " + std::string(e.description()));
  }
}

const toml::node* TomlReader::find(const std::string& path) const {
  return root_.at_path(path).node();
}

std::string TomlReader::message(const std::string& path, const std::string& value,
                                const std::string& why) const {
  const toml::node* n = find(path);
  return (n ? where(source_, n->source()) : source_ + ":1:1") + ": " + path + " = " + value + ": " + why;
}

void TomlReader::fail(const std::string& path, const std::string& value, const std::string& why) const {
  throw ConfigError(message(path, value, why));
}

void TomlReader::fail_at(const toml::node& node, const std::string& field, const std::string& value,
                         const std::string& why) const {
  throw ConfigError(where(source_, node.source()) + ": " + field + " = " + value + ": " + why);
}

void TomlReader::fail_missing(const std::string& path, const std::string& why) const {
  const std::string section = path.substr(0, path.find('.'));
  const toml::node* sec = find(section);
  if (sec && sec->source().begin.line > 0) {
    throw ConfigError(where(source_, sec->source()) + ": [" + section + "] " +
                      path.substr(path.find('.') + 1) + ": " + why);
  }
  throw ConfigError(source_ + ":1:1: " + path + ": " + why);
}

void TomlReader::number(const std::string& path, double& out,
                        const std::function<std::string(double)>& check) {
  used_.insert(path);
  const toml::node* n = find(path);
  if (!n) return;
  const auto v = n->value<double>();  // integers convert
  if (!v) fail_at(*n, path, show(*n), "expected a number");
  if (!std::isfinite(*v)) fail_at(*n, path, show(*n), "must be finite");
  if (check) {
    const std::string why = check(*v);
    if (!why.empty()) fail_at(*n, path, show(*n), why);
  }
  out = *v;
}

void TomlReader::integer(const std::string& path, std::int64_t& out, std::int64_t lo, std::int64_t hi) {
  used_.insert(path);
  const toml::node* n = find(path);
  if (!n) return;
  const auto v = n->value_exact<std::int64_t>();
  if (!v) fail_at(*n, path, show(*n), "expected an integer");
  if (*v < lo || *v > hi) {
    std::ostringstream os;
    os << "must be in [" << lo << ", " << hi << "]";
    fail_at(*n, path, show(*n), os.str());
  }
  out = *v;
}

void TomlReader::boolean(const std::string& path, bool& out) {
  used_.insert(path);
  const toml::node* n = find(path);
  if (!n) return;
  const auto v = n->value_exact<bool>();
  if (!v) fail_at(*n, path, show(*n), "expected true or false");
  out = *v;
}

void TomlReader::string(const std::string& path, std::string& out, const std::set<std::string>& allowed) {
  used_.insert(path);
  const toml::node* n = find(path);
  if (!n) return;
  const auto v = n->value<std::string>();
  if (!v) fail_at(*n, path, show(*n), "expected a string");
  if (!allowed.empty() && !allowed.count(*v)) {
    std::string list;
    for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
    fail_at(*n, path, show(*n), "must be one of: " + list);
  }
  out = *v;
}

void TomlReader::string_list(const std::string& path, std::vector<std::string>& out) {
  used_.insert(path);
  const toml::node* n = find(path);
  if (!n) return;
  const toml::array* arr = n->as_array();
  if (!arr) fail_at(*n, path, show(*n), "expected an array of strings");
  out.clear();
  for (const auto& e : *arr) {
    const auto s = e.value<std::string>();
    if (!s) fail_at(e, path, show(e), "expected a string");
    out.push_back(*s);
  }
}

void TomlReader::integer_list(const std::string& path, std::vector<int>& out, int lo, int hi,
                              std::size_t max_size) {
  used_.insert(path);
  const toml::node* n = find(path);
  if (!n) return;
  const toml::array* arr = n->as_array();
  if (!arr) fail_at(*n, path, show(*n), "expected an array of integers");
  if (arr->size() > max_size) {
    fail_at(*n, path, show(*n),
            "at most " + std::to_string(max_size) + " entries (" + std::to_string(arr->size()) + " given)");
  }
  out.clear();
  for (const auto& e : *arr) {
    const auto v = e.value_exact<std::int64_t>();
    if (!v) fail_at(e, path, show(e), "expected an integer");
    if (*v < lo || *v > hi) {
      fail_at(e, path, show(e), "outside " + std::to_string(lo) + ".." + std::to_string(hi));
    }
    out.push_back(static_cast<int>(*v));
  }
}

void TomlReader::reject_unknown(const std::set<std::string>& sections) const {
  for (const auto& [k, v] : root_) {
    const std::string name(k.str());
    if (!v.is_table() || sections.count(name) || used_.count(name)) continue;
    std::string best;
    std::size_t best_d = 3;  // suggest only near misses
    for (const auto& s : sections) {
      const std::size_t d = distance(name, s);
      if (d < best_d) best = s, best_d = d;
    }
    std::string list;
    for (const auto& s : sections) list += (list.empty() ? "" : ", ") + s;
    fail_at(
        v, "[" + name + "]", "{...}",
        "unknown section" + (best.empty() ? " (sections: " + list + ")" : " (did you mean [" + best + "]?)"));
  }
  reject_unknown();
}

void TomlReader::reject_unknown() const {
  std::vector<std::pair<std::string, const toml::node*>> keys;
  collect_keys(root_, "", keys);
  for (const auto& [path, node] : keys) {
    if (!used_.count(path)) fail_at(*node, path, show(*node), "unknown field");
  }
}

}  // namespace loom::firmware
