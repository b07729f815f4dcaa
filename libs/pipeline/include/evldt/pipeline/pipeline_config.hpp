#pragma once
// The parameters of a run: the method's (evldt/lines/params.hpp), the round schedule, the noise
// filters and the calibration, with defaults per sensor resolution (docs/configuration.md).

#include <memory>
#include <string>

#include "evldt/calibration/rectifier.hpp"
#include "evldt/events/event.hpp"
#include "evldt/filters/filter_chain.hpp"
#include "evldt/lines/params.hpp"

namespace evldt {

struct ScheduleParams {
  Timestamp track_period_us = 2000;
  Timestamp detect_period_us = 4000;
  /// Event-time gaps longer than this many tracking periods are skipped rather than replayed round by round.
  int max_catch_up_rounds = 8;
  /// The real-time engine, while it sheds batches over its latency budget: rounds this many periods
  /// apart. Chosen at x1 on monitor-hd (docs/realtime.md): 2 sheds a third as many batches as 1,
  /// 3 no fewer than 2 at a lower F@1%.
  int shedding_period_factor = 2;
  /// The real-time engine: input that stops for this long (wall time) is a pause, after which the
  /// rounds run on what is new without waiting for a period of event time. Longer than a live
  /// camera's or a slow replay's gap between batches, short enough that a stream's last events are
  /// answered promptly.
  int input_pause_ms = 10;
};

struct PipelineConfig {
  FilterConfig filters;  ///< noise filters run before storage
  LatticeParams lattice;
  ScoreParams score;
  TrackParams track;
  ScheduleParams schedule;
  WholeLineParams whole_lines;
  /// A camera calibration file ("none": the sensor's pixels are taken as they are) and the table made
  /// of it for the sensor (PipelineOptions::resolve): events move into the rectified image after the
  /// noise filters, and the lattice and the lines live there.
  std::string calibration = "none";
  std::shared_ptr<const RectificationTable> rectification;
  /// Threads a tracking or detection round is split over (a worker pool): the output is the same
  /// for any count.
  int threads = 1;
};

/// The defaults for a sensor (docs/configuration.md): b and dq from the nearest listed resolution, dq scaled by width.
PipelineConfig default_config_for(SensorSize sensor);

}  // namespace evldt
