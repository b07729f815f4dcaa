#include "evldt/nodes/lines_statistics.hpp"

#include <spdlog/spdlog.h>
#include <algorithm>
#include <string>
#include <vector>

#include "evldt/stats_t.hpp"
#include "evldt/transport/channels.hpp"

namespace evldt {

namespace {
// A statistics message lists at most this many masked pixels (16 KiB), whatever a broken sensor does.
constexpr std::size_t kMaxListedMaskedPixels = 4096;
}  // namespace

LinesStatistics::LinesStatistics(lcm::LCM& lcm, const LinesNodeOptions& options, std::int64_t epoch_us)
    : lcm_(lcm), options_(options), epoch_us_(epoch_us) {}

void LinesStatistics::publish(const LinesNodeTotals& now, const LatencySummary& latency, std::size_t live_lines,
                              const RealtimeEngine* engine, double period_s) {
  const auto rate = [&](std::uint64_t current, std::uint64_t before) {
    return static_cast<double>(current - before) / period_s;
  };
  stats_t msg{};
  msg.utime = wall_clock_us();
  msg.epoch = epoch_us_;
  msg.service = "evldt-lines";
  msg.source = options_.camera;
  msg.period_s = period_s;
  msg.events_in = static_cast<std::int64_t>(now.events_stored);
  msg.event_rate = rate(now.events_stored, last_.events_stored);
  msg.events_dropped = static_cast<std::int64_t>(now.receiver.drops.total());
  msg.batches_received = static_cast<std::int64_t>(now.receiver.sequence.received);
  msg.batches_lost = static_cast<std::int64_t>(now.receiver.sequence.lost);
  msg.invalid_messages = static_cast<std::int64_t>(now.receiver.invalid_messages);
  msg.detect_hz = rate(now.detect_rounds, last_.detect_rounds);
  msg.track_hz = rate(now.track_rounds, last_.track_rounds);
  msg.live_lines = static_cast<std::int32_t>(live_lines);
  msg.lists_published = static_cast<std::int64_t>(now.lists_published);
  msg.latency_samples = static_cast<std::int32_t>(latency.samples);
  msg.latency_median_ms = static_cast<float>(latency.median_ms);
  msg.latency_p99_ms = static_cast<float>(latency.p99_ms);
  msg.latency_from_receipt = now.latency_from_receipt > last_.latency_from_receipt;
  msg.publish_clock_offset_ms = static_cast<double>(now.publish_clock_offset_us.value_or(0)) * 1e-3;
  msg.latency_budget_ms = static_cast<float>(options_.max_latency_ms);
  msg.batches_shed = static_cast<std::int64_t>(now.receiver.batches_shed);
  msg.events_shed = static_cast<std::int64_t>(now.receiver.events_shed);
  msg.filtered_hot_pixel = static_cast<std::int64_t>(now.filtered.hot_pixel);
  msg.filtered_background_activity = static_cast<std::int64_t>(now.filtered.background_activity);
  msg.filtered_refractory = static_cast<std::int64_t>(now.filtered.refractory);
  msg.filtered_anti_flicker = static_cast<std::int64_t>(now.filtered.anti_flicker);
  msg.filters = "none";
  if (engine != nullptr) {
    msg.filters = format_filter_chain(engine->config().filters.chain);
    std::vector<std::uint32_t> masked = engine->masked_pixels();
    masked.resize(std::min<std::size_t>(masked.size(), kMaxListedMaskedPixels));
    msg.masked_pixels.assign(masked.begin(), masked.end());
  }
  msg.num_masked_pixels = static_cast<std::int32_t>(msg.masked_pixels.size());
  lcm_.publish(std::string(kStatsChannel), &msg);
  last_ = now;
  last_latency_ = latency;
}

void LinesStatistics::log(const LinesNodeTotals& now) const {
  spdlog::info(
      "{} events stored, {} batches ({} lost, {} shed over the latency budget, {} invalid messages), "
      "{} lines created, {} lists published, latency {:.1f} / {:.1f} ms (median / p99 of the last "
      "statistics period)",
      now.events_stored, now.receiver.sequence.received, now.receiver.sequence.lost, now.receiver.batches_shed,
      now.receiver.invalid_messages, now.lines_created, now.lists_published, last_latency_.median_ms,
      last_latency_.p99_ms);
}

}  // namespace evldt
