#include "evldt/export/foxglove_json.hpp"

#include <fmt/format.h>

#include <array>

#include "evldt/json/json_writer.hpp"
#include "evldt/lines/normal_motion.hpp"

namespace evldt {
namespace {

std::string time_json(std::uint64_t time_ns) {
  return fmt::format(R"({{"sec": {}, "nsec": {}}})", time_ns / 1'000'000'000u, time_ns % 1'000'000'000u);
}

std::string colour_json(const double (&rgba)[4]) {
  return fmt::format(R"({{"r": {:.3f}, "g": {:.3f}, "b": {:.3f}, "a": {:.3f}}})", rgba[0], rgba[1], rgba[2], rgba[3]);
}

// The viz's colours (scene_renderer.cpp), as r, g, b in 0..1.
constexpr double kDetected[4] = {1.0, 0.86, 0.0, 1}, kGood[4] = {0.24, 0.86, 0.31, 1}, kBad[4] = {0.9, 0.16, 0.16, 1};
constexpr double kTransparent[4] = {0, 0, 0, 0};
constexpr double kTextBackground[4] = {0, 0, 0, 0.5};
constexpr double kMotion[4] = {1.0, 0.55, 0.0, 1};  // orange, as evldt-viz draws it

// Shared by the schemas below.
constexpr const char* kTimeSchema =
    R"({"type": "object", "properties": {"sec": {"type": "integer", "minimum": 0}, "nsec": {"type": "integer", "minimum": 0, "maximum": 999999999}}, "required": ["sec", "nsec"]})";
constexpr const char* kColourSchema =
    R"({"type": "object", "properties": {"r": {"type": "number"}, "g": {"type": "number"}, "b": {"type": "number"}, "a": {"type": "number"}}, "required": ["r", "g", "b", "a"]})";
constexpr const char* kPointSchema =
    R"({"type": "object", "properties": {"x": {"type": "number"}, "y": {"type": "number"}}, "required": ["x", "y"]})";

std::string make_annotations_schema() {
  return fmt::format(
      R"({{"title": "foxglove.ImageAnnotations", "type": "object", "properties": {{)"
      R"("circles": {{"type": "array", "maxItems": 0}}, )"
      R"("points": {{"type": "array", "items": {{"type": "object", "properties": {{"timestamp": {0}, "type": {{"type": "integer", "minimum": 0, "maximum": 4}}, )"
      R"("points": {{"type": "array", "items": {2}}}, "outline_color": {1}, "outline_colors": {{"type": "array", "items": {1}}}, "fill_color": {1}, )"
      R"("thickness": {{"type": "number"}}}}, "required": ["timestamp", "type", "points", "outline_color", "outline_colors", "fill_color", "thickness"]}}}}, )"
      R"("texts": {{"type": "array", "items": {{"type": "object", "properties": {{"timestamp": {0}, "position": {2}, "text": {{"type": "string"}}, )"
      R"("font_size": {{"type": "number"}}, "text_color": {1}, "background_color": {1}}}, )"
      R"("required": ["timestamp", "position", "text", "font_size", "text_color", "background_color"]}}}}}}, "required": ["circles", "points", "texts"]}})",
      kTimeSchema, kColourSchema, kPointSchema);
}

std::string make_image_schema() {
  return fmt::format(
      R"({{"title": "foxglove.CompressedImage", "type": "object", "properties": {{"timestamp": {}, "frame_id": {{"type": "string"}}, )"
      R"("data": {{"type": "string", "contentEncoding": "base64"}}, "format": {{"type": "string"}}}}, "required": ["timestamp", "frame_id", "data", "format"]}})",
      kTimeSchema);
}

}  // namespace

const std::string& image_annotations_schema() {
  static const std::string schema = make_annotations_schema();
  return schema;
}

const std::string& compressed_image_schema() {
  static const std::string schema = make_image_schema();
  return schema;
}

const std::string& stats_schema() {
  static const std::string schema =
      R"({"title": "evldt.Stats", "description": "evldt-lines' statistics, as in lcmtypes/stats_t.lcm", "type": "object", "properties": {)"
      R"("timestamp": {"type": "object", "properties": {"sec": {"type": "integer", "minimum": 0}, "nsec": {"type": "integer", "minimum": 0, "maximum": 999999999}}, "required": ["sec", "nsec"]}, )"
      R"("service": {"type": "string"}, "source": {"type": "string"}, "events_in": {"type": "integer"}, "event_rate": {"type": "number"}, )"
      R"("batches_received": {"type": "integer"}, "batches_lost": {"type": "integer"}, "batches_shed": {"type": "integer"}, "events_shed": {"type": "integer"}, )"
      R"("detect_hz": {"type": "number"}, "track_hz": {"type": "number"}, "live_lines": {"type": "integer"}, )"
      R"("latency_median_ms": {"type": "number"}, "latency_p99_ms": {"type": "number"}, "latency_from_receipt": {"type": "boolean"}, )"
      R"("filters": {"type": "string"}, "masked_pixels": {"type": "integer"}}, )"
      R"("required": ["timestamp", "service", "source", "events_in", "event_rate", "batches_received", "batches_lost", "batches_shed", "events_shed", )"
      R"("detect_hz", "track_hz", "live_lines", "latency_median_ms", "latency_p99_ms", "latency_from_receipt", "filters", "masked_pixels"]})";
  return schema;
}

const std::string& camera_calibration_schema() {
  static const std::string schema =
      R"({"title": "foxglove.CameraCalibration", "description": "The calibrated camera evldt-lines gives its lines in (CAMERA_INFO_<CAM>): )"
      R"(K and D of the sensor, P of the rectified image the lines are in", "type": "object", "properties": {)"
      R"("timestamp": {"type": "object", "properties": {"sec": {"type": "integer", "minimum": 0}, "nsec": {"type": "integer", "minimum": 0, "maximum": 999999999}}, "required": ["sec", "nsec"]}, )"
      R"("frame_id": {"type": "string"}, "width": {"type": "integer", "minimum": 0}, "height": {"type": "integer", "minimum": 0}, )"
      R"("distortion_model": {"type": "string"}, "D": {"type": "array", "items": {"type": "number"}}, )"
      R"("K": {"type": "array", "items": {"type": "number"}, "minItems": 9, "maxItems": 9}, )"
      R"("R": {"type": "array", "items": {"type": "number"}, "minItems": 9, "maxItems": 9}, )"
      R"("P": {"type": "array", "items": {"type": "number"}, "minItems": 12, "maxItems": 12}}, )"
      R"("required": ["timestamp", "frame_id", "width", "height", "distortion_model", "D", "K", "R", "P"]})";
  return schema;
}

