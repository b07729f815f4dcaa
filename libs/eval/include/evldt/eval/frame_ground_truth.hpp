#pragma once
// Ground truth from intensity frames, as the paper makes it: LSD (OpenCV's
// createLineSegmentDetector, von Gioi et al.) on each frame gives the true lines at the frame's time.
// An imitation of the exact ground truth: LSD finds texture and shading edges too and splits lines
// at weak stretches; its ids are per frame, so identity figures against it mean nothing.

#include <cstdint>
#include <functional>
#include <vector>

#include <opencv2/core.hpp>

#include "evldt/eval/scene_evaluation.hpp"
#include "evldt/frames/frame_reader.hpp"

namespace evldt {

struct LsdParams {
  double min_length_px = 10;  ///< shorter LSD segments are dropped (the paper's frames are 240x180 and 346x260)
  double scale = 0.8;         ///< LSD's own parameters, at OpenCV's defaults
  double sigma_scale = 0.6;
  double quant = 2.0;
  double angle_tolerance_deg = 22.5;
  double log_eps = 0.0;
  double density_threshold = 0.7;
};

/// LSD's segments of an 8-bit grey image that are at least min_length_px long.
std::vector<Segment> lsd_segments(const cv::Mat& grey, const LsdParams& params);

/// Every frame of `frames`, read at once, as a ground-truth step of its LSD segments. Throws
/// FrameError (from the reader) for a frame that cannot be used, and when there is no frame.
GroundTruthSteps frame_ground_truth_steps(FrameReader& frames, const LsdParams& params);

/// What an events-only camera can see of a frame's LSD lines: those along which the recording's
/// events fell around the frame's time. A still camera's static edges, and edges moving along
/// themselves, give no events; LSD draws them all.
struct EventSupportRule {
  Timestamp half_window_us = 10'000;  ///< events within this of the frame's time count
  /// The share of the line's samples (1 px apart, both ends included) with an event in the 3 x 3
  /// pixels around them that makes the line seen.
  float min_share = 0.5f;
};

/// For every step of `truth`, a flag per piece (in segments_at's order): 1 where the events that
/// `read` hands over (batches in time order, as EventSource::read: false at the end) hold `rule`.
/// Reads the events once, keeping the latest time of each pixel.
std::vector<std::vector<std::uint8_t>> event_supported_pieces(const GroundTruthSteps& truth, SensorSize sensor,
                                                              const EventSupportRule& rule,
                                                              const std::function<bool(EventBatch&)>& read);

}  // namespace evldt
