#pragma once
// evldt-lines' options and the totals it reports, shared by its parts (lines_ingest.hpp,
// line_publishers.hpp, lines_statistics.hpp) and the node that composes them (lines_node.hpp).

#include <cstdint>
#include <cstdio>
#include <functional>
#include <optional>
#include <string>

#include "evldt/pipeline/pipeline_config.hpp"
#include "evldt/transport/event_batch_receiver.hpp"
#include "evldt/transport/latency_budget.hpp"
#include "evldt/transport/latency_tracker.hpp"

namespace evldt {

/// The default latency budget: well above the queueing of a service that keeps up (a few ms), well
/// below answers too old to steer by (docs/realtime.md).
inline constexpr double kDefaultMaxLatencyMs = 20;

struct LinesNodeOptions {
  std::string camera = "cam0";
  std::optional<SensorSize> sensor;  ///< unset: adopt the first valid batch's (set: the engine is built at start)
  std::function<PipelineConfig(SensorSize)> configure = default_config_for;
  Timestamp time_slack_us = 1000;
  double publish_hz = 100;  ///< at most this many segment lists a second: one after each round, when rounds are faster
  /// Batches that queued longer than this before they could be stored are thinned, past twice it
  /// shed whole (LatencyBudget; 0: never).
  double max_latency_ms = kDefaultMaxLatencyMs;
  OverloadPolicy overload = OverloadPolicy::Thin;
  double stats_hz = 1;
  double log_period_s = 10;  ///< a status line in the log this often (0: never)
  bool whole_lines = true;   ///< also publish whole lines on WHOLE_LINES_<CAMERA>
  /// Whole-line lists per second at most: with a segment list, once 1 / whole_lines_hz has passed since
  /// the last (a whole-line step costs 1.8 ms at HD; lines change little in 1 ms).
  double whole_lines_hz = 100;
  /// While the service sheds (a batch shed within the last second), whole lines go out at most this
  /// often: at HD they took a quarter of a core at 100 Hz, which the tracking rounds need more.
  double whole_lines_loaded_hz = 10;
};

/// Totals since start (what the stats message and the exit summary report).
struct LinesNodeTotals {
  ReceiverCounts receiver;            ///< batches received, lost, invalid and shed
  std::uint64_t events_received = 0;  ///< valid events handed to the engine
  FilterCounts filtered;              ///< what the noise filters dropped of them
  std::uint64_t events_stored = 0;
  std::uint64_t events_off_rectified = 0;  ///< with a calibration: left out, their pixel feeds no rectified pixel
  std::uint64_t detect_rounds = 0;
  std::uint64_t detect_rounds_without_bend_test = 0;  ///< run while shedding
  std::uint64_t track_rounds = 0;
  std::uint64_t lines_created = 0;
  std::uint64_t lists_published = 0;
  std::uint64_t whole_lists_published = 0;
  std::uint64_t whole_lists_while_shedding = 0;  ///< of them, published at whole_lines_loaded_hz
  std::uint64_t engine_restarts = 0;             ///< the camera restarted (new epoch): the lattice began afresh
  LatencySummary latency;          ///< batch publish -> first list including it, since the last camera (re)start
  LatencySummary settled_latency;  ///< the same, of the batches published 1 s or more after the first (LatencyTracker)
  /// Batches whose latency was measured from their receipt: their publish stamps were far from this
  /// host's clock (LatencyTracker::kClocksApartUs), by publish_clock_offset_us.
  std::uint64_t latency_from_receipt = 0;
  std::optional<std::int64_t> publish_clock_offset_us;

  /// The exit summary, with the options it was run with.
  void print(std::FILE* out, const LinesNodeOptions& options) const;
};

}  // namespace evldt
