// mmap-backed machine state for power-loss simulation.
#include "loom/sim_hal/sim_state_file.hpp"

#include <fcntl.h>
#include <sys/mman.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>

namespace loom::sim_hal {

SimStateFile::SimStateFile(const std::string& path) {
  fd_ = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd_ < 0) throw std::runtime_error("cannot open sim state file " + path + ": " + std::strerror(errno));
  if (::ftruncate(fd_, sizeof(PersistedMachine)) != 0) {
    ::close(fd_);
    throw std::runtime_error("cannot size sim state file " + path + ": " + std::strerror(errno));
  }
  void* p = ::mmap(nullptr, sizeof(PersistedMachine), PROT_READ | PROT_WRITE, MAP_SHARED, fd_, 0);
  if (p == MAP_FAILED) {
    ::close(fd_);
    throw std::runtime_error("cannot map sim state file " + path + ": " + std::strerror(errno));
  }
  map_ = static_cast<PersistedMachine*>(p);
}

SimStateFile::~SimStateFile() {
  if (map_ != nullptr) ::munmap(map_, sizeof(PersistedMachine));
  if (fd_ >= 0) ::close(fd_);
}

bool SimStateFile::load(PersistedMachine& out) const {
  if (map_->magic != PersistedMachine::kMagic) return false;
  out = *map_;
  return true;
}

void SimStateFile::store(const PersistedMachine& s) noexcept { *map_ = s; }

}  // namespace loom::sim_hal
