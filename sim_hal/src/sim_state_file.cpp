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
// The machine, then (page-aligned) the knotting heads' carpet.
constexpr std::size_t kCarpetOffset = (sizeof(PersistedMachine) + 4095) / 4096 * 4096;
constexpr std::size_t kFileSize = kCarpetOffset + sizeof(PersistedCarpet);
}  // namespace

SimStateFile::SimStateFile(const std::string& path) {
  // Never truncate or reinterpret a file that is not ours: an existing file must be exactly one
  // PersistedMachine carrying the magic (or empty, as a fresh file is).
  fd_ = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC | O_NOFOLLOW, 0644);
  if (fd_ < 0) throw std::runtime_error("cannot open sim state file " + path + ": " + std::strerror(errno));
  const auto refuse = [&](const std::string& why) {
    ::close(fd_);
    fd_ = -1;
    throw std::invalid_argument(path + ": " + why);
  };
  struct stat st {};
  if (::fstat(fd_, &st) != 0 || !S_ISREG(st.st_mode)) refuse("not a regular file");
  if (st.st_size != 0 && st.st_size != static_cast<off_t>(kFileSize)) {
    refuse("not a loomctl sim-state file (" + std::to_string(st.st_size) + " bytes, expected " +
           std::to_string(kFileSize) + "); not touched");
  }
  // The file's blocks are allocated now (posix_fallocate; a no-op where they exist), never left a sparse
  // hole (ftruncate): a store into a mapped hole on a full disk is a SIGBUS in the loop; here it is a
  // refusal before anything is armed.
  {
    const int rc = ::posix_fallocate(fd_, 0, kFileSize);
    if (rc != 0) {
      ::close(fd_);
      fd_ = -1;
      if (st.st_size == 0) ::unlink(path.c_str());  // ours and empty: leave no file a later run would adopt
      throw std::runtime_error("cannot allocate sim state file " + path + " (" +
                               std::to_string(kFileSize) + " bytes): " + std::strerror(rc));
    }
  }
  void* p = ::mmap(nullptr, kFileSize, PROT_READ | PROT_WRITE, MAP_SHARED, fd_, 0);
  if (p == MAP_FAILED) {
    ::close(fd_);
    throw std::runtime_error("cannot map sim state file " + path + ": " + std::strerror(errno));
  }
  map_ = static_cast<PersistedMachine*>(p);
  carpet_ = reinterpret_cast<PersistedCarpet*>(static_cast<char*>(p) + kCarpetOffset);
  if (st.st_size != 0) {
    const PersistedMachine& m = *map_;
    std::string why;
    if (m.magic != PersistedMachine::kMagic) why = "not a loomctl sim-state file (no LOOMSIM2 magic); not touched";
    for (double x : m.added_axis_position) {
      if (why.empty() && !(std::isfinite(x) && std::abs(x) <= kMaxAbsPosition)) why = "axis position " + std::to_string(x) + " is not plausible";
    }
    for (double x : m.axis_position) {
      if (why.empty() && !(std::isfinite(x) && std::abs(x) <= kMaxAbsPosition)) why = "axis position " + std::to_string(x) + " is not plausible";
    }
    for (double x : m.piston) {
      if (why.empty() && !(x >= 0.0 && x <= 1.0)) why = "piston stroke fraction " + std::to_string(x) + " is outside [0, 1]";
    }
    if (why.empty() && !(std::isfinite(m.shuttle_x) && std::abs(m.shuttle_x) <= 100.0)) {
      why = "shuttle position " + std::to_string(m.shuttle_x) + " m is not plausible";
    }
    if (!why.empty()) {
      ::munmap(map_, kFileSize);
      map_ = nullptr;
      carpet_ = nullptr;
      refuse(why);
    }
  }
}

SimStateFile::~SimStateFile() {
  if (map_ != nullptr) ::munmap(map_, kFileSize);
  if (fd_ >= 0) ::close(fd_);
}

bool SimStateFile::load(PersistedMachine& out) const {
  if (map_->magic != PersistedMachine::kMagic) return false;
  out = *map_;
  return true;
}

void SimStateFile::store(const PersistedMachine& s) noexcept { *map_ = s; }

}  // namespace loom::sim_hal
