#pragma once
// Draws what the pipeline sees: the SCARF surface (pixels holding active entries, in grey) and the
// segments coloured by status (detected yellow, good track green, bad track red), and the pixels
// the hot-pixel filter masks.

#include <opencv2/core.hpp>
#include <span>

#include "evldt/lines/line_map.hpp"

namespace evldt {

/// What is drawn. The viz window toggles each layer with a key (toggle_layer).
struct RenderOptions {
  int scale = 1;                ///< integer zoom of the output image
  bool show_ids = false;        ///< write each line's label beside it
  bool show_events = true;      ///< the SCARF surface
  bool show_segments = true;    ///< detected and well-tracked segments
  bool show_bad_tracks = true;  ///< segments whose last track scored below the threshold
  bool show_grid = false;       ///< the lattice's block borders
  bool show_whole_lines = false;  ///< whole lines (draw_whole_lines), over the segments
  int grid_block_size = 0;      ///< spacing of the grid (b); 0: no grid
};

/// The keys toggle_layer knows, for a help line.
inline constexpr const char* kLayerKeys =
    "keys: e events, s segments, b bad tracks, w whole lines, g block grid, i ids, q quit";
/// Flips the layer of a key of kLayerKeys; false for any other key.
bool toggle_layer(RenderOptions& options, int key);

cv::Scalar status_colour(LineStatus status);

/// Fills `canvas` (resized to the sensor size times scale, BGR) with the layers `options` selects.
/// `surface` is the per-pixel active-entry count of a lattice built with keep_surface (may be empty).
/// `labels` are written beside the lines with show_ids (one per line, e.g. from ShortIds; empty: the
/// lines' ids).
void render_scene(SensorSize sensor, std::span<const std::uint16_t> surface, std::span<const TrackedLine> lines,
                  const RenderOptions& options, cv::Mat& canvas, std::span<const std::uint32_t> labels = {});

/// Draws whole lines (cyan, thicker than segments) on a canvas render_scene drew, if
/// options.show_whole_lines; with show_ids, `labels` (one per line; empty: the ids) beside them.
void draw_whole_lines(std::span<const TrackedLine> lines, const RenderOptions& options, cv::Mat& canvas,
                      std::span<const std::uint32_t> labels = {});

/// Rings the pixels (y * width + x) the hot-pixel filter masks, in magenta, on a canvas that
/// render_scene drew at `scale`; indices off the sensor are ignored.
void draw_masked_pixels(SensorSize sensor, std::span<const std::int32_t> pixels, int scale, cv::Mat& canvas);

}  // namespace evldt
