#pragma once
// evldt-lines' statistics: a stats_t on EVLDT_STATS every period (rates from the change of the
// totals since the last), and a status line in the log.

#include <cstddef>
#include <cstdint>
#include <lcm/lcm-cpp.hpp>

#include "evldt/nodes/lines_options.hpp"
#include "evldt/pipeline/realtime_engine.hpp"

namespace evldt {

class LinesStatistics {
 public:
  LinesStatistics(lcm::LCM& lcm, const LinesNodeOptions& options, std::int64_t epoch_us);

  /// Publishes the figures of the last period_s: `now` the totals, `latency` that of the lists of
  /// the period, `live_lines` in the last list, `engine` (nullptr before the first batch) for the
  /// filters and the masked pixels.
  void publish(const LinesNodeTotals& now, const LatencySummary& latency, std::size_t live_lines,
               const RealtimeEngine* engine, double period_s);
  /// The log's status line of `now`, with the latency of the last statistics period.
  void log(const LinesNodeTotals& now) const;

 private:
  lcm::LCM& lcm_;
  const LinesNodeOptions& options_;
  std::int64_t epoch_us_;
  LinesNodeTotals last_;
  LatencySummary last_latency_;
};

}  // namespace evldt