std::string base64(std::span<const std::uint8_t> bytes) {
  static constexpr char kAlphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  std::size_t i = 0;
  for (; i + 3 <= bytes.size(); i += 3) {
    const std::uint32_t word = std::uint32_t{bytes[i]} << 16 | std::uint32_t{bytes[i + 1]} << 8 | bytes[i + 2];
    for (int shift = 18; shift >= 0; shift -= 6) out += kAlphabet[(word >> shift) & 63];
  }
  if (const std::size_t left = bytes.size() - i; left > 0) {
    const std::uint32_t word = std::uint32_t{bytes[i]} << 16 | (left == 2 ? std::uint32_t{bytes[i + 1]} << 8 : 0u);
    out += kAlphabet[(word >> 18) & 63];
    out += kAlphabet[(word >> 12) & 63];
    out += left == 2 ? kAlphabet[(word >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

std::string compressed_image_json(std::uint64_t time_ns, const std::string& frame_id,
                                  std::span<const std::uint8_t> jpeg) {
  return fmt::format(R"({{"timestamp": {}, "frame_id": {}, "format": "jpeg", "data": "{}"}})", time_json(time_ns),
                     json_quoted(frame_id), base64(jpeg));
}

std::string image_annotations_json(std::uint64_t time_ns, std::span<const TrackedLine> lines,
                                   const AnnotationStyle& style, int scale) {
  const std::string time = time_json(time_ns);
  const auto s = static_cast<double>(scale);
  // One line list per colour: by status, or all in the style's colour.
  struct Group {
    const double (*colour)[4];
    std::string points;
  };
  std::array<Group, 4> groups{{{&kDetected, {}}, {&kGood, {}}, {&kBad, {}}, {&kMotion, {}}}};
  if (!style.by_status) groups[0].colour = &style.colour;
  const auto add_segment = [&](Group& group, const Segment& segment) {
    group.points +=
        fmt::format(R"({}{{"x": {:.2f}, "y": {:.2f}}}, {{"x": {:.2f}, "y": {:.2f}}})", group.points.empty() ? "" : ", ",
                    segment.q0.x() * s, segment.q0.y() * s, segment.q1.x() * s, segment.q1.y() * s);
  };
  std::string texts;
  for (const TrackedLine& line : lines) {
    Group& group = style.by_status ? groups[static_cast<std::size_t>(line.status)] : groups[0];
    add_segment(group, line.segment);
    if (style.motion) add_segment(groups[3], motion_arrow(line.segment, line.normal_velocity));
    if (style.ids) {
      const Point2 centre = line.segment.centre();
      const std::string text =
          style.motion ? fmt::format("{} {:.0f} px/s", line.id, line.normal_velocity) : std::to_string(line.id);
      texts += fmt::format(
          R"({}{{"timestamp": {}, "position": {{"x": {:.2f}, "y": {:.2f}}}, "text": "{}", "font_size": {}, )"
          R"("text_color": {}, "background_color": {}}})",
          texts.empty() ? "" : ", ", time, centre.x() * s + 3, centre.y() * s, text, 10 * scale,
          colour_json(*group.colour), colour_json(kTextBackground));
    }
  }
  std::string points;
  for (const Group& group : groups) {
    if (group.points.empty()) continue;
    points += fmt::format(
        R"({}{{"timestamp": {}, "type": 4, "points": [{}], "outline_color": {}, "outline_colors": [], "fill_color": {}, "thickness": {}}})",
        points.empty() ? "" : ", ", time, group.points, colour_json(*group.colour), colour_json(kTransparent),
        style.thickness * s);
  }
  return fmt::format(R"({{"circles": [], "points": [{}], "texts": [{}]}})", points, texts);
}

std::string stats_json(std::uint64_t time_ns, const stats_t& stats) {
  return fmt::format(
      R"({{"timestamp": {}, "service": {}, "source": {}, "events_in": {}, "event_rate": {:.1f}, "batches_received": {}, )"
      R"("batches_lost": {}, "batches_shed": {}, "events_shed": {}, "detect_hz": {:.1f}, "track_hz": {:.1f}, "live_lines": {}, )"
      R"("latency_median_ms": {:.2f}, "latency_p99_ms": {:.2f}, "latency_from_receipt": {}, "filters": {}, "masked_pixels": {}}})",
      time_json(time_ns), json_quoted(stats.service), json_quoted(stats.source), stats.events_in, stats.event_rate,
      stats.batches_received, stats.batches_lost, stats.batches_shed, stats.events_shed, stats.detect_hz,
      stats.track_hz, stats.live_lines, stats.latency_median_ms, stats.latency_p99_ms,
      stats.latency_from_receipt ? "true" : "false", json_quoted(stats.filters), stats.num_masked_pixels);
}

std::string camera_calibration_json(std::uint64_t time_ns, const camera_info_t& info) {
  // Foxglove's names of the models: OpenCV's fisheye is Kannala-Brandt; radial-tangential with
  // 8 coefficients is ROS's rational polynomial, with fewer plumb bob (k1 k2 p1 p2 k3).
  std::vector<double> d = info.coefficients;
  std::string model = "plumb_bob";
  if (info.sensor_distortion == "equidistant") {
    model = "kannala_brandt";
  } else if (d.size() == 8) {
    model = "rational_polynomial";
  } else {
    d.resize(5, 0.0);
  }
  std::string list;
  for (const double c : d) list += (list.empty() ? "" : ", ") + fmt::format("{}", c);
  return fmt::format(
      R"({{"timestamp": {}, "frame_id": {}, "width": {}, "height": {}, "distortion_model": "{}", "D": [{}], )"
      R"("K": [{}, 0, {}, 0, {}, {}, 0, 0, 1], "R": [1, 0, 0, 0, 1, 0, 0, 0, 1], "P": [{}, 0, {}, 0, 0, {}, {}, 0, 0, 0, 1, 0]}})",
      time_json(time_ns), json_quoted(info.source), info.width, info.height, model, list, info.fx, info.cx, info.fy,
      info.cy, info.fx, info.cx, info.fy, info.cy);
}

}  // namespace evldt
