// The latched fault on disk (see latched_fault.hpp): a strict `key = value` reader, a durable writer.
#include "loom/firmware/serve/latched_fault.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <map>
#include <sstream>
#include <stdexcept>

#include "loom/config/config.hpp"
#include "loom/state/durable_file.hpp"

namespace loom::firmware::serve {
namespace {

constexpr std::size_t kMaxBytes = 4096;
constexpr std::size_t kMaxText = 200;
constexpr std::size_t kMaxAxis = 32;

std::optional<sequencer::Fault> fault_named(const std::string& name) {
#define LOOM_FAULT_BY_NAME(id, code, fname, text) \
  if (name == (fname)) return sequencer::Fault::id;
  LOOM_FAULT_TABLE(LOOM_FAULT_BY_NAME)
#undef LOOM_FAULT_BY_NAME
  return std::nullopt;
}

bool whole_number(const std::string& v, std::uint64_t max, std::uint64_t& out) {
  if (v.empty() || v.size() > 10 || v.find_first_not_of("0123456789") != std::string::npos) return false;
  if (v.size() > 1 && v[0] == '0') return false;
  out = std::stoull(v);
  return out <= max;
}

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t");
  if (b == std::string::npos) return "";
  return s.substr(b, s.find_last_not_of(" \t") - b + 1);
}

// `s` with \r, \n, \t as such and every other byte outside printable ASCII as \xNN.
std::string escaped(const std::string& s) {
  std::string out;
  for (const char ch : s) {
    const auto c = static_cast<unsigned char>(ch);
    if (c == '\r')
      out += "\\r";
    else if (c == '\n')
      out += "\\n";
    else if (c == '\t')
      out += "\\t";
    else if (c == '\\')
      out += "\\\\";
    else if (c < 0x20 || c >= 0x7F) {
      char b[8];
      std::snprintf(b, sizeof b, "\\x%02X", c);
      out += b;
    } else {
      out += ch;
    }
  }
  return out;
}

}  // namespace

std::string LatchedFaultStore::utc(std::int64_t unix_s) {
  std::tm tm{};
  const std::time_t t = static_cast<std::time_t>(unix_s);
  gmtime_r(&t, &tm);
  char b[32];
  std::strftime(b, sizeof b, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return b;
}

std::string LatchedFaultStore::format(const LatchedFault& f) {
  const FaultRecord& r = f.record;
  char device[16];
  std::snprintf(device, sizeof device, "0x%04X", r.device_code);
  std::ostringstream os;
  os << "# loomctl serve: the fault latched, kept until it is acknowledged (ctl ack or the ack button)\n"
     << "kind = " << r.kind << "\nfault = " << sequencer::fault_name(f.fault) << "\n";
  if (!r.axis.empty()) os << "axis = " << r.axis << "\n";
  os << "device_code = " << device << "\nlatched_at = " << utc(f.latched_at_s) << "\nrows = " << r.rows
     << "\npicks = " << r.picks << "\nbeats = " << r.beats << "\n";
  std::string text = r.text.substr(0, kMaxText);
  for (char& c : text) {
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7F) c = ' ';
  }
  text = trim(text);
  if (!text.empty()) os << "text = " << text << "\n";
  return os.str();
}

