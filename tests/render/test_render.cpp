#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "evldt/render/scene_renderer.hpp"
#include "evldt/render/short_ids.hpp"
#include "evldt/render/status_text.hpp"

namespace evldt {
namespace {

TEST(ShortIds, NumbersIdsInOrderOfFirstAppearanceAndKeepsThemWhileSeen) {
  ShortIds ids(3);
  std::vector<std::uint32_t> labels;
  ids.label(std::vector<std::uint64_t>{1'733'000'000'001, 1'733'000'000'002}, labels);
  EXPECT_EQ(labels, (std::vector<std::uint32_t>{1, 2}));
  ids.label(std::vector<std::uint64_t>{1'733'000'000'002, 1'733'000'000'007}, labels);
  EXPECT_EQ(labels, (std::vector<std::uint32_t>{2, 3}));
  // Id ...001 was last seen at call 1; at call 3 it has been away for 2 calls and is kept, so a
  // re-associated id comes back under its old number.
  ids.label(std::vector<std::uint64_t>{1'733'000'000'001}, labels);
  EXPECT_EQ(labels, (std::vector<std::uint32_t>{1}));
  // Calls 4-6 without it: forgotten at call 6 (away for 3 calls); numbers are never reused.
  for (int call = 4; call <= 6; ++call) ids.label(std::vector<std::uint64_t>{1'733'000'000'007}, labels);
  EXPECT_EQ(ids.remembered(), 1u);
  ids.label(std::vector<std::uint64_t>{1'733'000'000'001}, labels);
  EXPECT_EQ(labels, (std::vector<std::uint32_t>{4}));
}

TEST(ToggleLayer, EachKeyFlipsItsLayerAndOtherKeysNothing) {
  RenderOptions options;
  // By default: whole lines with their ids over segments without theirs, no grid.
  EXPECT_TRUE(options.show_whole_lines && options.show_whole_line_ids && options.show_segments &&
              !options.show_segment_ids);
  EXPECT_FALSE(options.show_grid);
  const std::vector<std::pair<int, bool RenderOptions::*>> keys = {
      {'e', &RenderOptions::show_events},         {'s', &RenderOptions::show_segments},
      {'b', &RenderOptions::show_bad_tracks},     {'w', &RenderOptions::show_whole_lines},
      {'i', &RenderOptions::show_whole_line_ids}, {'m', &RenderOptions::show_motion},
      {'n', &RenderOptions::show_segment_ids},    {'g', &RenderOptions::show_grid}};
  for (const auto& [key, shown] : keys) {
    const RenderOptions before = options;
    EXPECT_TRUE(toggle_layer(options, key)) << static_cast<char>(key);
    EXPECT_NE(options.*shown, before.*shown) << static_cast<char>(key);
    for (const auto& [other_key, other] : keys) {
      if (other_key != key) {
        EXPECT_EQ(options.*other, before.*other)
            << static_cast<char>(key) << " changed " << static_cast<char>(other_key);
      }
    }
  }
  const RenderOptions before = options;
  EXPECT_FALSE(toggle_layer(options, 'x'));
  EXPECT_FALSE(toggle_layer(options, -1));  // no key pressed
  for (const auto& [key, shown] : keys) EXPECT_EQ(options.*shown, before.*shown);
  EXPECT_EQ(layer_key_help(),
            (std::vector<std::string>{"keys: e events", "s segments", "b bad tracks", "w whole lines",
                                      "i whole-line ids", "m motion", "n segment ids", "g block grid", "q quit"}));
}

constexpr SensorSize kSensor{40, 30};

cv::Vec3b pixel(const cv::Mat& canvas, int x, int y) { return canvas.at<cv::Vec3b>(y, x); }
bool black(const cv::Vec3b& p) { return p == cv::Vec3b(0, 0, 0); }

TEST(RenderScene, LayersAppearOnlyWhenSwitchedOn) {
  std::vector<std::uint16_t> surface(static_cast<std::size_t>(kSensor.width * kSensor.height), 0);
  surface[static_cast<std::size_t>(25 * kSensor.width + 30)] = 1;  // one active pixel at (30, 25)
  TrackedLine good{.id = 7, .segment = {Point2(5, 10.5f), Point2(25, 10.5f)}, .status = LineStatus::GoodTrack};
  TrackedLine bad{.id = 8, .segment = {Point2(5, 20.5f), Point2(25, 20.5f)}, .status = LineStatus::BadTrack};
  const std::vector<TrackedLine> lines = {good, bad};
  cv::Mat canvas;
  RenderOptions options;  // scale 1: canvas pixels are sensor pixels
  render_scene(kSensor, surface, lines, options, canvas);
  EXPECT_FALSE(black(pixel(canvas, 30, 25)));
  EXPECT_FALSE(black(pixel(canvas, 15, 10)));
  EXPECT_FALSE(black(pixel(canvas, 15, 20)));
  EXPECT_TRUE(black(pixel(canvas, 2, 2)));  // no grid by default

  options.show_events = false;
  options.show_bad_tracks = false;
  render_scene(kSensor, surface, lines, options, canvas);
  EXPECT_TRUE(black(pixel(canvas, 30, 25)));
  EXPECT_FALSE(black(pixel(canvas, 15, 10)));
  EXPECT_TRUE(black(pixel(canvas, 15, 20)));

  options.show_segments = false;
  options.show_grid = true;
  options.grid_block_size = 8;  // borders at 4, 12, 20, ...
  render_scene(kSensor, surface, lines, options, canvas);
  EXPECT_TRUE(black(pixel(canvas, 15, 10)));
  EXPECT_FALSE(black(pixel(canvas, 4, 2)));
  EXPECT_FALSE(black(pixel(canvas, 2, 12)));
  EXPECT_TRUE(black(pixel(canvas, 2, 2)));
}

TEST(RenderScene, AWholeLinesMotionIsAnOrangeArrowWhereItMovesAndTheLayerHidesIt) {
  // Drawn left to right, moving up the image at 80 px/s: an arrow from (15, 20) to (15, 12).
  TrackedLine moving{.id = 3, .segment = {Point2(5, 20.5f), Point2(25, 20.5f)}, .status = LineStatus::GoodTrack};
  moving.normal_velocity = -80;
  const std::vector<TrackedLine> lines = {moving};
  RenderOptions options;
  options.show_whole_line_ids = false;
  cv::Mat canvas(kSensor.height, kSensor.width, CV_8UC3, cv::Scalar(0, 0, 0));
  draw_whole_lines(lines, options, canvas);
  const auto orange = [](const cv::Vec3b& p) { return p[2] > 150 && p[0] < 100; };  // BGR; cyan is blue
  EXPECT_TRUE(orange(pixel(canvas, 15, 15))) << pixel(canvas, 15, 15);
  EXPECT_TRUE(black(pixel(canvas, 15, 25)));  // nothing on the side it leaves
  canvas.setTo(cv::Scalar(0, 0, 0));
  options.show_motion = false;
  draw_whole_lines(lines, options, canvas);
  EXPECT_TRUE(black(pixel(canvas, 15, 15)));
  EXPECT_FALSE(black(pixel(canvas, 15, 20)));  // the line itself
}

// The viz's status fields at a 240x180 sensor drawn at scale 1: wrapped, every line fits the
// picture (drawn on one twice as wide, no text reaches past its width), fields whole and in order.
TEST(StatusText, FieldsWrapToThePictureWidthWholeAndInOrder) {
  const std::vector<std::string> fields = {"cam0",    "t=12.345 s",    "1.23 Mev/s",   "57 lines",
                                           "9 whole", "detect 100 Hz", "track 500 Hz", "latency 3.2/7.0 ms",
                                           "lost 0",  "shed 0",        "hot pixels 3"};
  for (const int width : {240, 346, 640, 1280}) {
    const std::vector<std::string> lines = wrap_fields(fields, width);
    std::vector<std::string> rejoined;
    for (const std::string& line : lines) {
      for (std::size_t start = 0; start <= line.size();) {
        const std::size_t gap = std::min(line.find("  ", start), line.size());
        rejoined.push_back(line.substr(start, gap - start));
        start = gap + 2;
      }
    }
    EXPECT_EQ(rejoined, fields) << width;
    cv::Mat canvas(400, 2 * width, CV_8UC3, cv::Scalar(0, 0, 0));
    EXPECT_EQ(put_text_lines(canvas, lines, 0), static_cast<int>(lines.size()));
    cv::Mat beyond;
    cv::cvtColor(canvas.colRange(width, 2 * width), beyond, cv::COLOR_BGR2GRAY);
    EXPECT_EQ(cv::countNonZero(beyond), 0) << width << " px: a line runs past the picture";
    if (width == 1280) {
      EXPECT_EQ(lines.size(), 1u);
    }
    if (width == 240) {
      EXPECT_GE(lines.size(), 4u);
    }
  }
  const std::vector<std::string> wide = {"a field far wider than the narrow picture it is drawn on"};
  EXPECT_EQ(wrap_fields(wide, 60), wide);  // never split
}

}  // namespace
}  // namespace evldt
