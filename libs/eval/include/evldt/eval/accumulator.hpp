#pragma once
// Sums of per-step accuracy over a run, and how long predicted segments live.

#include <cstddef>
#include <cstdint>
#include <span>
#include <unordered_map>
#include <vector>

#include "evldt/eval/line_heatmap.hpp"
#include "evldt/events/event.hpp"

namespace evldt {

/// Collects the MatchCounts of each evaluation step at several tolerances. The figure is the Prf of
/// the counts summed over all steps (every pixel weighs the same, as in the benchmarks).
class EvaluationAccumulator {
 public:
  /// Tolerances as fractions of the image diagonal; throws std::invalid_argument if empty.
  explicit EvaluationAccumulator(std::vector<double> tolerance_fractions = {0.01, 0.02});

  /// counts[i] is the step's result at tolerance_fractions()[i]; throws std::invalid_argument if
  /// the sizes differ.
  void add_step(std::span<const MatchCounts> counts, std::size_t predicted_segments, std::size_t ground_truth_segments);

  [[nodiscard]] std::span<const double> tolerance_fractions() const { return tolerance_fractions_; }
  [[nodiscard]] std::uint64_t steps() const { return steps_; }
  /// Counts summed over all steps at tolerance index i.
  [[nodiscard]] const MatchCounts& total(std::size_t i) const { return totals_.at(i); }
  /// Prf of total(i) (undefined parts are NaN: see prf()).
  [[nodiscard]] Prf summed_prf(std::size_t i) const { return prf(totals_.at(i)); }
  /// Mean number of segments per step (0 with no step).
  [[nodiscard]] double mean_predicted_segments() const;
  [[nodiscard]] double mean_ground_truth_segments() const;

 private:
  std::vector<double> tolerance_fractions_;
  std::vector<MatchCounts> totals_;
  std::uint64_t steps_ = 0;
  std::uint64_t predicted_segments_ = 0;
  std::uint64_t ground_truth_segments_ = 0;
};

/// When one id was first and last observed.
struct IdLifetime {
  std::uint64_t id = 0;
  Timestamp first_us = 0;
  Timestamp last_us = 0;

  [[nodiscard]] double lifetime_ms() const { return static_cast<double>(last_us - first_us) / 1000.0; }
};

struct LifetimeSummary {
  std::uint64_t count = 0;
  double mean_ms = 0;
  double std_ms = 0;  ///< population standard deviation (divides by count)
  double max_ms = 0;
};

inline constexpr std::size_t kMaxHistogramBins = 1'000'000;

/// Follows predicted segment ids over the output steps: an id's lifetime is the time from its first
/// to its last observation (0 for an id seen once). Observations may come in any time order.
class LifetimeTracker {
 public:
  void observe(Timestamp t_us, std::uint64_t id);
  void observe_step(Timestamp t_us, std::span<const std::uint64_t> ids);

  [[nodiscard]] std::size_t ids() const { return seen_.size(); }
  /// One entry per id, sorted by id.
  [[nodiscard]] std::vector<IdLifetime> lifetimes() const;
  /// All zero when nothing was observed.
  [[nodiscard]] LifetimeSummary summary() const;
  /// counts[k] = number of ids whose lifetime is in [k * bin_width_ms, (k + 1) * bin_width_ms), up to
  /// the bin of the longest lifetime; empty when nothing was observed. Throws std::invalid_argument
  /// unless bin_width_ms is finite and > 0, and std::length_error above kMaxHistogramBins bins.
  [[nodiscard]] std::vector<std::uint64_t> histogram(double bin_width_ms) const;

 private:
  struct Span {
    Timestamp first_us = 0;
    Timestamp last_us = 0;
  };
  std::unordered_map<std::uint64_t, Span> seen_;
};

}  // namespace evldt
