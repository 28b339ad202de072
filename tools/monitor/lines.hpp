// The text loom-monitor prints, kept apart from main.cpp so the exact format is unit-tested.
// Two styles:
//  - per-channel lines (`--channel status|axes|rt|beat|fault|row`): one key=value line per message,
//    fields separated by single spaces, for grep and scripts;
//  - the event view (the default): what a person reads — one line per event (state change, beat, row
//    done with its force summary, fault with its text) plus a compact status line at most once per
//    second of loop time.
// Codes are printed in hex as the fault table and drive manuals write them (0x1002, 0x8611).
#pragma once

#include <map>
#include <string>
#include <vector>

#include "loomlcm/axes_t.hpp"
#include "loomlcm/beat_t.hpp"
#include "loomlcm/design_t.hpp"
#include "loomlcm/fault_t.hpp"
#include "loomlcm/knots_t.hpp"
#include "loomlcm/row_t.hpp"
#include "loomlcm/rt_stats_t.hpp"
#include "loomlcm/status_t.hpp"
#include "loomlcm/weaver_request_t.hpp"

namespace loom::monitor {

// loom=<id> tick=<n> t=<s.mmm>s state=<name> row=<in progress> done=<n> pick=<n> beat=<n>
//   fault=<name|none> fault_code=0x<hhhh> [axis=<name> device_code=0x<hhhh> text="<operator text>"]
std::string status_line(const loomlcm::status_t& m);
// axes loom=<id> tick=<n> t=<s>s crank_phase=<rad> beater=<rad> force=<N>N then per axis
// " | <name> pos=.. vel=.. tgt=.. ferr=.. lim=.. eff=.. drive=<state> unit=<rad|m>" (+ " code=0x<hhhh>" when
// non-zero; no unit= from a publisher that sends none)
std::string axes_line(const loomlcm::axes_t& m);
// rt loom=<id> tick=<n> t=<s>s overruns=<n> tick_cost_us=<us> max_tick_cost_us=<us> wake_p50_us=..
//   wake_p99_us=.. wake_max_us=.. dropped=<n> dropped_events=<n> backlog=<n> can_tx_dropped=<n>
//   can_rx_errors=<n>
std::string rt_line(const loomlcm::rt_stats_t& m);
// beat loom=<id> t=<s>s row=<n> index=<k> x=<m>m force=<N>N in_band=yes|no|unmeasured
std::string beat_line(const loomlcm::beat_t& m);
// fault loom=<id> t=<s>s kind=<first|diagnosis|device> name=<n> code=0x<hhhh> axis=<name|->
// device_code=0x<hhhh>
//   state=<s> row=<n> pick=<n> beat=<n> text="<operator text>"
std::string fault_line(const loomlcm::fault_t& m);
// row loom=<id> t=<s>s row=<n> time=<s>s shed=<s>s pick=<s>s beat=<s>s beats=<n> steps=<n>
//   force_min=<N>N force_mean=<N>N force_max=<N>N in_band=<k>/<n>   (force fields "-" when unmeasured)
//   knotting=<s>s, then for a row the knotting heads tied:
//   knots_tied=<n> knots_retried=<n> knots_by_hand=<n> knot_time=<s>s weaver_time=<s>s
std::string row_line(const loomlcm::row_t& m);
// weaver loom=<id> t=<s>s n=<request number> ask=<tie_by_hand|reload|check_knot> row=<n> design_row=<0-based>
//   knot=<0-based|-1> head=<0-based> slot=<n> colour=<code|-> text="<the request in the weaver's words>"
std::string weaver_line(const loomlcm::weaver_request_t& m);
// knots loom=<id> tick=<n> t=<s>s state=<name> row=<n> design_row=<0-based> cycle=<j|-1>/<stripe>
//   cycles_done=<n> tied=<n> retried=<n> by_hand=<n> row_tied=<n> row_retried=<n> row_by_hand=<n>
//   requests=<n> ask=<name|-> then per head " | head<h> knot=<k|-1> colour=<code|->
//   stock=<slot0>,<slot1>,..."
std::string knots_line(const loomlcm::knots_t& m);
std::string design_line(const loomlcm::design_t& m);

// Received text is printed only after replacing spaces and non-printable bytes with '?', so a
// malformed or hostile message cannot break the one-line, space-separated format.
std::string printable_field(const std::string& s);
// Free text (fault texts) keeps its spaces but loses control bytes and quotes.
std::string printable_text(const std::string& s);

// The default, human view. Feed it messages in arrival order; each call returns the lines to print
// (possibly none). Keeps a little state per loom id (bounded by the looms heard).
class EventView {
 public:
  explicit EventView(double status_every_s = 1.0, bool show_beats = true)
      : status_every_s_(status_every_s), show_beats_(show_beats) {}
  std::vector<std::string> on_status(const loomlcm::status_t& m);
  std::vector<std::string> on_beat(const loomlcm::beat_t& m);
  std::vector<std::string> on_fault(const loomlcm::fault_t& m);
  std::vector<std::string> on_row(const loomlcm::row_t& m);
  std::vector<std::string> on_rt(const loomlcm::rt_stats_t& m);
  // One line per request the knotting heads make of the weaver.
  std::vector<std::string> on_weaver(const loomlcm::weaver_request_t& m);
  // A line only when the row to knot next changes (DESIGN repeats every second).
  std::vector<std::string> on_design(const loomlcm::design_t& m);

 private:
  struct Loom {
    std::string state;
    double last_status_t = -1e300;
    std::int64_t last_tick = -1;
    std::int64_t overruns = 0, dropped = 0, dropped_events = 0, can_tx_dropped = 0, can_rx_errors = 0;
    bool rt_seen = false;
    std::int64_t design_rows_done = -1;
  };
  double status_every_s_;
  bool show_beats_;
  std::map<std::string, Loom> looms_;
};

}  // namespace loom::monitor
