#pragma once
// Draws what the pipeline sees: the SCARF surface (pixels holding active entries, in grey) and the
// segments coloured by status (detected yellow, good track green, bad track red), and the pixels
// the hot-pixel filter masks.

#include <array>
#include <opencv2/core.hpp>
#include <span>
#include <string>
#include <vector>

#include "evldt/lines/line_types.hpp"

namespace evldt {

/// What is drawn. The viz toggles each layer with a key (kLayers). By default the whole lines, the
/// pipeline's best output, are drawn with their ids over thinner segments without ids.
struct RenderOptions {
  int scale = 1;                    ///< integer zoom of the output image
  bool show_events = true;          ///< the SCARF surface
  bool show_segments = true;        ///< detected and well-tracked segments
  bool show_bad_tracks = true;      ///< segments whose last track scored below the threshold
  bool show_whole_lines = true;     ///< whole lines (draw_whole_lines), over the segments
  bool show_whole_line_ids = true;  ///< each whole line's label beside it
  bool show_motion = true;          ///< each whole line's motion across itself, an arrow (motion_arrow)
  bool show_segment_ids = false;    ///< each segment's label beside it
  bool show_grid = false;           ///< the lattice's block borders
  int grid_block_size = 0;          ///< spacing of the grid (b); 0: no grid
};

/// A layer a key shows or hides.
struct Layer {
  char key;
  const char* name;
  bool RenderOptions::*shown;
};
inline constexpr std::array<Layer, 8> kLayers{{{'e', "events", &RenderOptions::show_events},
                                               {'s', "segments", &RenderOptions::show_segments},
                                               {'b', "bad tracks", &RenderOptions::show_bad_tracks},
                                               {'w', "whole lines", &RenderOptions::show_whole_lines},
                                               {'i', "whole-line ids", &RenderOptions::show_whole_line_ids},
                                               {'m', "motion", &RenderOptions::show_motion},
                                               {'n', "segment ids", &RenderOptions::show_segment_ids},
                                               {'g', "block grid", &RenderOptions::show_grid}}};
/// The layer of a key, or null.
const Layer* find_layer(int key);
/// Flips the layer of a key of kLayers; false for any other key.
bool toggle_layer(RenderOptions& options, int key);
/// The keys as help fields: "keys: e events", "s segments", ..., "q quit".
std::vector<std::string> layer_key_help();

cv::Scalar status_colour(LineStatus status);

/// Fills `canvas` (resized to the sensor size times scale, BGR) with the layers `options` selects.
/// `surface` is the per-pixel active-entry count of a lattice built with keep_surface (may be empty).
/// `labels` are written beside the segments with show_segment_ids (one per line, e.g. from ShortIds; empty: the
/// lines' ids).
void render_scene(SensorSize sensor, std::span<const std::uint16_t> surface, std::span<const TrackedLine> lines,
                  const RenderOptions& options, cv::Mat& canvas, std::span<const std::uint32_t> labels = {});

/// Draws whole lines (cyan, thicker than segments) on a canvas render_scene drew, if
/// options.show_whole_lines; with show_whole_line_ids, `labels` (one per line; empty: the ids) beside
/// them; with show_motion, an orange arrow from each one's middle to where it moves in
/// kMotionArrowSeconds.
void draw_whole_lines(std::span<const TrackedLine> lines, const RenderOptions& options, cv::Mat& canvas,
                      std::span<const std::uint32_t> labels = {});

/// Rings the pixels (y * width + x) the hot-pixel filter masks, in magenta, on a canvas that
/// render_scene drew at `scale`; indices off the sensor are ignored.
void draw_masked_pixels(SensorSize sensor, std::span<const std::int32_t> pixels, int scale, cv::Mat& canvas);

}  // namespace evldt
