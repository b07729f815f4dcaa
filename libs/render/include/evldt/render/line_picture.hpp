#pragma once
// One picture of the pipeline's output, as every view draws it (evldt-viz, evldt-offline's frames):
// the scene with its segments (render_scene), the whole lines over them, each kind labelled with
// short ids that stay the same from picture to picture.

#include <span>
#include <vector>

#include "evldt/render/scene_renderer.hpp"
#include "evldt/render/short_ids.hpp"

namespace evldt {

class LinePicture {
 public:
  /// Fills `canvas` with the layers `options` selects. Lines are labelled whether or not their
  /// labels are shown, so a line keeps its label when they are shown again.
  void draw(SensorSize sensor, std::span<const std::uint16_t> surface, std::span<const TrackedLine> segments,
            std::span<const TrackedLine> whole_lines, const RenderOptions& options, cv::Mat& canvas);

 private:
  ShortIds segment_ids_, whole_line_ids_;
  std::vector<std::uint64_t> ids_;
  std::vector<std::uint32_t> labels_;
};

}  // namespace evldt
