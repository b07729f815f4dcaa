#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <opencv2/calib3d.hpp>

#include "evldt/calibration/camera_model.hpp"
#include "evldt/calibration/rectifier.hpp"
#include "evldt/pipeline/deterministic_pipeline.hpp"
#include "evldt/sim/event_simulator.hpp"
#include "evldt/sim/scenes.hpp"

namespace evldt {
namespace {

const std::filesystem::path kFixtures = EVLDT_SOURCE_DIR "/tests/data/calibration";

TEST(CameraModel, EveryFormatReadsTheSameCamera) {
  // The Event Camera Dataset's DAVIS240C, as each tool writes it.
  for (const char* file : {"davis240c_calib.txt", "davis240c_camera_info.yaml", "davis240c_camchain.yaml",
                           "davis240c_opencv.yaml", "davis240c_opencv.xml"}) {
    SCOPED_TRACE(file);
    const CameraModel model = read_camera_model(kFixtures / file);
    EXPECT_DOUBLE_EQ(model.fx, 199.092366542);
    EXPECT_DOUBLE_EQ(model.fy, 198.82882047);
    EXPECT_DOUBLE_EQ(model.cx, 132.192071378);
    EXPECT_DOUBLE_EQ(model.cy, 110.712660011);
    EXPECT_EQ(model.distortion, CameraModel::Distortion::RadialTangential);
    ASSERT_GE(model.coefficients.size(), 4u);
    EXPECT_DOUBLE_EQ(model.coefficients[0], -0.368436311798);
    EXPECT_DOUBLE_EQ(model.coefficients[1], 0.150947243557);
    EXPECT_DOUBLE_EQ(model.coefficients[2], -0.000296130534385);
    EXPECT_DOUBLE_EQ(model.coefficients[3], -0.000759431726241);
    if (std::string(file) == "davis240c_calib.txt") {
      EXPECT_EQ(model.size, (SensorSize{0, 0}));  // calib.txt does not say
    } else {
      EXPECT_EQ(model.size, (SensorSize{240, 180}));
    }
  }
  for (const char* file : {"hd_equidistant_camera_info.yaml", "hd_equidistant_camchain.yaml"}) {
    SCOPED_TRACE(file);
    const CameraModel model = read_camera_model(kFixtures / file);
    EXPECT_EQ(model.distortion, CameraModel::Distortion::Equidistant);
    EXPECT_EQ(model.coefficients, (std::vector<double>{0.05, 0.01, 0.0, 0.0}));
    EXPECT_EQ(model.size, (SensorSize{1280, 720}));
    EXPECT_DOUBLE_EQ(model.fx, 800.0);
    EXPECT_DOUBLE_EQ(model.cy, 360.0);
  }
}

TEST(CameraModel, UndistortionInvertsTheLens) {
  // Each pixel's undistorted centre, distorted again by OpenCV's forward model, lands on the pixel.
  for (const char* file : {"davis240c_camera_info.yaml", "hd_equidistant_camera_info.yaml"}) {
    SCOPED_TRACE(file);
    const CameraModel model = read_camera_model(kFixtures / file);
    const std::vector<float> centres = undistorted_pixel_centres(model, model.size);
    const cv::Matx33d k(model.fx, 0, model.cx, 0, model.fy, model.cy, 0, 0, 1);
    int checked = 0;
    for (int y = 0; y < model.size.height; y += 17) {
      for (int x = 0; x < model.size.width; x += 23) {
        const std::size_t i =
            static_cast<std::size_t>(y) * static_cast<std::size_t>(model.size.width) + static_cast<std::size_t>(x);
        // Back to normalised coordinates, then through the lens (OpenCV: a pixel's centre at its index).
        const cv::Point2d normalised((centres[2 * i] - 0.5 - model.cx) / model.fx,
                                     (centres[2 * i + 1] - 0.5 - model.cy) / model.fy);
        std::vector<cv::Point2d> back;
        if (model.distortion == CameraModel::Distortion::Equidistant) {
          cv::fisheye::distortPoints(std::vector<cv::Point2d>{normalised}, back, k, model.coefficients);
        } else {
          cv::projectPoints(std::vector<cv::Point3d>{{normalised.x, normalised.y, 1.0}}, cv::Vec3d::zeros(),
                            cv::Vec3d::zeros(), k, model.coefficients, back);
        }
        EXPECT_NEAR(back[0].x, x, 0.01) << "pixel " << x << ", " << y;
        EXPECT_NEAR(back[0].y, y, 0.01) << "pixel " << x << ", " << y;
        ++checked;
      }
    }
    EXPECT_GT(checked, 100);
  }
}

TEST(CameraModel, TheLensMovesTheCornersNotTheCentre) {
  // The DAVIS240C's barrel lens: a corner pixel sees about a quarter further out than a pinhole.
  const CameraModel model = read_camera_model(kFixtures / "davis240c_calib.txt");
  const SensorSize sensor{240, 180};
  const std::vector<float> centres = undistorted_pixel_centres(model, sensor);
  const auto at = [&](int x, int y) {
    const std::size_t i = static_cast<std::size_t>(y) * 240 + static_cast<std::size_t>(x);
    return std::pair<double, double>{centres[2 * i], centres[2 * i + 1]};
  };
  const auto [px, py] = at(132, 111);
  EXPECT_NEAR(px, 132.5, 0.5);
  EXPECT_NEAR(py, 111.5, 0.5);
  const auto [cx, cy] = at(0, 0);
  const double before = std::hypot(0.5 - (model.cx + 0.5), 0.5 - (model.cy + 0.5));
  const double after = std::hypot(cx - (model.cx + 0.5), cy - (model.cy + 0.5));
  EXPECT_GT(after / before, 1.15);
  EXPECT_LT(after / before, 1.5);
  // So the corner pixels see beyond the rectified image and feed none of its pixels, the centre
  // feeds itself, and towards the edges, where the lens squeezes the scene, a sensor pixel feeds
  // more than one; every rectified pixel is fed.
  const auto table = rectification_table(model, sensor);
  const auto feeds = [&](std::size_t pixel) { return table->first[pixel + 1] - table->first[pixel]; };
  EXPECT_EQ(feeds(0), 0u);
  ASSERT_EQ(feeds(111 * 240 + 132), 1u);
  EXPECT_EQ(table->targets[table->first[111 * 240 + 132]], 132u | 111u << 16);
  std::size_t squeezed = 0;
  for (std::size_t pixel = 0; pixel < 240 * 180; ++pixel) squeezed += feeds(pixel) > 1;
  EXPECT_GT(squeezed, 100u);
  EXPECT_EQ(table->targets.size(), 240u * 180u);
  EXPECT_THROW(
      static_cast<void>(rectification_table(read_camera_model(kFixtures / "davis240c_camera_info.yaml"), {346, 260})),
      std::invalid_argument);
}

TEST(CameraModel, ABadFileSaysWhichAndWhy) {
  const auto dir = std::filesystem::temp_directory_path() / ("evldt_calibration_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const auto expect_error = [&](const std::string& name, const std::string& text, const std::string& why) {
    std::ofstream(dir / name) << text;
    try {
      static_cast<void>(read_camera_model(dir / name));
      ADD_FAILURE() << name << " was read";
    } catch (const std::runtime_error& error) {
      EXPECT_NE(std::string(error.what()).find(name), std::string::npos) << error.what();
      EXPECT_NE(std::string(error.what()).find(why), std::string::npos) << error.what();
    }
  };
  expect_error("short.txt", "199 198 132 110 -0.3 0.1 0\n", "found 7 numbers");
  expect_error("word.txt", "199 198 f 110\n", "'f' is not a number");
  expect_error("matrix.yaml", "camera_matrix:\n  data: [1, 0, 0, 0, 1, 0, 0, 0]\n", "9 numbers");
  expect_error("model.yaml", "camera_matrix:\n  data: [1, 0, 0, 0, 1, 0, 0, 0, 1]\ndistortion_model: spline\n",
               "spline");
  expect_error("fisheye.yaml",
               "cam0:\n  camera_model: pinhole\n  intrinsics: [1, 1, 0, 0]\n  distortion_model: equidistant\n  "
               "distortion_coeffs: [0.1, 0, 0, 0, 0]\n",
               "equidistant distortion takes 4 coefficients");
  expect_error("focal.yaml", "cam0:\n  intrinsics: [0, 1, 0, 0]\n", "focal lengths must be positive");
  expect_error("other.yaml", "hello: world\n", "neither a ROS camera_info");
  expect_error("broken.yaml", "camera_matrix: [\n", "not valid YAML");
  EXPECT_THROW(static_cast<void>(read_camera_model(dir / "missing.yaml")), std::runtime_error);
  std::filesystem::remove_all(dir);
}

TEST(Rectifier, MovesEventsToTheRectifiedPixelsTheirPixelFeedsInTurnAndCountsThoseOff) {
  // Rectified (2, 1) and (3, 1) are seen by sensor pixel (1, 0), rectified (0, 0) by (2, 1).
  std::vector<std::int32_t> sources(8, -1);
  sources[6] = 1;
  sources[7] = 1;
  sources[0] = 6;
  const RectificationTable table = RectificationTable::from_sources({4, 2}, sources);
  Rectifier rectifier(table);
  EventBatch in, out;
  in.push_back(10, 1, 0, 1);
  in.push_back(11, 0, 0, -1);  // feeds none
  in.push_back(12, 2, 1, 1);
  in.push_back(13, 1, 0, -1);  // (1, 0) again: its second rectified pixel
  rectifier.apply(in, out);
  ASSERT_EQ(out.size(), 3u);
  EXPECT_EQ(out[0], (Event{10, 2, 1, 1}));
  EXPECT_EQ(out[1], (Event{12, 0, 0, 1}));
  EXPECT_EQ(out[2], (Event{13, 3, 1, -1}));
  EXPECT_EQ(rectifier.dropped(), 1u);
  in.clear();
  in.push_back(14, 1, 0, 1);  // and the first again, in the next batch
  rectifier.apply(in, out);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0], (Event{14, 2, 1, 1}));
}

