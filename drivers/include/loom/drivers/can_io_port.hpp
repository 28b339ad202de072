// The loom's I/O node as a CANopen CiA 401 generic I/O module behind hal::IoPort: valve coils and the
// stack light through 0x6200 in an RPDO, end sensors, shuttle sensors, the e-stop chain and the operator
// buttons through 0x6000 (8-bit groups) or 0x6100 (16-bit groups, CanIoConfig::input_group_bits) in a TPDO,
// the beater's load cell through 0x6401 in a TPDO. Which bit is which signal, its polarity and the load-cell
// scaling are wiring (config), so any module can be used.
//
// A loom may spread its signals over several modules (IoBit::module; CanIoModules joins them into one
// hal::IoPort). Each module is a CanNode of its bus' CanMaster (can_master.hpp): the master brings it up
// in the same NMT sequence as that bus' drives, drains the bus once per tick and hands this node's frames
// here, and supervises it (heartbeat, boot-up, EMCY), so a fault of this node stops every axis in the
// same tick. This class only does the CiA 401 profile. configure_profile() may block (SDO); the rest is
// RT-safe.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "loom/drivers/bus_load.hpp"
#include "loom/drivers/can_frame.hpp"
#include "loom/drivers/can_io_config.hpp"
#include "loom/drivers/can_master.hpp"
#include "loom/drivers/configure_clock.hpp"
#include "loom/drivers/status.hpp"
#include "loom/hal/hal.hpp"

namespace loom::drivers {

// The output values the module is told to adopt by itself on failure (0x6206/0x6207): both valve coils
// de-energised (frames retracted and vented; no shed, so no pick can start and nothing is trapped),
// green/amber off, red on, buzzer off, every knotting head's gripper open and cutter retracted.
hal::DigitalOutputs io_safe_outputs() noexcept;

class CanIoPort final : public hal::IoPort, public CanNode {
 public:
  static constexpr int kMaxPdoEntries = 8;

  // Configure-time only.
  explicit CanIoPort(CanIoConfig config);

  // Configure-time only. The master settings of a network of this module alone (its cycle and timeouts,
  // no master heartbeat): a module is brought up only by a CanNetwork (can_network.hpp) it is registered
  // on — alone, or on its bus beside the drives (CanNetwork::add) — in that bus' one NMT sequence:
  // reset-node → boot-up → configure_profile() → NMT start → operational heartbeat. The network then polls
  // it every tick.
  CanMasterConfig master_config() const;

  // What the bring-up found optional and absent, or accepted instead of what it asked for (one line each).
  const std::vector<std::string>& notes() const { return notes_; }

  // hal::IoPort (RT-safe).
  void read_io(hal::Tick now, const hal::AxisFeedbacks& axes, hal::DigitalInputs& io) noexcept override;
  // RT-safe. Only the signals wired to this module into `io` (the others untouched: another module's),
  // and when its inputs were last refreshed (kNeverTick before the first TPDO).
  void read_wired(hal::DigitalInputs& io) const noexcept;
  hal::Tick inputs_refreshed() const noexcept { return inputs_refreshed_; }
  bool has_load_cell() const noexcept { return wiring_.load_cell_channel != 0; }
  void read_analog(hal::Tick now, hal::AnalogInputs& analog) noexcept override;
  void write_io(hal::Tick now, const hal::DigitalOutputs& io) noexcept override;

  // CanNode. configure_profile(): device type 0x1000 is CiA 401 → 0x1017 → 0x6206/0x6207 (safe outputs)
  // → 0x1016 consumer of the master heartbeat → PDO mapping (written, or read back when the module's
  // mapping is fixed, and accepted only when it carries every object the wiring needs).
  std::uint8_t node_id() const override { return config_.node_id; }
  std::string label() const override;
  const NodeDescription* description() const override { return config_.description.get(); }
  NodeTiming timing() const override;
  void bring_up_started() override;
  Status configure_profile(SdoClient& sdo) override;
  void brought_up(CanBus& bus) override;
  void on_profile_frame(hal::Tick now, const CanFrame& frame) noexcept override;  // RT-safe

  // Diagnostics; RT-safe.
  bool configured() const noexcept { return configured_; }
  const CanIoConfig& config() const { return config_; }
  std::uint16_t last_emcy_code() const noexcept { return supervisor_.emcy_code(); }
  std::uint32_t tx_dropped() const noexcept { return tx_dropped_; }

 private:
  // Where one object sits in the PDOs the module actually uses (after the bring-up).
  struct Slot {
    int pdo = -1;  // 0..3, −1 = not mapped
    std::uint8_t offset = 0;
    std::uint8_t bytes = 0;
  };
  struct PdoLayout {
    std::uint8_t count = 0;
    std::array<std::uint32_t, kMaxPdoEntries> entries{};
  };

  // Subs of 0x6000 (8-bit groups) the master can read (kIoMaxInputBits); 0x6100 (16-bit) uses half.
  static constexpr std::size_t kMaxInputSubs = kIoMaxInputBits / 8;
  static constexpr std::size_t kMaxInputBytes = kIoMaxInputBits / 8;

  Status configure_mapping(class SdoClient& sdo);
  // The mapping entry of input group `sub` (0x6000:sub/8 or 0x6100:sub/16).
  std::uint32_t input_entry(std::uint8_t sub) const;
  Status locate(const std::array<PdoLayout, 4>& layouts, std::uint32_t wanted, const std::string& what,
                Slot& slot) const;
  Status locate_inputs(std::uint8_t subs);
  Status explain_refused_input(const Status& s, std::uint32_t entry, std::uint8_t subs) const;
  // `refused` (optional): the mapping entry the module refused to take, 0 when none was.
  Status map_pdo(SdoClient& sdo, bool rx, int pdo, const std::vector<std::uint32_t>& wanted,
                 std::uint8_t transmission_type, PdoLayout& actual, std::uint32_t* refused = nullptr);
  Status disable_pdo(SdoClient& sdo, bool rx, int pdo);
  static Slot find(const std::array<PdoLayout, 4>& layouts, std::uint32_t entry_without_len);
  std::string who() const;
  bool input(const IoBit& b) const noexcept;

  CanIoConfig config_;
  IoWiring wiring_;  // this module's signals: module_wiring(config_.wiring, config_.module)
  int group_bits_;   // its digital inputs as 8-bit (0x6000) or 16-bit (0x6100) groups
  CanBus* bus_ = nullptr;
  bool configured_ = false;
  std::vector<std::string> notes_;

  std::array<PdoLayout, 4> tpdo_{};
  std::array<PdoLayout, 4> rpdo_{};
  // 8-bit subs of 0x6200 the master can write (kIoMaxOutputBits).
  static constexpr std::size_t kMaxOutputSubs = kIoMaxOutputBits / 8;

  std::array<Slot, kMaxInputSubs> input_slot_{};    // 0x6000:01..08 / 0x6100:01..04 (pdo −1: not read)
  int input_pdo_ = -1;                              // the one TPDO carrying the digital inputs
  std::array<Slot, kMaxOutputSubs> output_slot_{};  // 0x6200:01..08
  Slot analog_slot_{};
  int output_pdo_ = -1;
  std::uint8_t output_pdo_bytes_ = 0;

  // RT state.
  std::array<std::uint8_t, kMaxInputBytes> inputs_{};  // terminals 0..63, 8 per byte, whatever the groups
  hal::Tick inputs_refreshed_ = hal::kNeverTick;
  std::int16_t analog_counts_ = 0;
  hal::Tick analog_refreshed_ = hal::kNeverTick;
  std::uint32_t tx_dropped_ = 0;
};

}  // namespace loom::drivers
