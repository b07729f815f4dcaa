// Foxglove JSON messages: base64 as RFC 4648 gives it, annotations in image coordinates by colour.

#include <gtest/gtest.h>

#include "evldt/export/foxglove_json.hpp"

namespace evldt {
namespace {

std::string base64_of(const std::string& text) {
  return base64(std::span<const std::uint8_t>(reinterpret_cast<const std::uint8_t*>(text.data()), text.size()));
}

TEST(Base64, Rfc4648TestVectors) {
  EXPECT_EQ(base64_of(""), "");
  EXPECT_EQ(base64_of("f"), "Zg==");
  EXPECT_EQ(base64_of("fo"), "Zm8=");
  EXPECT_EQ(base64_of("foo"), "Zm9v");
  EXPECT_EQ(base64_of("foob"), "Zm9vYg==");
  EXPECT_EQ(base64_of("fooba"), "Zm9vYmE=");
  EXPECT_EQ(base64_of("foobar"), "Zm9vYmFy");
  EXPECT_EQ(base64_of(std::string("\xff\xd8\xff", 3)), "/9j/");
}

TrackedLine line(std::uint64_t id, float x0, float y0, float x1, float y1, LineStatus status) {
  TrackedLine out;
  out.id = id;
  out.segment = Segment{Point2(x0, y0), Point2(x1, y1)};
  out.status = status;
  return out;
}

TEST(ImageAnnotations, ALineListPerStatusColourScaledAndIdsAtTheCentres) {
  const std::vector<TrackedLine> lines = {line(7, 1, 2, 11, 2, LineStatus::GoodTrack),
                                          line(9, 0, 0, 0, 4, LineStatus::BadTrack),
                                          line(8, 5, 5, 6, 6, LineStatus::GoodTrack)};
  const std::string segments = image_annotations_json(1'500'000'000, lines, AnnotationStyle{}, 2);
  // Good tracks together (green), then bad (red); no detected ones: no empty list.
  EXPECT_EQ(
      segments,
      R"({"circles": [], "points": [{"timestamp": {"sec": 1, "nsec": 500000000}, "type": 4, "points": [{"x": 2.00, "y": 4.00}, {"x": 22.00, "y": 4.00}, )"
      R"({"x": 10.00, "y": 10.00}, {"x": 12.00, "y": 12.00}], "outline_color": {"r": 0.240, "g": 0.860, "b": 0.310, "a": 1.000}, "outline_colors": [], )"
      R"("fill_color": {"r": 0.000, "g": 0.000, "b": 0.000, "a": 0.000}, "thickness": 2}, {"timestamp": {"sec": 1, "nsec": 500000000}, "type": 4, )"
      R"("points": [{"x": 0.00, "y": 0.00}, {"x": 0.00, "y": 8.00}], "outline_color": {"r": 0.900, "g": 0.160, "b": 0.160, "a": 1.000}, "outline_colors": [], )"
      R"("fill_color": {"r": 0.000, "g": 0.000, "b": 0.000, "a": 0.000}, "thickness": 2}], "texts": []})");
  AnnotationStyle whole{.thickness = 2, .by_status = false, .ids = true};
  const std::string whole_lines = image_annotations_json(0, std::span(lines).first(1), whole, 1);
  EXPECT_NE(whole_lines.find(
                R"("texts": [{"timestamp": {"sec": 0, "nsec": 0}, "position": {"x": 9.00, "y": 2.00}, "text": "7", )"),
            std::string::npos)
      << whole_lines;
  EXPECT_NE(whole_lines.find(R"("outline_color": {"r": 0.160, "g": 0.820, "b": 0.900, "a": 1.000})"), std::string::npos)
      << whole_lines;
  EXPECT_EQ(image_annotations_json(0, {}, AnnotationStyle{}, 1), R"({"circles": [], "points": [], "texts": []})");
}

TEST(ImageAnnotations, WithMotionEachLineGetsAnArrowAndItsVelocityInItsText) {
  TrackedLine moving = line(7, 1, 2, 11, 2, LineStatus::GoodTrack);
  moving.normal_velocity = -50;  // up the image, for a line drawn left to right: 5 px in 0.1 s
  const AnnotationStyle whole{.thickness = 2, .by_status = false, .ids = true, .motion = true};
  const std::string json = image_annotations_json(0, std::span(&moving, 1), whole, 2);
  // The arrow from the middle (6, 2) to (6, -3), scaled by 2, in orange.
  EXPECT_NE(
      json.find(
          R"("points": [{"x": 12.00, "y": 4.00}, {"x": 12.00, "y": -6.00}], "outline_color": {"r": 1.000, "g": 0.550, "b": 0.000, "a": 1.000})"),
      std::string::npos)
      << json;
  EXPECT_NE(json.find(R"("text": "7 -50 px/s")"), std::string::npos) << json;
}

}  // namespace
}  // namespace evldt
