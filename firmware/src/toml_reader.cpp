// TomlReader: parse errors and value errors share one format so a technician can jump to the line.
#include "toml_reader.hpp"

#include <cmath>

namespace loom::firmware {
namespace {

std::string where(const std::string& source, const toml::source_region& r) {
  std::ostringstream os;
  os << source << ":" << r.begin.line << ":" << r.begin.column;
  return os.str();
}

std::string show(const toml::node& n) {
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

void collect_keys(const toml::table& t, const std::string& prefix, std::vector<std::pair<std::string, const toml::node*>>& out) {
  for (const auto& [k, v] : t) {
    const std::string path = prefix.empty() ? std::string(k.str()) : prefix + "." + std::string(k.str());
    if (const auto* sub = v.as_table()) {
      collect_keys(*sub, path, out);
    } else {
      out.emplace_back(path, &v);
    }
  }
}

}  // namespace

std::string positive(double v) { return v > 0.0 && std::isfinite(v) ? "" : "must be positive and finite"; }
std::string non_negative(double v) { return v >= 0.0 && std::isfinite(v) ? "" : "must be >= 0 and finite"; }

TomlReader::TomlReader(const std::string& text, std::string source) : source_(std::move(source)) {
  try {
    root_ = toml::parse(text, source_);
  } catch (const toml::parse_error& e) {
    throw ConfigError(where(source_, e.source()) + ": " + std::string(e.description()));
  }
}

const toml::node* TomlReader::find(const std::string& path) const {
  return root_.at_path(path).node();
}

void TomlReader::fail(const std::string& path, const std::string& value, const std::string& why) const {
  const toml::node* n = find(path);
  if (n) fail_at(*n, path, value, why);
  throw ConfigError(source_ + ":1:1: " + path + " = " + value + ": " + why);
}

void TomlReader::fail_at(const toml::node& node, const std::string& field, const std::string& value,
                         const std::string& why) const {
  throw ConfigError(where(source_, node.source()) + ": " + field + " = " + value + ": " + why);
}

void TomlReader::number(const std::string& path, double& out, const std::function<std::string(double)>& check) {
  used_.insert(path);
  const toml::node* n = find(path);
  if (!n) return;
  const auto v = n->value<double>();  // integers convert
  if (!v) fail_at(*n, path, show(*n), "expected a number");
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

void TomlReader::reject_unknown() const {
  std::vector<std::pair<std::string, const toml::node*>> keys;
  collect_keys(root_, "", keys);
  for (const auto& [path, node] : keys) {
    if (!used_.count(path)) fail_at(*node, path, show(*node), "unknown field");
  }
}

}  // namespace loom::firmware
