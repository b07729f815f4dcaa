#pragma once
// Ground truth from intensity frames, as the paper makes it (issue 28): LSD (OpenCV's
// createLineSegmentDetector, von Gioi et al.) on each frame gives the true lines at the frame's time.
// An imitation of the exact ground truth: LSD finds texture and shading edges too and splits lines
// at weak stretches; its ids are per frame, so identity figures against it mean nothing.

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

}  // namespace evldt
