#pragma once
// Pictures of a run scored against frames: for each ground-truth step, its frame with
// LSD's lines (the ground truth) and the lines evldt held at that time, segments and whole lines in
// colours of their own, so a person can see where they agree.

#include <filesystem>
#include <span>
#include <vector>

#include "evldt/eval/scene_evaluation.hpp"
#include "evldt/frames/frame_reader.hpp"
#include "evldt/pipeline/segment_csv.hpp"

namespace evldt {

/// A prediction stream drawn over the frames, and how long a step of it holds (as scored).
struct OverlayStream {
  std::span<const SegmentRow> rows;  ///< any order
  Timestamp hold_us = 0;
};

/// Writes `dir`/step_NNNNN.png for every ground-truth step of `truth` (frame_ground_truth_steps of
/// the same frames): the frame in grey, LSD's lines in green (with `visibility`, those it hides in
/// purple), `segments` in red and `whole_lines` in blue, each the step held at the frame's time
/// (none past its hold), drawn `scale` times the sensor's size. Returns the number of pictures;
/// throws std::runtime_error when one cannot be written, FrameError as the frames do.
std::size_t write_overlays(const std::filesystem::path& dir, FrameReader& frames, const GroundTruthSteps& truth,
                           const OverlayStream& segments, const OverlayStream& whole_lines,
                           const VisibilitySplit* visibility = nullptr, int scale = 3);

}  // namespace evldt
