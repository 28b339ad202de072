// Append-only fault history with one-generation rotation.
#include "loom/firmware/serve/fault_history.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <fstream>
#include <stdexcept>

namespace loom::firmware::serve {

FaultHistory::FaultHistory(std::string path, std::uint64_t max_bytes)
    : path_(std::move(path)), max_bytes_(max_bytes) {}

std::string FaultHistory::format(const FaultRecord& r, std::int64_t unix_s) {
  std::tm tm{};
  const std::time_t t = static_cast<std::time_t>(unix_s);
  gmtime_r(&t, &tm);
  char when[32];
  std::strftime(when, sizeof when, "%Y-%m-%dT%H:%M:%SZ", &tm);
  char buf[512];
  std::snprintf(buf, sizeof buf, "%s %s %s %s 0x%04X%s%s device=0x%04X rows=%u picks=%u beats=%u: %s", when,
                r.kind.c_str(), r.loom_id.c_str(), r.name.c_str(), r.code,
                r.axis.empty() ? "" : " axis=", r.axis.c_str(), r.device_code, r.rows, r.picks, r.beats,
                r.text.c_str());
  std::string line = buf;
  for (char& c : line) {
    if (c == '\n') c = ' ';
  }
  return line;
}

void FaultHistory::append(const FaultRecord& r) {
  const std::string line = format(r, static_cast<std::int64_t>(std::time(nullptr))) + "\n";
  std::lock_guard<std::mutex> lock(mu_);
  struct stat st {};
  if (::stat(path_.c_str(), &st) == 0 && static_cast<std::uint64_t>(st.st_size) + line.size() > max_bytes_) {
    const std::string old = path_ + ".1";
    if (::rename(path_.c_str(), old.c_str()) != 0) {
      throw std::runtime_error("fault history: cannot rotate " + path_ + " to " + old + ": " +
                               std::strerror(errno));
    }
  }
  const int fd = ::open(path_.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0640);
  if (fd < 0) throw std::runtime_error("fault history: cannot open " + path_ + ": " + std::strerror(errno));
  const ssize_t n = ::write(fd, line.data(), line.size());
  const int err = errno;
  const bool synced = ::fsync(fd) == 0;
  ::close(fd);
  if (n != static_cast<ssize_t>(line.size()) || !synced) {
    throw std::runtime_error("fault history: cannot write " + path_ + ": " + std::strerror(err));
  }
}

std::vector<std::string> FaultHistory::read_all() const {
  std::lock_guard<std::mutex> lock(mu_);
  std::vector<std::string> lines;
  for (const std::string& p : {path_ + ".1", path_}) {
    std::ifstream f(p);
    std::string line;
    while (std::getline(f, line)) {
      if (!line.empty()) lines.push_back(line);
    }
  }
  return lines;
}

}  // namespace loom::firmware::serve
