#pragma once
// Draws what the pipeline sees: the SCARF surface (pixels holding active entries, in grey) and the
// segments coloured by status (detected yellow, good track green, bad track red).

#include <opencv2/core.hpp>
#include <span>

#include "evldt/lines/line_map.hpp"

namespace evldt {

struct RenderOptions {
  int scale = 1;          ///< integer zoom of the output image
  bool show_ids = false;  ///< write each line's id beside it
};

cv::Scalar status_colour(LineStatus status);

/// Fills `canvas` (resized to the sensor size times scale, BGR) with the surface and the segments.
/// `surface` is the per-pixel active-entry count of a lattice built with keep_surface (may be empty).
void render_scene(SensorSize sensor, std::span<const std::uint16_t> surface, std::span<const TrackedLine> lines,
                  const RenderOptions& options, cv::Mat& canvas);

}  // namespace evldt