EventBatch simulate_all(const Scene& scene, const SimulatorConfig& config) {
  EventSimulator simulator(scene, config);
  EventBatch events;
  while (simulator.run_until(simulator.now_us() + 10'000, events)) {
  }
  return events;
}

TEST(Calibration, APinholeCalibrationChangesNothing) {
  // A calibration without distortion: the same events from the simulator, the same lines from the
  // pipeline, whatever path they took through the tables.
  Scene scene = make_scene("boxes-6dof");
  scene.duration_us = 300'000;
  const auto file = std::filesystem::temp_directory_path() / ("evldt_pinhole_" + std::to_string(::getpid()) + ".txt");
  std::ofstream(file) << "199.1 198.8 119.5 89.5\n";
  const CameraModel pinhole = read_camera_model(file);
  std::filesystem::remove(file);
  SimulatorConfig through_lens = scene_camera_model("boxes-6dof");
  const EventBatch plain = simulate_all(scene, through_lens);
  through_lens.lens = std::make_shared<const std::vector<float>>(undistorted_pixel_centres(pinhole, scene.sensor));
  const EventBatch lensed = simulate_all(scene, through_lens);
  ASSERT_GT(plain.size(), 10'000u);
  EXPECT_EQ(plain.t, lensed.t);
  EXPECT_EQ(plain.x, lensed.x);
  EXPECT_EQ(plain.y, lensed.y);

  const auto run = [&](PipelineConfig config) {
    DeterministicPipeline pipeline(config);
    std::vector<std::pair<Timestamp, Segment>> seen;
    pipeline.set_output(10'000, [&](const OutputStep& step) {
      for (const TrackedLine& line : step.segments.lines()) seen.emplace_back(step.t, line.segment);
    });
    pipeline.process(plain);
    return seen;
  };
  PipelineConfig config = default_config_for(scene.sensor);
  const auto without = run(config);
  config.rectification = rectification_table(pinhole, scene.sensor);
  const auto with = run(config);
  ASSERT_GT(without.size(), 500u);
  ASSERT_EQ(without.size(), with.size());
  for (std::size_t i = 0; i < with.size(); ++i) {
    EXPECT_EQ(without[i].first, with[i].first);
    EXPECT_EQ(without[i].second.q0, with[i].second.q0);
    EXPECT_EQ(without[i].second.q1, with[i].second.q1);
  }
}

}  // namespace
}  // namespace evldt
