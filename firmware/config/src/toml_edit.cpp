// See toml_edit.hpp. Line-based on purpose: a loom config is flat tables of `key = value  # comment`,
// and a line-level edit is the only kind that keeps everything else byte for byte.
#include "loom/config/toml_edit.hpp"

#include <sstream>

#include "loom/config/config.hpp"

namespace loom::firmware {
namespace {

std::vector<std::string> split_lines(const std::string& text) {
  std::vector<std::string> lines;
  std::size_t start = 0;
  while (start < text.size()) {
    const std::size_t nl = text.find('\n', start);
    if (nl == std::string::npos) {
      lines.push_back(text.substr(start));
      break;
    }
    lines.push_back(text.substr(start, nl - start));
    start = nl + 1;
  }
  return lines;
}

std::string trim(const std::string& s) {
  const auto a = s.find_first_not_of(" \t\r");
  if (a == std::string::npos) return "";
  const auto b = s.find_last_not_of(" \t\r");
  return s.substr(a, b - a + 1);
}

// "[name]" (with optional spaces and a comment) → name; "" when the line is not a table header.
std::string header_of(const std::string& line) {
  const std::string t = trim(line);
  if (t.size() < 3 || t[0] != '[' || t[1] == '[') return "";
  const auto close = t.find(']');
  if (close == std::string::npos) return "";
  return trim(t.substr(1, close - 1));
}

// Where a value ends: before a comment that is not inside a quoted string.
std::size_t value_end(const std::string& line, std::size_t from) {
  char quote = 0;
  for (std::size_t i = from; i < line.size(); ++i) {
    const char c = line[i];
    if (quote != 0) {
      if (c == '\\' && quote == '"')
        ++i;
      else if (c == quote)
        quote = 0;
    } else if (c == '"' || c == '\'') {
      quote = c;
    } else if (c == '#') {
      return i;
    }
  }
  return line.size();
}

}  // namespace

std::string set_toml_values(const std::string& text, const std::vector<TomlAssignment>& assignments,
                            std::vector<std::string>& changes) {
  std::vector<std::string> lines = split_lines(text);
  for (const TomlAssignment& a : assignments) {
    std::string section;
    int header_line = -1, found = -1;
    std::size_t eq = 0;
    for (std::size_t i = 0; i < lines.size(); ++i) {
      if (const std::string h = header_of(lines[i]); !h.empty()) {
        section = h;
        if (h == a.section) header_line = static_cast<int>(i);
        continue;
      }
      if (section != a.section) continue;
      const std::string& l = lines[i];
      const auto k0 = l.find_first_not_of(" \t");
      if (k0 == std::string::npos || l.compare(k0, a.key.size(), a.key) != 0) continue;
      const auto after = l.find_first_not_of(" \t", k0 + a.key.size());
      if (after == std::string::npos || l[after] != '=') continue;
      found = static_cast<int>(i);
      eq = after;
      break;
    }
    const std::string name = a.section + "." + a.key;
    if (found >= 0) {
      std::string& l = lines[static_cast<std::size_t>(found)];
      const auto v0 = l.find_first_not_of(" \t", eq + 1);
      if (v0 == std::string::npos || l[v0] == '{' || l[v0] == '[' || l.compare(v0, 3, "\"\"\"") == 0 ||
          l.compare(v0, 3, "'''") == 0) {
        throw ConfigError("line " + std::to_string(found + 1) + ": " + name +
                          " has a value that cannot be rewritten on its line; set it by hand");
      }
      const std::size_t v1 = value_end(l, v0);
      const std::string old = trim(l.substr(v0, v1 - v0));
      // Keep the comment where it was when the new value fits in the old one's room.
      std::string pad;
      if (v1 < l.size()) {
        const std::size_t room = v1 - v0;
        pad = a.value.size() + 1 < room ? std::string(room - a.value.size(), ' ') : " ";
      }
      l = l.substr(0, v0) + a.value + (v1 < l.size() ? pad + l.substr(v1) : "");
      changes.push_back(std::to_string(found + 1) + ": " + name + " = " + a.value + " (was " + old + ")");
    } else if (header_line >= 0) {
      lines.insert(lines.begin() + header_line + 1, a.key + " = " + a.value);
      changes.push_back(std::to_string(header_line + 2) + ": " + name + " = " + a.value + " (added)");
    } else {
      lines.push_back("");
      lines.push_back("[" + a.section + "]");
      lines.push_back(a.key + " = " + a.value);
      changes.push_back(std::to_string(lines.size()) + ": " + name + " = " + a.value +
                        " (added with its section)");
    }
  }
  std::string out;
  for (std::size_t i = 0; i < lines.size(); ++i) {
    out += lines[i];
    if (i + 1 < lines.size() || (!text.empty() && text.back() == '\n')) out += '\n';
  }
  return out;
}

}  // namespace loom::firmware
