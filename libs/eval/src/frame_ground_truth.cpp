#include "evldt/eval/frame_ground_truth.hpp"

#include <memory>

#include <opencv2/imgproc.hpp>

namespace evldt {

std::vector<Segment> lsd_segments(const cv::Mat& grey, const LsdParams& params) {
  const cv::Ptr<cv::LineSegmentDetector> lsd =
      cv::createLineSegmentDetector(cv::LSD_REFINE_STD, params.scale, params.sigma_scale, params.quant, params.angle_tolerance_deg,
                                    params.log_eps, params.density_threshold);
  std::vector<cv::Vec4f> found;
  lsd->detect(grey, found);
  std::vector<Segment> segments;
  for (const cv::Vec4f& line : found) {
    const Segment segment{{line[0], line[1]}, {line[2], line[3]}};
    if (segment.length() >= params.min_length_px) segments.push_back(segment);
  }
  return segments;
}

GroundTruthSteps frame_ground_truth_steps(FrameReader& frames, const LsdParams& params) {
  struct Step {
    std::vector<Segment> segments;
    std::vector<std::uint64_t> ids;
  };
  auto steps = std::make_shared<std::vector<Step>>();
  GroundTruthSteps truth;
  std::uint64_t next_id = 0;
  while (auto frame = frames.next()) {
    // Frames at one time (a duplicate stamp) are one step: the later frame replaces the earlier.
    if (!truth.times.empty() && truth.times.back() == frame->t_us) {
      truth.times.pop_back();
      steps->pop_back();
    }
    Step step;
    step.segments = lsd_segments(frame->image, params);
    for (std::size_t k = 0; k < step.segments.size(); ++k) step.ids.push_back(next_id++);
    truth.times.push_back(frame->t_us);
    steps->push_back(std::move(step));
  }
  if (truth.times.empty()) throw FrameError("no frame to take ground truth from");
  truth.segments_at = [steps](std::size_t index, std::vector<Segment>& segments, std::vector<std::uint64_t>& ids) {
    segments = (*steps)[index].segments;
    ids = (*steps)[index].ids;
  };
  return truth;
}

}  // namespace evldt
