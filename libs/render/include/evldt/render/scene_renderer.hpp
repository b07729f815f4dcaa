#pragma once
// Draws what the pipeline sees: the SCARF surface (pixels holding active entries, in grey) and the
// segments coloured by status (detected yellow, good track green, bad track red), and the pixels
// the hot-pixel filter masks.

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

/// Rings the pixels (y * width + x) the hot-pixel filter masks, in magenta, on a canvas that
/// render_scene drew at `scale`; indices off the sensor are ignored.
void draw_masked_pixels(SensorSize sensor, std::span<const std::int32_t> pixels, int scale, cv::Mat& canvas);

}  // namespace evldt
