// The simulated machine's physical state kept in a memory-mapped file, so that killing the controller
// (a power cut) leaves the simulated loom where it physically was: the next run starts from there, as a
// real loom would. Stores are plain memory writes into an already-mapped page (RT-safe); the kernel
// keeps the page when the process dies.
#pragma once

#include <array>
#include <cstdint>
#include <string>

#include "loom/hal/types.hpp"
#include "loom/sim_hal/knotter.hpp"

namespace loom::sim_hal {

struct PersistedMachine {
  std::uint64_t magic = 0;                // kMagic once written
  std::array<double, 3> axis_position{};  // the core axes (this layout first: tools read it with od)
  std::array<double, 2> piston{};
  double shuttle_x = 0.0;
  std::uint64_t tick = 0;
  std::array<double, hal::kMaxAxes - hal::kCoreAxisCount>
      added_axis_position{};                                      // slots 3.. (knotting heads)
  static constexpr std::uint64_t kMagic = 0x4c4f4f4d53494d32ull;  // "LOOMSIM2"
};

// The file: the machine (one page), then the knotting heads' carpet (its header and one byte per knot), as
// long as the carpet needs: a file without heads ends after the carpet's header; reserve() grows it.
class SimStateFile final : public CarpetKeeper {
 public:
  // Configure-time only. Opens (creating) and maps `path`; throws std::runtime_error naming the path
  // when it cannot, and std::invalid_argument (nothing written) when the file exists but is not a
  // sim-state file or holds implausible values (NaN, 1e300).
  explicit SimStateFile(const std::string& path);
  static constexpr double kMaxAbsPosition = 1.0e6;  // rad or m: beyond any unwrapped axis reading
  ~SimStateFile();
  SimStateFile(const SimStateFile&) = delete;
  SimStateFile& operator=(const SimStateFile&) = delete;

  // Configure-time. True (and fills `out`) when the file holds a state from an earlier run.
  bool load(PersistedMachine& out) const;
  // RT-safe.
  void store(const PersistedMachine& s) noexcept;
  // The knotting heads' persisted carpet and magazines, in the same file after the machine (the knotter
  // effect keeps them there directly: the carpet survives the power cut as the real one would).
  CarpetKeeper* carpet() noexcept { return this; }
  // Configure-time (CarpetKeeper). Grows the file (blocks allocated, never a sparse hole) and maps it again;
  // throws std::runtime_error naming the path and size when the disk has no room (the file is left as it
  // was).
  PersistedCarpet& reserve(std::size_t cells) override;
  std::size_t room() const noexcept override { return room_; }

 private:
  void map(std::size_t bytes);
  std::string path_;
  int fd_ = -1;
  std::size_t size_ = 0;  // bytes mapped (the file's size)
  std::size_t room_ = 0;  // knots of carpet after its header
  PersistedMachine* map_ = nullptr;
  PersistedCarpet* carpet_ = nullptr;
};

}  // namespace loom::sim_hal
