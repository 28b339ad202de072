// The CAN network (see can_network.hpp): one master per bus, brought up in bus order, polled and
// reported as one link.
#include "loom/drivers/can_network.hpp"

#include <algorithm>
#include <string>

#include "loom/drivers/emcy.hpp"

namespace loom::drivers {

namespace {

// How bad a recovery state is, for reporting the worst over several buses.
int rank(hal::LinkRecovery r) noexcept {
  switch (r) {
    case hal::LinkRecovery::kHealthy:
      return 0;
    case hal::LinkRecovery::kReady:
      return 1;
    case hal::LinkRecovery::kNodeSilent:
      return 2;
    case hal::LinkRecovery::kBusOff:
      return 3;
  }
  return 0;
}

}  // namespace

CanNetwork::CanNetwork(const CanMasterConfig& config, std::size_t bus_count)
    : n_buses_(std::min(bus_count, kMaxBuses)) {
  for (CanMaster& m : masters_) m = CanMaster(config);
}

bool CanNetwork::add(CanNode& node, std::size_t bus) {
  return bus < n_buses_ && masters_[bus].add(node);
}

void CanNetwork::clear_nodes() {
  for (CanMaster& m : masters_) m.clear_nodes();
}

std::size_t CanNetwork::node_count() const {
  std::size_t n = 0;
  for (std::size_t b = 0; b < n_buses_; ++b) n += masters_[b].node_count();
  return n;
}

Status CanNetwork::configure(CanBus& bus, ConfigureClock& clock) {
  CanBus* const one[] = {&bus};
  return configure(std::span<CanBus* const>(one), clock);
}

Status CanNetwork::configure(std::span<CanBus* const> buses, ConfigureClock& clock) {
  configured_ = false;
  if (buses.size() != n_buses_) {
    return Status::error("the network has " + std::to_string(n_buses_) + " CAN bus(es) but " +
                         std::to_string(buses.size()) + " interface(s) were given");
  }
  for (std::size_t b = 0; b < n_buses_; ++b) {
    if (buses[b] == nullptr) return Status::error("bus " + std::to_string(b) + ": no interface");
    if (Status s = masters_[b].bring_up(*buses[b], clock); !s) return s;
  }
  configured_ = true;
  return Status::ok();
}

// ---------------------------------------------------------------------------------------------------
// Per tick (RT-safe)
// ---------------------------------------------------------------------------------------------------
void CanNetwork::poll(hal::Tick now) noexcept {
  if (!configured_) return;
  for (std::size_t b = 0; b < n_buses_; ++b) masters_[b].poll(now);
}

void CanNetwork::read_link(hal::Tick now, hal::LinkStatus& link) noexcept {
  link = hal::LinkStatus{};
  if (!configured_) {
    link.link_fault = true;
    link.link_fault_code = fault_code::kCommunication;
    link.link_fault_kind = hal::FaultKind::kCommunication;
  }
  for (std::size_t b = 0; b < n_buses_; ++b) masters_[b].report_link(link);
  // The worst recovery state over the buses: a bus-off first, then a silent node, then ready.
  link.recovery = configured_ ? hal::LinkRecovery::kHealthy : hal::LinkRecovery::kReady;
  for (std::size_t b = 0; b < n_buses_; ++b) {
    std::uint8_t silent = 0;
    const hal::LinkRecovery r = masters_[b].recovery(now, silent);
    if (rank(r) > rank(link.recovery)) {
      link.recovery = r;
      link.silent_node = r == hal::LinkRecovery::kNodeSilent ? silent : 0;
    }
  }
  link_edge_.raise(link);
}

void CanNetwork::start_cycle(hal::Tick now) noexcept {
  if (!configured_) return;
  for (std::size_t b = 0; b < n_buses_; ++b) masters_[b].start_cycle(now);
}

void CanNetwork::acknowledge() noexcept {
  for (std::size_t b = 0; b < n_buses_; ++b) masters_[b].acknowledge();
}

bool CanNetwork::any_fault() const noexcept {
  for (std::size_t b = 0; b < n_buses_; ++b) {
    if (masters_[b].any_fault()) return true;
  }
  return false;
}

}  // namespace loom::drivers
