// Request-line parsing for the control socket: strict, bounded, total (every input gets a verdict).
#include "loom/firmware/serve/control_protocol.hpp"

namespace loom::firmware::serve {
namespace {

constexpr std::size_t kMaxLine = 512, kMaxToken = 128, kMaxFields = 8;

bool printable(char c) {
  return c > ' ' && c < 0x7F;
}

std::optional<CommandClass> class_of(std::string_view w) {
  if (w == "stop" || w == "pause") return CommandClass::kStopping;
  if (w == "start" || w == "resume" || w == "next" || w == "ack" || w == "reload") {
    return CommandClass::kStarting;
  }
  if (w == "status" || w == "faults" || w == "pairs" || w == "whoami") return CommandClass::kReading;
  if (w == "pair" || w == "unpair" || w == "redeem") return CommandClass::kPairing;
  if (w == "job") return CommandClass::kReading;  // list and show; the changing verbs: job_fields_error
  return std::nullopt;
}

bool known_field(std::string_view k) {
  return k == "via" || k == "client" || k == "token" || k == "code" || k == "hours" || k == "device" ||
         k == "head" || k == "slot" || k == "knots" || k == "id" || k == "design" || k == "rows" ||
         k == "metres" || k == "repeat";
}

std::string word_list() {
  std::string s;
  for (const char* w : kCommandWords) s += (s.empty() ? "" : ", ") + std::string(w);
  return s;
}

// For error messages: at most 40 characters, anything unprintable as '?'.
std::string shown(std::string_view s) {
  std::string out;
  for (char c : s.substr(0, 40)) out += printable(c) ? c : '?';
  return out + (s.size() > 40 ? "..." : "");
}

// A whole number 0..max written in decimal digits only (no sign, no spaces, at most 7 digits).
bool small_number(const std::string& s, int max) {
  if (s.empty() || s.size() > 7 || s.find_first_not_of("0123456789") != std::string::npos) return false;
  return std::stol(s) <= max;
}

// reload needs head= and slot= (knots= optional); no other word takes them.
std::string reload_fields_error(const ParsedRequest& r) {
  const bool reload = r.word == "reload";
  for (const char* k : {"head", "slot", "knots"}) {
    if (r.fields.count(k) != 0 && !reload) return std::string(k) + "= is for reload only";
  }
  if (!reload) return "";
  if (r.fields.count("head") == 0 || r.fields.count("slot") == 0) {
    return "reload needs head=H slot=S (e.g. reload head=2 slot=1; knots=K when not full)";
  }
  if (!small_number(r.field("head"), 99) || std::stol(r.field("head")) < 1) {
    return "head=" + shown(r.field("head")) + ": a head number from 1 (as the request names it)";
  }
  if (!small_number(r.field("slot"), 99)) {
    return "slot=" + shown(r.field("slot")) + ": a slot number from 0 (as the request names it)";
  }
  if (r.fields.count("knots") != 0 && !small_number(r.field("knots"), kMaxReloadKnots)) {
    return "knots=" + shown(r.field("knots")) + ": the knots now in the slot, 0 to " +
           std::to_string(kMaxReloadKnots);
  }
  return "";
}

// A whole number 1..max in decimal digits only (at most 10 digits: a job number, a length in rows).
bool count_in(const std::string& s, std::uint64_t max) {
  if (s.empty() || s.size() > 10 || s.find_first_not_of("0123456789") != std::string::npos) return false;
  const std::uint64_t v = std::stoull(s);
  return v >= 1 && v <= max;
}

// A plain decimal number of metres (digits, at most one '.'), more than 0 and at most 1e6.
bool metres_in_range(const std::string& s) {
  if (s.empty() || s.size() > 16 || s.find_first_not_of("0123456789.") != std::string::npos ||
      s.find('.') != s.rfind('.') || s == ".") {
    return false;
  }
  const double v = std::stod(s);
  return v > 0.0 && v <= 1e6;
}

// job VERB: the verb known, its fields present (id= for show/remove/start-over, design= for add) and
// no other word's; the changing verbs are of the queue class.
std::string job_fields_error(ParsedRequest& r) {
  const bool job = r.word == "job";
  for (const char* k : {"id", "design", "rows", "metres", "repeat"}) {
    if (r.fields.count(k) != 0 && !job) return std::string(k) + "= is for job only";
  }
  if (!job) return "";
  const std::string& v = r.arg;
  if (v.empty()) return "job needs a verb (list, show, add, remove, start-over)";
  if (v != "list" && v != "show" && v != "add" && v != "remove" && v != "start-over") {
    return "job " + shown(v) + ": not a verb (list, show, add, remove, start-over)";
  }
  const bool add = v == "add", numbered = v == "show" || v == "remove" || v == "start-over";
  if (numbered != (r.fields.count("id") != 0)) {
    return numbered ? "job " + v + " needs id=N (the job's number, as job list shows it)"
                    : "id= is not for job " + v;
  }
  if (numbered && !count_in(r.field("id"), 4294967295ull)) {
    return "id=" + shown(r.field("id")) + ": not a job number (1, 2, ...)";
  }
  if (add != (r.fields.count("design") != 0)) {
    return add ? "job add needs design=PATH (the design file, an absolute path)"
               : "design= is for job add only";
  }
  if (add && r.field("design").front() != '/') {
    return "design=" + shown(r.field("design")) + ": an absolute path (the loom's service resolves nothing)";
  }
  const int lengths =
      static_cast<int>(r.fields.count("rows") + r.fields.count("metres") + r.fields.count("repeat"));
  if (lengths > 0 && !add) return "rows=, metres= and repeat= are for job add only";
  if (lengths > 1) return "one of rows=, metres=, repeat= (the carpet's length)";
  if (r.fields.count("rows") != 0 && !count_in(r.field("rows"), 4294967295ull)) {
    return "rows=" + shown(r.field("rows")) + ": the carpet's rows, 1 to 4294967295";
  }
  if (r.fields.count("repeat") != 0 && !count_in(r.field("repeat"), 1000000)) {
    return "repeat=" + shown(r.field("repeat")) + ": the design's repeats, 1 to 1000000";
  }
  if (r.fields.count("metres") != 0 && !metres_in_range(r.field("metres"))) {
    return "metres=" + shown(r.field("metres")) +
           ": the carpet's length in metres, a decimal number above 0 "
           "and at most 1000000";
  }
  if (add || v == "remove" || v == "start-over") r.cls = CommandClass::kQueue;
  return "";
}

}  // namespace

std::string pairing_name_error(std::string_view s) {
  if (s.empty() || s.size() > 32) return "a pairing name is 1 to 32 characters";
  for (char c : s) {
    const bool ok = (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_' ||
                    c == '-' || c == '.';
    if (!ok) return "a pairing name has only letters, digits, '_', '-' and '.'";
  }
  return "";
}

std::optional<ParsedRequest> parse_request(std::string_view line, std::string& error) {
  if (line.size() > kMaxLine) {
    error = "request longer than " + std::to_string(kMaxLine) + " bytes";
    return std::nullopt;
  }
  ParsedRequest r;
  std::size_t i = 0, n = 0;
  while (i < line.size()) {
    if (line[i] == ' ') {
      ++i;
      continue;
    }
    std::size_t j = i;
    while (j < line.size() && line[j] != ' ') {
      if (!printable(line[j])) {
        error = "request has a character that is not printable ASCII";
        return std::nullopt;
      }
      ++j;
    }
    const std::string_view tok = line.substr(i, j - i);
    i = j;
    if (tok.size() > kMaxToken && tok.rfind("design=", 0) != 0) {  // a design's path: up to the line
      error = "request word longer than " + std::to_string(kMaxToken) + " bytes";
      return std::nullopt;
    }
    if (n++ == 0) {
      r.word = tok;
      continue;
    }
    const auto eq = tok.find('=');
    if (eq == std::string_view::npos) {
      if (!r.arg.empty() || !r.fields.empty()) {
        error = "unexpected '" + shown(tok) + "' (one argument, then key=value fields)";
        return std::nullopt;
      }
      r.arg = tok;
      continue;
    }
    const std::string key(tok.substr(0, eq));
    if (!known_field(key)) {
      error =
          "unknown field '" + shown(key) +
          "' (via, client, token, device, code, hours, head, slot, knots, id, design, rows, metres, repeat)";
      return std::nullopt;
    }
    if (r.fields.size() >= kMaxFields || r.fields.count(key) != 0) {
      error = "field '" + key + "' given twice";
      return std::nullopt;
    }
    r.fields[key] = std::string(tok.substr(eq + 1));
  }
  const auto cls = class_of(r.word);
  if (!cls) {
    error = "unknown command '" + shown(r.word) + "' (" + word_list() + ")";
    return std::nullopt;
  }
  r.cls = *cls;
  const bool takes_arg = r.word == "pair" || r.word == "unpair" || r.word == "job";
  if (takes_arg && r.arg.empty() && r.word != "job") {
    error = r.word + " needs a NAME (e.g. " + r.word + " phone-anna)";
    return std::nullopt;
  }
  if (!takes_arg && !r.arg.empty()) {
    error = r.word + " takes no argument (got '" + shown(r.arg) + "')";
    return std::nullopt;
  }
  if (takes_arg && r.word != "job") {
    if (auto e = pairing_name_error(r.arg); !e.empty()) {
      error = e;
      return std::nullopt;
    }
  }
  if (r.fields.count("hours") != 0 && r.word != "pair") {
    error = "hours= is for pair only";
    return std::nullopt;
  }
  if (auto e = reload_fields_error(r); !e.empty()) {
    error = e;
    return std::nullopt;
  }
  if (auto e = job_fields_error(r); !e.empty()) {
    error = e;
    return std::nullopt;
  }
  if (r.fields.count("code") != 0 && r.word != "redeem") {
    error = "code= is for redeem only";
    return std::nullopt;
  }
  if (r.fields.count("via") != 0 && r.field("via") != "panel") {
    error = "via=" + shown(r.field("via")) + ": only via=panel";
    return std::nullopt;
  }
  if (r.via_panel() && r.field("client").empty()) {
    error = "via=panel needs client=ADDR";
    return std::nullopt;
  }
  return r;
}

}  // namespace loom::firmware::serve
