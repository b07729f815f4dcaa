// Intensity frames (issue 28): the ECD layout written and read back, its bad inputs, and LSD ground
// truth from the simulator's frames against the scene's exact lines.

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "evldt/eval/frame_ground_truth.hpp"
#include "evldt/frames/frame_reader.hpp"
#include "evldt/frames/frame_writer.hpp"
#include "evldt/sim/event_simulator.hpp"
#include "evldt/sim/scenes.hpp"

namespace evldt {
namespace {

constexpr SensorSize kSensor{64, 48};

class FramesTest : public ::testing::Test {
 protected:
  void SetUp() override {
    folder_ = std::filesystem::temp_directory_path() /
              ("evldt_frames_" + std::to_string(getpid()) + "_" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::remove_all(folder_);
  }
  void TearDown() override { std::filesystem::remove_all(folder_); }

  // A dark frame with a bright square whose left side is at x = left.
  static cv::Mat square(int left) {
    cv::Mat image(kSensor.height, kSensor.width, CV_8UC1, cv::Scalar(30));
    cv::rectangle(image, cv::Rect(left, 12, 24, 24), cv::Scalar(220), cv::FILLED);
    return image;
  }
  void write_list(const std::string& text) { std::ofstream(folder_ / "images.txt") << text; }
  std::string error_of(const std::filesystem::path& path) {
    try {
      const auto reader = open_ecd_frames(path, kSensor);
      while (reader->next()) {
      }
    } catch (const FrameError& e) {
      return e.what();
    }
    return "";
  }

  std::filesystem::path folder_;
};

TEST_F(FramesTest, WrittenFramesReadBackInOrder) {
  EcdFrameWriter writer(folder_);
  for (int k = 0; k < 3; ++k) writer.write(10'000 * k + 5, square(8 + 4 * k));
  writer.close();
  const auto reader = open_ecd_frames(folder_, kSensor);
  for (int k = 0; k < 3; ++k) {
    const auto frame = reader->next();
    ASSERT_TRUE(frame);
    EXPECT_EQ(frame->t_us, 10'000 * k + 5);
    EXPECT_EQ(frame->image.cols, kSensor.width);
    EXPECT_EQ(frame->image.rows, kSensor.height);
    EXPECT_EQ(cv::norm(frame->image, square(8 + 4 * k), cv::NORM_INF), 0.0) << frame->name;  // PNG: lossless
  }
  EXPECT_FALSE(reader->next());
}

TEST_F(FramesTest, BadInputsNameTheFrame) {
  EcdFrameWriter writer(folder_);
  writer.write(0, square(8));
  writer.close();
  cv::Mat small(10, 10, CV_8UC1, cv::Scalar(0));
  cv::imwrite((folder_ / "images" / "small.png").string(), small);

  EXPECT_NE(error_of(folder_ / "none").find("no frame list"), std::string::npos);
  write_list("0.0 images/frame_00000000.png\n0.01 images/missing.png\n");
  EXPECT_NE(error_of(folder_).find("images/missing.png is missing"), std::string::npos) << error_of(folder_);
  std::ofstream(folder_ / "images" / "text.png") << "not a PNG";
  write_list("0.0 images/text.png\n");
  EXPECT_NE(error_of(folder_).find("images/text.png is not an image"), std::string::npos) << error_of(folder_);
  write_list("0.0 images/small.png\n");
  EXPECT_NE(error_of(folder_).find("small.png is 10x10, the sensor 64x48"), std::string::npos) << error_of(folder_);
  write_list("0.02 images/frame_00000000.png\n0.01 images/frame_00000000.png\n");
  EXPECT_NE(error_of(folder_).find("is earlier than the one before"), std::string::npos) << error_of(folder_);
  write_list("images/frame_00000000.png\n");
  EXPECT_NE(error_of(folder_).find("images.txt:1: expected"), std::string::npos) << error_of(folder_);
  // Nothing is scored from a folder that throws, and an empty one has no ground truth.
  write_list("");
  const auto empty = open_ecd_frames(folder_, kSensor);
  EXPECT_THROW(frame_ground_truth_steps(*empty, LsdParams{}), FrameError);
}

TEST_F(FramesTest, LsdFindsTheSidesOfASquare) {
  const std::vector<Segment> found = lsd_segments(square(20), LsdParams{});
  int vertical_at_left = 0;
  for (const Segment& s : found) {
    if (std::abs(s.q0.x() - 20.0f) < 1.0f && std::abs(s.q1.x() - 20.0f) < 1.0f && s.length() > 18) ++vertical_at_left;
  }
  EXPECT_GE(found.size(), 4u);
  EXPECT_EQ(vertical_at_left, 1);
  LsdParams long_only;
  long_only.min_length_px = 30;
  EXPECT_TRUE(lsd_segments(square(20), long_only).empty());  // the sides are 24 px
}

// The whole chain: the simulator's frames, written and read back, LSD on them, scored against
// the scene's exact lines: the imitation the paper relies on is close on a scene of clean edges.
TEST_F(FramesTest, LsdOnSimulatedFramesMatchesTheExactLines) {
  Scene scene = make_scene("three-lines-fast");
  scene.duration_us = 200'000;
  const EventSimulator simulator(scene, SimulatorConfig{});
  EcdFrameWriter writer(folder_);
  std::vector<std::uint8_t> grey;
  for (Timestamp t = 0; t <= scene.duration_us; t += 20'000) {
    simulator.render_frame(t, grey);
    writer.write(t, cv::Mat(scene.sensor.height, scene.sensor.width, CV_8UC1, grey.data()));
  }
  writer.close();
  const auto frames = open_ecd_frames(folder_, scene.sensor);
  const GroundTruthSteps lsd = frame_ground_truth_steps(*frames, LsdParams{});
  ASSERT_EQ(lsd.times.size(), 11u);
  const StreamEvaluator evaluator = evaluate_steps_against(lsd, scene_ground_truth_steps(scene, 20'000), scene.sensor, {0.01});
  EXPECT_EQ(evaluator.hold_us(), 30'000);
  EXPECT_GT(evaluator.accuracy().summed_prf(0).f, 0.9);
}

}  // namespace
}  // namespace evldt
