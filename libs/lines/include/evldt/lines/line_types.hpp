#pragma once
// What evldt gives out, free of the lattice and the parameters: a line segment with its id, score,
// status and times, for a block's segment and a whole line alike. The transport, the renderers, the
// exporters, the evaluation and Python read these; the tracker's own bookkeeping stays in LineMap.

#include <cstdint>
#include <string_view>

#include "evldt/events/event.hpp"
#include "evldt/lines/geometry.hpp"

namespace evldt {

enum class LineStatus : std::uint8_t { Detected, GoodTrack, BadTrack };

/// "detected", "good", "bad": the CSV's and the messages' names.
inline std::string_view status_name(LineStatus status) {
  switch (status) {
    case LineStatus::Detected:
      return "detected";
    case LineStatus::GoodTrack:
      return "good";
    case LineStatus::BadTrack:
      return "bad";
  }
  return "?";
}

/// A segment as tracked and published. For a whole line (WholeLineStage), score is the number of
/// block segments joined, the status good and the admin block -1.
struct TrackedLine {
  std::uint64_t id = 0;
  Segment segment;
  float score = 0;
  LineStatus status = LineStatus::Detected;
  int admin_block = -1;
  Timestamp first_seen_us = 0;
  Timestamp last_good_us = 0;  ///< last time its score was above threshold (detection counts)
  /// How fast it moves across itself, px/s along its normal (-(y1 - y0), x1 - x0) / length, and the
  /// standard deviation of that estimate (normal_motion.hpp).
  float normal_velocity = 0;
  float normal_velocity_std = 0;
};

/// A whole line as the whole-line tracker keeps it.
struct WholeLine {
  std::uint64_t id = 0;
  Segment segment;              ///< the fitted line over the extent of its segments (and remembered ends)
  std::uint32_t segments = 0;   ///< block segments joined into it at this step
  Timestamp first_seen_us = 0;  ///< when its track began
  Timestamp last_seen_us = 0;
  float normal_velocity = 0;  ///< as TrackedLine's, along this segment's normal
  float normal_velocity_std = 0;
};

}  // namespace evldt
