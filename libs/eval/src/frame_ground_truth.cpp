#include "evldt/eval/frame_ground_truth.hpp"

#include <cmath>
#include <limits>
#include <memory>

#include <opencv2/imgproc.hpp>

namespace evldt {

std::vector<Segment> lsd_segments(const cv::Mat& grey, const LsdParams& params) {
  const cv::Ptr<cv::LineSegmentDetector> lsd =
      cv::createLineSegmentDetector(cv::LSD_REFINE_STD, params.scale, params.sigma_scale, params.quant,
                                    params.angle_tolerance_deg, params.log_eps, params.density_threshold);
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

std::vector<std::vector<std::uint8_t>> event_supported_pieces(const GroundTruthSteps& truth, SensorSize sensor,
                                                              const EventSupportRule& rule,
                                                              const std::function<bool(EventBatch&)>& read) {
  const auto width = static_cast<std::size_t>(sensor.width), height = static_cast<std::size_t>(sensor.height);
  // Each pixel's latest event among those read: all events up to a step's time + half window are
  // read before it is judged, so a latest time at or after its time - half window is an event in the window.
  std::vector<Timestamp> latest(width * height, std::numeric_limits<Timestamp>::min());
  EventBatch batch;
  std::size_t next = 0;
  bool more = true;
  const auto read_until = [&](Timestamp until) {
    while (more) {
      if (next == batch.size()) {
        more = read(batch);
        next = 0;
        continue;
      }
      if (batch.t[next] > until) return;
      if (batch.x[next] < width && batch.y[next] < height)
        latest[batch.y[next] * width + batch.x[next]] = batch.t[next];
      ++next;
    }
  };
  std::vector<std::vector<std::uint8_t>> supported(truth.times.size());
  std::vector<Segment> segments;
  std::vector<std::uint64_t> ids;
  for (std::size_t step = 0; step < truth.times.size(); ++step) {
    const Timestamp t = truth.times[step];
    read_until(t + rule.half_window_us);
    const Timestamp since = t - rule.half_window_us;
    const auto event_near = [&](Point2 p) {
      const auto x = static_cast<long>(std::floor(p.x())), y = static_cast<long>(std::floor(p.y()));
      for (long ny = std::max(0L, y - 1); ny <= std::min(static_cast<long>(height) - 1, y + 1); ++ny) {
        for (long nx = std::max(0L, x - 1); nx <= std::min(static_cast<long>(width) - 1, x + 1); ++nx) {
          if (latest[static_cast<std::size_t>(ny) * width + static_cast<std::size_t>(nx)] >= since) return true;
        }
      }
      return false;
    };
    truth.segments_at(step, segments, ids);
    for (const Segment& piece : segments) {
      const int samples = 1 + static_cast<int>(std::ceil(piece.length()));
      int held = 0;
      for (int k = 0; k < samples; ++k) {
        const float along = samples > 1 ? static_cast<float>(k) / static_cast<float>(samples - 1) : 0.0f;
        held += event_near(piece.q0 + along * (piece.q1 - piece.q0)) ? 1 : 0;
      }
      supported[step].push_back(static_cast<float>(held) >= rule.min_share * static_cast<float>(samples) ? 1 : 0);
    }
  }
  return supported;
}

}  // namespace evldt
