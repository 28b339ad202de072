// mmap-backed machine state for power-loss simulation.
#include "loom/sim_hal/sim_state_file.hpp"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <stdexcept>

namespace loom::sim_hal {
namespace {
// The machine, then (page-aligned) the knotting heads' carpet: its header, then its cells (as many as the
// carpet has room for: the file's size says how many).
constexpr std::size_t kCarpetOffset = (sizeof(PersistedMachine) + 4095) / 4096 * 4096;
constexpr std::size_t kMinFileSize = kCarpetOffset + sizeof(PersistedCarpet);
constexpr std::size_t kMaxFileSize = std::size_t{1}
                                     << 32;  // 4 GiB: far beyond any carpet (a 1e6-row one is 360 MB)
}  // namespace

void SimStateFile::map(std::size_t bytes) {
  void* p = ::mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_SHARED, fd_, 0);
  if (p == MAP_FAILED)
    throw std::runtime_error("cannot map sim state file " + path_ + ": " + std::strerror(errno));
  map_ = static_cast<PersistedMachine*>(p);
  carpet_ = reinterpret_cast<PersistedCarpet*>(static_cast<char*>(p) + kCarpetOffset);
  size_ = bytes;
  room_ = bytes - kMinFileSize;
}

PersistedCarpet& SimStateFile::reserve(std::size_t cells) {
  if (cells <= room_) return *carpet_;
  const std::size_t bytes = kMinFileSize + cells;
  if (bytes > kMaxFileSize) {
    throw std::runtime_error("sim state file " + path_ + ": a carpet of " + std::to_string(cells) +
                             " knots is beyond the simulator's record");
  }
  // Blocks allocated before the file is mapped longer (as at creation): a full disk is a refusal here, not a
  // SIGBUS in the tick. On failure the file and its mapping stay as they were.
  if (const int rc = ::posix_fallocate(fd_, 0, static_cast<off_t>(bytes)); rc != 0) {
    throw std::runtime_error("cannot allocate sim state file " + path_ + " for a carpet of " +
                             std::to_string(cells) + " knots (" + std::to_string(bytes) +
                             " bytes): " + std::strerror(rc));
  }
  ::munmap(map_, size_);
  map_ = nullptr;
  carpet_ = nullptr;
  map(bytes);
  return *carpet_;
}

SimStateFile::SimStateFile(const std::string& path) : path_(path) {
  // Never truncate or reinterpret a file that is not ours: an existing file must start with one
  // PersistedMachine carrying the magic, followed by a carpet (or be empty, as a fresh file is).
  fd_ = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC | O_NOFOLLOW, 0644);
  if (fd_ < 0) throw std::runtime_error("cannot open sim state file " + path + ": " + std::strerror(errno));
  const auto refuse = [&](const std::string& why) {
    ::close(fd_);
    fd_ = -1;
    throw std::invalid_argument(path + ": " + why);
  };
  struct stat st {};
  if (::fstat(fd_, &st) != 0 || !S_ISREG(st.st_mode)) refuse("not a regular file");
  if (st.st_size != 0 &&
      (st.st_size < static_cast<off_t>(kMinFileSize) || st.st_size > static_cast<off_t>(kMaxFileSize))) {
    refuse("not a loomctl sim-state file (" + std::to_string(st.st_size) + " bytes, expected " +
           std::to_string(kMinFileSize) + " to " + std::to_string(kMaxFileSize) + "); not touched");
  }
  const std::size_t bytes = st.st_size == 0 ? kMinFileSize : static_cast<std::size_t>(st.st_size);
  // The file's blocks are allocated now (posix_fallocate; a no-op where they exist), never left a sparse
  // hole (ftruncate): a store into a mapped hole on a full disk is a SIGBUS in the loop; here it is a
  // refusal before anything is armed.
  {
    const int rc = ::posix_fallocate(fd_, 0, static_cast<off_t>(bytes));
    if (rc != 0) {
      ::close(fd_);
      fd_ = -1;
      if (st.st_size == 0) ::unlink(path.c_str());  // ours and empty: leave no file a later run would adopt
      throw std::runtime_error("cannot allocate sim state file " + path + " (" + std::to_string(bytes) +
                               " bytes): " + std::strerror(rc));
    }
  }
  try {
    map(bytes);
  } catch (const std::runtime_error&) {
    ::close(fd_);
    fd_ = -1;
    throw;
  }
  if (st.st_size != 0) {
    const PersistedMachine& m = *map_;
    std::string why;
    if (m.magic != PersistedMachine::kMagic)
      why = "not a loomctl sim-state file (no LOOMSIM2 magic); not touched";
    for (double x : m.added_axis_position) {
      if (why.empty() && !(std::isfinite(x) && std::abs(x) <= kMaxAbsPosition))
        why = "axis position " + std::to_string(x) + " is not plausible";
    }
    for (double x : m.axis_position) {
      if (why.empty() && !(std::isfinite(x) && std::abs(x) <= kMaxAbsPosition))
        why = "axis position " + std::to_string(x) + " is not plausible";
    }
    for (double x : m.piston) {
      if (why.empty() && !(x >= 0.0 && x <= 1.0))
        why = "piston stroke fraction " + std::to_string(x) + " is outside [0, 1]";
    }
    if (why.empty() && !(std::isfinite(m.shuttle_x) && std::abs(m.shuttle_x) <= 100.0)) {
      why = "shuttle position " + std::to_string(m.shuttle_x) + " m is not plausible";
    }
    if (!why.empty()) {
      ::munmap(map_, size_);
      map_ = nullptr;
      carpet_ = nullptr;
      refuse(why);
    }
  }
}

SimStateFile::~SimStateFile() {
  if (map_ != nullptr) ::munmap(map_, size_);
  if (fd_ >= 0) ::close(fd_);
}

bool SimStateFile::load(PersistedMachine& out) const {
  if (map_->magic != PersistedMachine::kMagic) return false;
  out = *map_;
  return true;
}

void SimStateFile::store(const PersistedMachine& s) noexcept {
  *map_ = s;
}

}  // namespace loom::sim_hal
