#include "evldt/eval/accumulator.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

namespace evldt {

EvaluationAccumulator::EvaluationAccumulator(std::vector<double> tolerance_fractions)
    : tolerance_fractions_(std::move(tolerance_fractions)), totals_(tolerance_fractions_.size()) {
  if (tolerance_fractions_.empty()) throw std::invalid_argument("an evaluation needs at least one tolerance");
}

void EvaluationAccumulator::add_step(std::span<const MatchCounts> counts, std::size_t predicted_segments,
                                     std::size_t ground_truth_segments) {
  if (counts.size() != tolerance_fractions_.size()) {
    throw std::invalid_argument("step has counts for " + std::to_string(counts.size()) + " tolerances, expected " +
                                std::to_string(tolerance_fractions_.size()));
  }
  for (std::size_t i = 0; i < counts.size(); ++i) totals_[i] += counts[i];
  ++steps_;
  predicted_segments_ += predicted_segments;
  ground_truth_segments_ += ground_truth_segments;
}

double EvaluationAccumulator::mean_predicted_segments() const {
  return steps_ == 0 ? 0.0 : static_cast<double>(predicted_segments_) / static_cast<double>(steps_);
}

double EvaluationAccumulator::mean_ground_truth_segments() const {
  return steps_ == 0 ? 0.0 : static_cast<double>(ground_truth_segments_) / static_cast<double>(steps_);
}

void LifetimeTracker::observe(Timestamp t_us, std::uint64_t id) {
  const auto [it, inserted] = seen_.try_emplace(id, Span{t_us, t_us});
  if (inserted) return;
  it->second.first_us = std::min(it->second.first_us, t_us);
  it->second.last_us = std::max(it->second.last_us, t_us);
}

void LifetimeTracker::observe_step(Timestamp t_us, std::span<const std::uint64_t> ids) {
  for (const std::uint64_t id : ids) observe(t_us, id);
}

std::vector<IdLifetime> LifetimeTracker::lifetimes() const {
  std::vector<IdLifetime> result;
  result.reserve(seen_.size());
  for (const auto& [id, span] : seen_) result.push_back({id, span.first_us, span.last_us});
  std::sort(result.begin(), result.end(), [](const IdLifetime& a, const IdLifetime& b) { return a.id < b.id; });
  return result;
}

LifetimeSummary LifetimeTracker::summary() const {
  LifetimeSummary summary;
  if (seen_.empty()) return summary;
  // Sorted by id, so the floating-point sums do not depend on the hash map's order.
  const std::vector<IdLifetime> all = lifetimes();
  double sum = 0;
  for (const IdLifetime& l : all) {
    sum += l.lifetime_ms();
    summary.max_ms = std::max(summary.max_ms, l.lifetime_ms());
  }
  summary.count = all.size();
  summary.mean_ms = sum / static_cast<double>(all.size());
  double squares = 0;
  for (const IdLifetime& l : all) squares += (l.lifetime_ms() - summary.mean_ms) * (l.lifetime_ms() - summary.mean_ms);
  summary.std_ms = std::sqrt(squares / static_cast<double>(all.size()));
  return summary;
}

std::vector<std::uint64_t> LifetimeTracker::histogram(double bin_width_ms) const {
  if (!std::isfinite(bin_width_ms) || bin_width_ms <= 0) {
    throw std::invalid_argument("histogram bin width must be finite and > 0, got " + std::to_string(bin_width_ms));
  }
  std::vector<std::uint64_t> counts;
  if (seen_.empty()) return counts;
  const auto bin_of = [bin_width_ms](const Span& span) {
    return std::floor(static_cast<double>(span.last_us - span.first_us) / 1000.0 / bin_width_ms);
  };
  double last_bin = 0;
  for (const auto& entry : seen_) last_bin = std::max(last_bin, bin_of(entry.second));
  if (last_bin >= static_cast<double>(kMaxHistogramBins)) {
    throw std::length_error("lifetime histogram would need more than " + std::to_string(kMaxHistogramBins) + " bins");
  }
  counts.assign(static_cast<std::size_t>(last_bin) + 1, 0);
  for (const auto& entry : seen_) ++counts[static_cast<std::size_t>(bin_of(entry.second))];
  return counts;
}

}  // namespace evldt
