#include "evldt/transport/latency_tracker.hpp"

#include <algorithm>
#include <cmath>

namespace evldt {

LatencyStatistics::LatencyStatistics(std::size_t sample_capacity)
    : sample_capacity_(sample_capacity), run_histogram_(static_cast<std::size_t>(1000.0 / kBinMs) + 1) {
  samples_ms_.reserve(sample_capacity);
}

void LatencyStatistics::add(double latency_ms) {
  if (samples_ms_.size() < sample_capacity_) samples_ms_.push_back(latency_ms);
  const double bin = std::clamp(latency_ms / kBinMs, 0.0, static_cast<double>(run_histogram_.size() - 1));
  ++run_histogram_[static_cast<std::size_t>(bin)];
  ++run_samples_;
}

LatencyTracker::LatencyTracker(std::size_t pending_capacity, std::size_t sample_capacity)
    : ring_(std::max<std::size_t>(pending_capacity, 1)), statistics_(sample_capacity) {}

void LatencyTracker::batch_stored(std::int64_t seq, std::int64_t publish_utime, std::int64_t received_utime,
                                  Timestamp newest_event_us) {
  if (!first_utime_) {
    first_utime_ = publish_utime;
    window_start_ = received_utime;
  }
  if (received_utime - window_start_ >= kOffsetWindowUs) {
    previous_least_ = current_least_;
    current_least_.reset();
    window_start_ = received_utime;
  }
  const std::int64_t delay = received_utime - publish_utime;
  current_least_ = current_least_ ? std::min(*current_least_, delay) : delay;
  const std::int64_t offset = *publish_clock_offset_us();
  const bool from_receipt = offset > kClocksApartUs || offset < -kClocksApartUs;
  if (count_ == ring_.size()) {  // forget the oldest
    head_ = (head_ + 1) % ring_.size();
    --count_;
  }
  ring_[(head_ + count_) % ring_.size()] = {seq, publish_utime, received_utime, from_receipt, newest_event_us};
  ++count_;
}

std::optional<std::int64_t> LatencyTracker::publish_clock_offset_us() const {
  if (!current_least_) return previous_least_;
  return previous_least_ ? std::min(*current_least_, *previous_least_) : current_least_;
}

LatencyTracker::Included LatencyTracker::list_published(Timestamp lattice_us, std::int64_t now_utime) {
  // Batches arrive in event-time order, so the included ones are a prefix of the ring.
  while (count_ > 0 && ring_[head_].newest_event_us <= lattice_us) {
    const Pending& batch = ring_[head_];
    const double latency_ms =
        static_cast<double>(now_utime - (batch.from_receipt ? batch.received_utime : batch.utime)) * 1e-3;
    from_receipt_ += batch.from_receipt ? 1 : 0;
    statistics_.add(latency_ms);
    if (batch.utime - *first_utime_ >= kSettleUs) settled_.add(latency_ms);
    newest_ = {batch.seq, batch.utime};
    head_ = (head_ + 1) % ring_.size();
    --count_;
  }
  return newest_;
}

LatencySummary LatencyStatistics::take_summary() {
  LatencySummary summary;
  summary.samples = static_cast<std::uint32_t>(samples_ms_.size());
  if (!samples_ms_.empty()) {
    const auto quantile = [&](double q) {
      const auto k = static_cast<std::size_t>(std::ceil(q * static_cast<double>(samples_ms_.size()))) - 1;
      std::nth_element(samples_ms_.begin(), samples_ms_.begin() + static_cast<std::ptrdiff_t>(k), samples_ms_.end());
      return samples_ms_[k];
    };
    summary.median_ms = quantile(0.5);
    summary.p99_ms = quantile(0.99);
  }
  samples_ms_.clear();
  return summary;
}

LatencySummary LatencyStatistics::run_summary() const {
  LatencySummary summary;
  summary.samples = static_cast<std::uint32_t>(std::min<std::uint64_t>(run_samples_, UINT32_MAX));
  if (run_samples_ == 0) return summary;
  // The upper edge of the bin holding the q-quantile sample.
  const auto quantile = [&](double q) {
    const auto rank = static_cast<std::uint64_t>(std::ceil(q * static_cast<double>(run_samples_)));
    std::uint64_t seen = 0;
    for (std::size_t bin = 0; bin < run_histogram_.size(); ++bin) {
      seen += run_histogram_[bin];
      if (seen >= rank) return static_cast<double>(bin + 1) * kBinMs;
    }
    return static_cast<double>(run_histogram_.size()) * kBinMs;
  };
  summary.median_ms = quantile(0.5);
  summary.p99_ms = quantile(0.99);
  return summary;
}

}  // namespace evldt
