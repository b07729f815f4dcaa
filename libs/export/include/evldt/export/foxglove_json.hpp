#pragma once
// Messages in Foxglove's schemas, JSON encoding (docs.foxglove.dev, "Foxglove schemas"), so that
// Foxglove opens what evldt recorded: pictures as foxglove.CompressedImage, segments and whole lines
// as foxglove.ImageAnnotations (image coordinates: the origin at the top-left pixel's top-left
// corner, as evldt's), and evldt's statistics in a JSON schema of its own (evldt.Stats).

#include <cstdint>
#include <span>
#include <string>

#include "evldt/camera_info_t.hpp"
#include "evldt/lines/line_types.hpp"
#include "evldt/stats_t.hpp"

namespace evldt {

/// The JSON Schemas written into an MCAP file with the messages (schema encoding "jsonschema"),
/// describing the fields evldt writes.
const std::string& compressed_image_schema();    ///< foxglove.CompressedImage
const std::string& image_annotations_schema();   ///< foxglove.ImageAnnotations
const std::string& stats_schema();               ///< evldt.Stats
const std::string& camera_calibration_schema();  ///< foxglove.CameraCalibration

std::string base64(std::span<const std::uint8_t> bytes);

/// A JPEG picture taken at `time_ns` (ns since the epoch).
std::string compressed_image_json(std::uint64_t time_ns, const std::string& frame_id,
                                  std::span<const std::uint8_t> jpeg);

struct AnnotationStyle {
  double thickness = 1;
  bool by_status = true;  ///< segments: colour by status (yellow detected, green good, red bad); else `colour`
  double colour[4] = {0.16, 0.82, 0.90, 1};  ///< r, g, b, a in 0..1 (whole lines: cyan)
  bool ids = false;                          ///< a text with each line's id at its centre
  /// Each line's motion: an arrow (motion_arrow, orange) and, with ids, its normal velocity in the text.
  bool motion = false;
};
/// Lines as line lists (one per colour) and, with style.ids, their ids; coordinates times `scale`.
std::string image_annotations_json(std::uint64_t time_ns, std::span<const TrackedLine> lines,
                                   const AnnotationStyle& style, int scale);

/// The lines service's statistics.
std::string stats_json(std::uint64_t time_ns, const stats_t& stats);
/// A CAMERA_INFO message as foxglove.CameraCalibration: K and D the sensor's, P the rectified image's.
std::string camera_calibration_json(std::uint64_t time_ns, const camera_info_t& info);

}  // namespace evldt