LatchedFault LatchedFaultStore::parse(const std::string& text, const std::string& source) {
  std::map<std::string, std::pair<std::string, int>> fields;  // key → value, line
  std::istringstream in(text);
  std::string raw;
  int line = 0;
  const auto refuse = [&](int at, const std::string& field, const std::string& value,
                          const std::string& why) {
    // A CR (a file saved with Windows line ends) and any other control byte shown, never printed raw.
    const bool cr = value.find('\r') != std::string::npos;
    throw ConfigError(
        source + ":" + std::to_string(at) + ": " + field + " = \"" + escaped(value.substr(0, 80)) +
        (value.size() > 80 ? "..." : "") + "\": " + why +
        (cr ? " (the line ends in \\r: the file has Windows line ends (CRLF); serve writes LF only)" : "") +
        " (a latched-fault record; refusing to arm from it — fix or remove the file, then "
        "acknowledge at the loom)");
  };
  while (std::getline(in, raw)) {
    ++line;
    const std::string l = trim(raw);
    if (l.empty() || l[0] == '#') continue;
    const auto eq = l.find('=');
    if (eq == std::string::npos) refuse(line, "line", l, "not `key = value`");
    const std::string key = trim(l.substr(0, eq));
    const std::string value = trim(l.substr(eq + 1));
    static const char* const known[] = {"kind", "fault", "axis",  "device_code", "latched_at",
                                        "rows", "picks", "beats", "text"};
    bool ok = false;
    for (const char* k : known) ok = ok || key == k;
    if (!ok) refuse(line, key, value, "unknown field");
    if (fields.count(key) != 0) {
      refuse(line, key, value, "given twice (first at line " + std::to_string(fields[key].second) + ")");
    }
    fields[key] = {value, line};
  }
  for (const char* k : {"kind", "fault", "latched_at"}) {
    if (fields.count(k) == 0) refuse(line, k, "", "missing");
  }
  LatchedFault f;
  FaultRecord& r = f.record;
  {
    const auto& [v, at] = fields["kind"];
    if (v != "fault" && v != "overrun_stop") refuse(at, "kind", v, "must be fault or overrun_stop");
    r.kind = v;
  }
  {
    const auto& [v, at] = fields["fault"];
    const auto named = fault_named(v);
    if (!named || *named == sequencer::Fault::kNone) refuse(at, "fault", v, "not a fault of the fault table");
    f.fault = *named;
    r.name = v;
    r.code = sequencer::fault_code(f.fault);
  }
  if (fields.count("axis") != 0) {
    const auto& [v, at] = fields["axis"];
    if (v.empty() || v.size() > kMaxAxis ||
        v.find_first_not_of("abcdefghijklmnopqrstuvwxyz0123456789_") != std::string::npos) {
      refuse(at, "axis", v, "an axis name: a-z, 0-9 and _, 1 to 32 characters");
    }
    r.axis = v;
  }
  if (fields.count("device_code") != 0) {
    const auto& [v, at] = fields["device_code"];
    if (v.size() != 6 || v.compare(0, 2, "0x") != 0 ||
        v.find_first_not_of("0123456789ABCDEFabcdef", 2) != std::string::npos) {
      refuse(at, "device_code", v, "must be 0x0000..0xFFFF");
    }
    r.device_code = static_cast<std::uint16_t>(std::stoul(v.substr(2), nullptr, 16));
  }
  {
    const auto& [v, at] = fields["latched_at"];
    std::tm tm{};
    char z = 0;
    int n = 0;
    const bool shaped = v.size() == 20 &&
                        std::sscanf(v.c_str(), "%4d-%2d-%2dT%2d:%2d:%2d%c%n", &tm.tm_year, &tm.tm_mon,
                                    &tm.tm_mday, &tm.tm_hour, &tm.tm_min, &tm.tm_sec, &z, &n) == 7 &&
                        z == 'Z' && n == 20;
    if (shaped) {
      tm.tm_year -= 1900;
      tm.tm_mon -= 1;
      f.latched_at_s = static_cast<std::int64_t>(timegm(&tm));
    }
    // A date that does not exist (2026-02-30) comes back as another one: refused.
    if (!shaped || utc(f.latched_at_s) != v)
      refuse(at, "latched_at", v, "must be a UTC time like 2026-11-26T20:50:03Z");
  }
  for (const char* k : {"rows", "picks", "beats"}) {
    if (fields.count(k) == 0) continue;
    const auto& [v, at] = fields[k];
    std::uint64_t n = 0;
    if (!whole_number(v, UINT32_MAX, n)) refuse(at, k, v, "must be a whole number in 0..4294967295");
    (k[0] == 'r' ? r.rows : k[0] == 'p' ? r.picks : r.beats) = static_cast<std::uint32_t>(n);
  }
  if (fields.count("text") != 0) {
    const auto& [v, at] = fields["text"];
    if (v.size() > kMaxText) refuse(at, "text", v, "longer than 200 bytes");
    for (const char c : v) {
      if (static_cast<unsigned char>(c) < 0x20 || c == 0x7F)
        refuse(at, "text", v, "holds a control character");
    }
    r.text = v;
  }
  return f;
}

std::optional<LatchedFault> LatchedFaultStore::load() const {
  const state::StateFileRead r = state::read_state_file(path_, kMaxBytes);
  switch (r.outcome) {
    case state::StateFileRead::Outcome::kAbsent:
      return std::nullopt;
    case state::StateFileRead::Outcome::kCannotOpen:
      throw ConfigError(path_ + ": latched-fault record exists but cannot be read: " + r.error +
                        " (refusing to arm: a fault may still be latched)");
    case state::StateFileRead::Outcome::kNotRegular:
      throw ConfigError(path_ + ":1: file = \"" + path_ +
                        "\": not a latched-fault record (not a regular file of at most 4 KiB)");
    case state::StateFileRead::Outcome::kCannotRead:
      throw ConfigError(path_ + ": latched-fault record cannot be read: " + r.error);
    case state::StateFileRead::Outcome::kRead:
      break;
  }
  return parse(r.text, path_);
}

void LatchedFaultStore::save(const LatchedFault& f) const {
  state::write_file_durably(path_, format(f), reserve_);
}

void LatchedFaultStore::clear() const {
  if (::unlink(path_.c_str()) != 0) {
    if (errno == ENOENT) return;
    throw std::runtime_error("cannot remove " + path_ + ": " + std::strerror(errno));
  }
  const std::string dir = path_.find('/') == std::string::npos ? "." : path_.substr(0, path_.rfind('/'));
  const int dfd = ::open(dir.empty() ? "/" : dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dfd < 0) throw std::runtime_error("cannot open directory of " + path_ + ": " + std::strerror(errno));
  const int rc = ::fsync(dfd);
  const int err = errno;
  ::close(dfd);
  if (rc != 0 && err != EINVAL)
    throw std::runtime_error("cannot sync directory of " + path_ + ": " + std::strerror(err));
}

}  // namespace loom::firmware::serve
