// Atomic counter persistence as a tiny JSON object {"rows":R,"picks":P,"beats":B,"picks_in_row":K}.
#include "loom/firmware/counter_store.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <regex>
#include <sstream>
#include <stdexcept>

#include "loom/firmware/config.hpp"

namespace loom::firmware {
namespace {
[[noreturn]] void sys_fail(const std::string& what, const std::string& path) {
  throw std::runtime_error(what + " " + path + ": " + std::strerror(errno));
}
}  // namespace

std::optional<sequencer::Counters> CounterStore::load() const {
  std::ifstream f(path_);
  if (!f) return std::nullopt;
  std::ostringstream os;
  os << f.rdbuf();
  const std::string text = os.str();
  sequencer::Counters c;
  const auto field = [&](const char* key, std::uint32_t& out) {
    const std::regex re(std::string("\"") + key + "\"\\s*:\\s*([0-9]{1,10})");
    std::smatch m;
    if (!std::regex_search(text, m, re)) {
      throw ConfigError(path_ + ": counters file lacks a valid \"" + key + "\" (file: " + text.substr(0, 80) + ")");
    }
    out = static_cast<std::uint32_t>(std::stoul(m[1]));
  };
  field("rows", c.rows);
  field("picks", c.picks);
  field("beats", c.beats);
  field("picks_in_row", c.picks_in_row);
  return c;
}

void CounterStore::save(const sequencer::Counters& c) const {
  std::ostringstream os;
  os << "{\"rows\":" << c.rows << ",\"picks\":" << c.picks << ",\"beats\":" << c.beats
     << ",\"picks_in_row\":" << c.picks_in_row << "}\n";
  const std::string body = os.str();
  const std::string tmp = path_ + ".tmp";
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) sys_fail("cannot create", tmp);
  const ssize_t n = ::write(fd, body.data(), body.size());
  if (n != static_cast<ssize_t>(body.size()) || ::fsync(fd) != 0) {
    ::close(fd);
    sys_fail("cannot write", tmp);
  }
  ::close(fd);
  if (::rename(tmp.c_str(), path_.c_str()) != 0) sys_fail("cannot rename onto", path_);
  // Make the rename itself durable.
  const std::string dir = path_.find('/') == std::string::npos ? "." : path_.substr(0, path_.rfind('/'));
  const int dfd = ::open(dir.empty() ? "/" : dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dfd >= 0) {
    ::fsync(dfd);
    ::close(dfd);
  }
}

}  // namespace loom::firmware
