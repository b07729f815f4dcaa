#include "evldt/eval/overlay.hpp"

#include <algorithm>
#include <cstdio>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

#include "evldt/media/media.hpp"

namespace evldt {

namespace {

const cv::Scalar kTruthColour(80, 220, 80), kSegmentColour(60, 60, 235), kWholeLineColour(235, 150, 40);  // BGR
const cv::Scalar kUnseenTruthColour(200, 80, 220);  // LSD's lines without events along them (--visible-only)

/// The rows of the step held at `t`: the latest step at or before it, if within `hold_us`.
std::span<const SegmentRow> held_at(std::span<const SegmentRow> sorted, Timestamp t, Timestamp hold_us) {
  const auto after =
      std::upper_bound(sorted.begin(), sorted.end(), t, [](Timestamp v, const SegmentRow& r) { return v < r.t_us; });
  if (after == sorted.begin()) return {};
  const Timestamp step = std::prev(after)->t_us;
  if (t - step > hold_us) return {};
  const auto first =
      std::lower_bound(sorted.begin(), after, step, [](const SegmentRow& r, Timestamp v) { return r.t_us < v; });
  return {first, after};
}

std::vector<SegmentRow> by_time(std::span<const SegmentRow> rows) {
  std::vector<SegmentRow> sorted(rows.begin(), rows.end());
  std::stable_sort(sorted.begin(), sorted.end(),
                   [](const SegmentRow& a, const SegmentRow& b) { return a.t_us < b.t_us; });
  return sorted;
}

void draw(cv::Mat& canvas, const Segment& s, int scale, const cv::Scalar& colour, int thickness) {
  // Sub-pixel ends (4 fractional bits); OpenCV puts a canvas pixel's centre at its integer coordinate.
  const auto at = [k = static_cast<float>(scale)](const Point2& p) {
    return cv::Point(cvRound((p.x() * k - 0.5f) * 16), cvRound((p.y() * k - 0.5f) * 16));
  };
  cv::line(canvas, at(s.q0), at(s.q1), colour, thickness, cv::LINE_AA, 4);
}

}  // namespace

std::size_t write_overlays(const std::filesystem::path& dir, FrameReader& frames, const GroundTruthSteps& truth,
                           const OverlayStream& segments, const OverlayStream& whole_lines,
                           const VisibilitySplit* visibility, int scale) {
  std::filesystem::create_directories(dir);
  const std::vector<SegmentRow> segment_rows = by_time(segments.rows), whole_rows = by_time(whole_lines.rows);
  std::vector<Segment> truth_segments, seen, unseen;
  std::vector<std::uint64_t> truth_ids;
  std::size_t written = 0, step = 0;
  cv::Mat grey, canvas;
  while (auto frame = frames.next()) {
    // A duplicate stamp is one step (frame_ground_truth_steps): the later frame's.
    while (step < truth.times.size() && truth.times[step] < frame->t_us) ++step;
    if (step == truth.times.size()) break;
    if (truth.times[step] != frame->t_us) continue;
    cv::resize(frame->image, grey, {}, scale, scale, cv::INTER_NEAREST);
    cv::cvtColor(grey, canvas, cv::COLOR_GRAY2BGR);
    truth.segments_at(step, truth_segments, truth_ids);
    if (visibility) {
      (*visibility)(step, truth_segments, seen, unseen);
      for (const Segment& s : unseen) draw(canvas, s, scale, kUnseenTruthColour, 2);
      truth_segments = seen;
    }
    for (const Segment& s : truth_segments) draw(canvas, s, scale, kTruthColour, 2);
    for (const SegmentRow& row : held_at(whole_rows, frame->t_us, whole_lines.hold_us))
      draw(canvas, row.segment, scale, kWholeLineColour, 3);
    for (const SegmentRow& row : held_at(segment_rows, frame->t_us, segments.hold_us))
      draw(canvas, row.segment, scale, kSegmentColour, 1);
    const std::string caption = "t " + std::to_string(frame->t_us) + " us   LSD green" +
                                (visibility ? " (no events: purple)" : "") + ", segments red, whole lines blue";
    cv::putText(canvas, caption, {6, 16}, cv::FONT_HERSHEY_SIMPLEX, 0.45, cv::Scalar(0, 0, 0), 3, cv::LINE_AA);
    cv::putText(canvas, caption, {6, 16}, cv::FONT_HERSHEY_SIMPLEX, 0.45, cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
    char name[32];
    std::snprintf(name, sizeof name, "step_%05zu.png", step);
    const auto path = dir / name;
    if (!media::write_image(path.string(), canvas)) throw std::runtime_error("cannot write " + path.string());
    ++written;
    ++step;
  }
  return written;
}

}  // namespace evldt
