// Reads a loom config's [beatup] section with toml++ (see beatup_config.hpp). Every refusal is one
// line: "file:line:col: beatup.key = value: why".
#include "loom/cli/beatup_config.hpp"

#include <cmath>
#include <sstream>
#include <toml++/toml.h>

#include "loom/cli/run.hpp"

namespace loom::cli {

namespace {

std::string where(const std::string& path, const toml::source_region& r) {
  std::ostringstream s;
  s << path << ':' << r.begin.line << ':' << r.begin.column;
  return s.str();
}

class Section {
 public:
  Section(std::string path, const toml::table& t, const toml::source_region& r)
      : path_(std::move(path)), t_(t), region_(r) {}

  std::optional<double> number(const char* key, bool required) const {
    const toml::node* n = t_.get(key);
    if (n == nullptr) {
      if (required) throw UsageError(where(path_, region_) + ": [beatup] has no " + key);
      return std::nullopt;
    }
    std::optional<double> v = n->value<double>();  // integers convert too
    if (!v) throw UsageError(where(path_, n->source()) + ": beatup." + key + ": must be a number");
    if (!std::isfinite(*v) || !(*v > 0.0)) {
      std::ostringstream s;
      s << where(path_, n->source()) << ": beatup." << key << " = " << *v << ": must be positive and finite";
      throw UsageError(s.str());
    }
    return v;
  }

  std::string choice(const char* key, const char* fallback, std::initializer_list<const char*> allowed) const {
    const toml::node* n = t_.get(key);
    if (n == nullptr) return fallback;
    const std::optional<std::string> v = n->value<std::string>();
    std::string list;
    for (const char* a : allowed) {
      if (v && *v == a) return *v;
      list += list.empty() ? "" : ", ";
      list += std::string("\"") + a + "\"";
    }
    throw UsageError(where(path_, n->source()) + ": beatup." + key + " = " + (v ? "\"" + *v + "\"" : "?") +
                     ": must be one of " + list);
  }

 private:
  std::string path_;
  const toml::table& t_;
  toml::source_region region_;
};

}  // namespace

BeatupConfig read_beatup_config(const std::string& path) {
  toml::table root;
  try {
    root = toml::parse_file(path);
  } catch (const toml::parse_error& e) {
    const auto& b = e.source().begin;
    std::ostringstream s;
    s << path << ':' << b.line << ':' << b.column << ": " << e.description();
    throw UsageError(s.str());
  }
  const toml::table* bt = root["beatup"].as_table();
  if (bt == nullptr) throw UsageError(path + ": no [beatup] section (the beat-up linkage of the loom)");
  const Section s(path, *bt, bt->source());

  BeatupConfig c;
  motion::BeatUpGeometry& g = c.geometry;
  g.bar.crank = *s.number("crank_m", true);
  g.bar.coupler = *s.number("coupler_m", true);
  g.bar.rocker = *s.number("rocker_m", true);
  g.bar.ground = *s.number("ground_m", true);
  g.beater_arm_m = *s.number("beater_arm_m", true);
  g.branch = s.choice("branch", "positive", {"positive", "negative"}) == "positive" ? motion::Branch::kPositive
                                                                                    : motion::Branch::kNegative;
  g.fell_at = s.choice("fell_at", "extended", {"extended", "folded"}) == "extended" ? motion::FellSide::kExtended
                                                                                   : motion::FellSide::kFolded;
  if (const auto w = s.number("warp_depth_m", false)) g.warp_depth_m = *w;
  if (const auto m = s.number("beater_mass_kg", false)) c.beater_mass_kg = *m;
  c.crank_speed_rad_s = s.number("crank_speed_rad_s", false);
  c.beat_force_target_n = s.number("beat_force_target_n", false);
  return c;
}

}  // namespace loom::cli
