#include "loom/telemetry/job_events.hpp"

#include <lcm/lcm.h>

#include <algorithm>
#include <stdexcept>

#include "loom/telemetry/channels.hpp"

namespace loom::telemetry {

namespace {

std::int64_t wall_utime() {
  return std::chrono::duration_cast<std::chrono::microseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

std::int64_t clamp64(std::uint64_t v) {
  return static_cast<std::int64_t>(std::min<std::uint64_t>(v, INT64_MAX));
}

}  // namespace

double JobReport::eta_s() const {
  if (row_mean_s < 0.0) return -1.0;
  const std::uint64_t left = rows_total > rows_done ? rows_total - rows_done : 0;
  return static_cast<double>(left) * row_mean_s;
}

loomlcm::job_t to_job(const JobReport& r, const std::string& loom_id, std::int64_t utime) {
  loomlcm::job_t m;
  m.utime = utime;
  m.loom_id = loom_id;
  m.job_id = static_cast<std::int32_t>(r.job_id);
  m.state = r.state;
  m.design_name = r.design_name;
  m.design_hash = r.design_hash;
  m.width = r.width;
  m.design_rows = r.design_rows;
  m.rows_done = clamp64(r.rows_done);
  m.rows_total = clamp64(r.rows_total);
  m.heads = static_cast<std::int16_t>(r.stock.size());
  m.stripe = static_cast<std::int16_t>(r.stripe);
  m.cycles_done = static_cast<std::int32_t>(r.cycles_done);
  m.row_mean_s = r.row_mean_s;
  m.eta_s = r.eta_s();
  m.slots = static_cast<std::int16_t>(r.slot_colours.size());
  m.knots_per_slot = r.knots_per_slot;
  m.slot_colour = r.slot_colours;
  for (const auto& head : r.stock) {
    std::vector<std::int32_t> row(r.slot_colours.size(), -1);
    std::copy_n(head.begin(), std::min(head.size(), row.size()), row.begin());
    m.stock.push_back(std::move(row));
  }
  m.n_jobs = static_cast<std::int16_t>(std::min<std::size_t>(r.queue.size(), INT16_MAX));
  for (std::size_t i = 0; i < static_cast<std::size_t>(m.n_jobs); ++i) {
    const JobLine& j = r.queue[i];
    m.queue_id.push_back(static_cast<std::int32_t>(j.id));
    m.queue_design.push_back(j.design_name);
    m.queue_state.push_back(j.state);
    m.queue_rows_done.push_back(clamp64(j.rows_done));
    m.queue_rows_total.push_back(clamp64(j.rows_total));
  }
  return m;
}

std::vector<loomlcm::carpet_t> to_carpet(const design::Design& d, std::uint32_t job_id,
                                         const std::string& hash, const std::string& loom_id,
                                         std::int64_t utime) {
  if (d.palette().size() > 256) {
    throw std::invalid_argument("design " + d.name() + ": " + std::to_string(d.palette().size()) +
                                " colours; CARPET carries at most 256 (a byte per knot)");
  }
  const int width = std::max(d.width(), 1);
  const int band = std::max<int>(1, static_cast<int>(kCarpetBandKnots / static_cast<std::size_t>(width)));
  std::vector<loomlcm::carpet_t> out;
  for (int first = 0; first < d.height(); first += band) {
    loomlcm::carpet_t m;
    m.utime = utime;
    m.loom_id = loom_id;
    m.job_id = static_cast<std::int32_t>(job_id);
    m.design_hash = hash;
    m.design_name = d.name();
    m.width = d.width();
    m.height = d.height();
    m.n_colours = static_cast<std::int16_t>(d.palette().size());
    for (const design::Colour& c : d.palette()) {
      m.code.push_back(c.code);
      m.rgb.push_back(static_cast<std::int32_t>(c.rgb));
    }
    m.first_row = first;
    m.n_rows = std::min(band, d.height() - first);
    for (int r = first; r < first + m.n_rows; ++r) {
      for (std::uint16_t k : d.row(r)) m.knots.push_back(static_cast<std::uint8_t>(k));
    }
    m.n_knots = static_cast<std::int32_t>(m.knots.size());
    out.push_back(std::move(m));
  }
  return out;
}

JobEvents::JobEvents(const std::string& lcm_url, const std::string& prefix, const std::string& loom_id)
    : loom_id_(loom_id) {
  const ChannelNames ch = channel_names(prefix, loom_id);
  job_channel_ = ch.job;
  carpet_channel_ = ch.carpet;
  lcm_ = lcm_create(lcm_url.empty() ? nullptr : lcm_url.c_str());
  if (lcm_ == nullptr)
    throw std::invalid_argument("telemetry lcm_url '" + lcm_url + "' could not be opened by LCM");
}

JobEvents::~JobEvents() {
  lcm_destroy(lcm_);
}

template <typename Msg>
void JobEvents::send(const std::string& channel, const Msg& m) {
  std::vector<std::uint8_t> buf(static_cast<std::size_t>(m.getEncodedSize()));
  const int n = m.encode(buf.data(), 0, static_cast<int>(buf.size()));
  const bool ok = n >= 0 && lcm_publish(lcm_, channel.c_str(), buf.data(), static_cast<unsigned>(n)) == 0;
  ++(ok ? published_ : failures_);
}

void JobEvents::publish_job(const JobReport& r) noexcept {
  std::lock_guard<std::mutex> lock(mu_);
  try {
    send(job_channel_, to_job(r, loom_id_, wall_utime()));
  } catch (...) {  // an allocation failure loses this message, never the service
    ++failures_;
  }
}

void JobEvents::send_carpet() {
  carpet_sent_ = std::chrono::steady_clock::now();
  if (!design_) return;
  for (const loomlcm::carpet_t& m : to_carpet(*design_, job_id_, hash_, loom_id_, wall_utime())) {
    send(carpet_channel_, m);
  }
}

void JobEvents::set_carpet(std::shared_ptr<const design::Design> d, std::uint32_t job_id,
                           const std::string& hash) noexcept {
  std::lock_guard<std::mutex> lock(mu_);
  design_ = std::move(d);
  job_id_ = job_id;
  hash_ = hash;
  try {
    send_carpet();
  } catch (...) {
    ++failures_;
  }
}

void JobEvents::repeat_carpet() noexcept {
  std::lock_guard<std::mutex> lock(mu_);
  if (!design_ || std::chrono::steady_clock::now() - carpet_sent_ < kCarpetRepeat) return;
  try {
    send_carpet();
  } catch (...) {
    ++failures_;
  }
}

std::uint64_t JobEvents::published() const {
  std::lock_guard<std::mutex> lock(mu_);
  return published_;
}

std::uint64_t JobEvents::failures() const {
  std::lock_guard<std::mutex> lock(mu_);
  return failures_;
}

}  // namespace loom::telemetry
