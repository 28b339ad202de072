// Channel naming and the validation of the two user-supplied parts (loom id, prefix), kept in one
// place so the publisher and every subscriber (loom-monitor, tests) agree on the names.
#include "loom/telemetry/channels.hpp"

namespace loom::telemetry {

namespace {

bool is_field_char(char c) {
  return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_' || c == '-';
}

std::string quoted(std::string_view v) {
  return "'" + std::string(v) + "'";
}

}  // namespace

std::string loom_id_error(std::string_view id) {
  if (id.empty()) return "loom id '' is empty; use 1 to 32 of A-Z a-z 0-9 _ -";
  if (id.size() > kMaxLoomIdLength) {
    return "loom id " + quoted(id) + " is " + std::to_string(id.size()) + " characters; at most " +
           std::to_string(kMaxLoomIdLength) + " allowed";
  }
  for (char c : id) {
    if (!is_field_char(c)) {
      return "loom id " + quoted(id) + " contains '" + std::string(1, c) +
             "'; only A-Z a-z 0-9 _ - are allowed";
    }
  }
  return {};
}

std::string channel_prefix_error(std::string_view prefix) {
  if (prefix.empty()) return "channel prefix '' is empty";
  std::size_t field_len = 0;
  for (char c : prefix) {
    if (c == '.') {
      if (field_len == 0) return "channel prefix " + quoted(prefix) + " has an empty dot-separated field";
      field_len = 0;
    } else if (!is_field_char(c)) {
      return "channel prefix " + quoted(prefix) + " contains '" + std::string(1, c) +
             "'; only A-Z a-z 0-9 _ - and '.' between fields are allowed";
    } else {
      ++field_len;
    }
  }
  if (field_len == 0) return "channel prefix " + quoted(prefix) + " has an empty dot-separated field";
  return {};
}

ChannelNames channel_names(std::string_view prefix, std::string_view loom_id) {
  const std::string base = std::string(prefix) + "." + std::string(loom_id) + ".";
  return {base + "STATUS",  base + "AXES",   base + "RT",       base + "BEAT",  base + "FAULT",
          base + "ROW",     base + "DESIGN", base + "IDENTITY", base + "KNOTS", base + "WEAVER",
          base + "COMMAND", base + "JOB",    base + "CARPET"};
}

std::string channel_regex(std::string_view prefix, std::string_view loom_id, std::string_view kind) {
  // The allowed characters make '.' the only regex metacharacter that can appear; '-' is literal
  // outside brackets. LCM anchors the regex at both ends.
  std::string re;
  for (char c : prefix) {
    if (c == '.')
      re += "\\.";
    else
      re += c;
  }
  re += "\\.";
  re += loom_id.empty() ? std::string("[A-Za-z0-9_-]+") : std::string(loom_id);
  re += "\\.";
  re += kind;
  return re;
}

}  // namespace loom::telemetry
