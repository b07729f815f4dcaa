#include "evldt/sim/scenes.hpp"

#include <cmath>
#include <numbers>
#include <stdexcept>

#include "evldt/sim/random.hpp"

namespace evldt {

namespace {

constexpr double kTwoPi = 6.283185307179586;

std::vector<Vec2d> rectangle(double x0, double y0, double x1, double y1) {
  return {{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}};
}

std::vector<Vec2d> regular_polygon(Vec2d centre, double radius, int sides, double rotation) {
  std::vector<Vec2d> out;
  for (int i = 0; i < sides; ++i) {
    const double a = rotation + kTwoPi * i / sides;
    out.emplace_back(centre.x() + radius * std::cos(a), centre.y() + radius * std::sin(a));
  }
  return out;
}

Shape solid(std::vector<Vec2d> polygon, double brightness, bool straight = true) {
  Shape s;
  s.polygon = std::move(polygon);
  s.brightness = brightness;
  s.straight_edges = straight;
  return s;
}

MotionChannel sine(double amplitude, double frequency_hz, double phase = 0) {
  return {0, 0, amplitude, frequency_hz, phase};
}

// Three dark vertical bars taller than the view, swept fast left and right (peak ~940 px/s).
Scene three_lines_fast() {
  Scene s{"three-lines-fast", {640, 480}, 0.8, {}, {}, 1'000'000};
  for (const double x : {200.0, 320.0, 440.0}) s.shapes.push_back(solid(rectangle(x - 15, -20, x + 15, 500), 0.15));
  s.camera.tx = sine(150, 1.0);
  return s;
}

// A bright board with a dark circle and a dark square, moving mostly horizontally, so its
// horizontal edges produce few events.
Scene circle_board() {
  Scene s{"circle-board", {640, 480}, 0.2, {}, {}, 1'500'000};
  s.shapes.push_back(solid(rectangle(130, 110, 510, 370), 0.85));
  s.shapes.push_back(solid(regular_polygon({250, 240}, 70, 64, 0), 0.15, /*straight=*/false));
  s.shapes.push_back(solid(rectangle(360, 180, 450, 300), 0.15));
  s.camera.tx = sine(110, 0.8);
  s.camera.ty = sine(6, 0.5, 1.0);
  return s;
}

// Boxes and polygons under camera motion that turns, zooms and tilts, at changing speed.
Scene boxes_6dof() {
  Scene s{"boxes-6dof", {240, 180}, 0.45, {}, {}, 2'000'000};
  s.shapes.push_back(solid(rectangle(30, 30, 100, 80), 0.9));
  s.shapes.push_back(solid(rectangle(140, 25, 205, 95), 0.1));
  s.shapes.push_back(solid(regular_polygon({70, 130}, 32, 3, 0.3), 0.85));
  s.shapes.push_back(solid(regular_polygon({165, 135}, 30, 5, 0.0), 0.12));
  s.shapes.push_back(solid(rectangle(85, 65, 130, 110), 0.7));
  s.camera.pivot = {120, 90};
  s.camera.tx = {0, 0, 25, 0.45, 0};
  s.camera.ty = {0, 0, 15, 0.7, 1.0};
  s.camera.angle = sine(0.2, 0.35, 0.5);
  s.camera.log_scale = sine(0.12, 0.3, 2.0);
  s.camera.perspective_x = sine(4e-4, 0.25);
  s.camera.perspective_y = sine(3e-4, 0.2, 1.5);
  return s;
}

// Three bars in separate bands at 15, 80 and up to ~500 px/s: SCARF keeps the same number of
// events per block whatever the speed.
Scene multi_speed() {
  Scene s{"multi-speed", {346, 260}, 0.75, {}, {}, 1'500'000};
  const double bands[3][2] = {{15, 80}, {95, 165}, {180, 250}};
  for (int k = 0; k < 3; ++k) s.shapes.push_back(solid(rectangle(150, bands[k][0], 190, bands[k][1]), 0.15));
  s.shapes[0].motion.tx = {-40, 15, 0, 0, 0};
  s.shapes[1].motion.tx = {-60, 80, 0, 0, 0};
  s.shapes[2].motion.tx = sine(120, 0.65);
  return s;
}

// A dense grid of window-like rectangles at 1280x720 under camera motion: > 10 Mev/s.
Scene monitor_hd() {
  Scene s{"monitor-hd", {1280, 720}, 0.55, {}, {}, 500'000};
  for (int row = 0; row < 7; ++row) {
    for (int col = 0; col < 12; ++col) {
      const double x = 60 + col * 98, y = 40 + row * 92;
      s.shapes.push_back(solid(rectangle(x, y, x + 66, y + 58), (row + col) % 2 ? 0.3 : 0.85));
    }
  }
  s.camera.pivot = {640, 360};
  s.camera.tx = sine(180, 1.2);
  s.camera.ty = sine(60, 0.9, 0.7);
  s.camera.angle = sine(0.04, 0.8);
  return s;
}

// The scenes of real sensors' troubles, 5 s each: boxes-6dof's motion goes on.

// boxes-6dof seen by a noisy sensor (its camera model: scene_camera_model).
Scene noisy_boxes() {
  Scene s = boxes_6dof();
  s.name = "noisy-boxes";
  s.duration_us = 5'000'000;
  return s;
}

// A textured board under camera motion with two lamps in view: a mains light at 100 Hz and an LED
// at 300 Hz (round, so their outlines are not ground-truth lines), read out through a sensor whose
// bandwidth the switching bursts exceed.
Scene flicker_lamps() {
  Scene s{"flicker-lamps", {346, 260}, 0.35, {}, {}, 5'000'000};
  s.shapes.push_back(solid(rectangle(40, 30, 300, 230), 0.7));
  for (int row = 0; row < 3; ++row) {
    for (int col = 0; col < 4; ++col) {
      const double x = 60 + col * 60, y = 50 + row * 60;
      s.shapes.push_back(solid(rectangle(x, y, x + 36, y + 34), (row + col) % 2 ? 0.15 : 0.4));
    }
  }
  Shape mains = solid(regular_polygon({95, 140}, 16, 32, 0), 0.95, /*straight=*/false);
  mains.flicker = {100, 0.5, 0.6};
  Shape led = solid(regular_polygon({250, 90}, 12, 32, 0), 0.9, /*straight=*/false);
  led.flicker = {300, 0.3, 0.5};
  s.shapes.push_back(mains);
  s.shapes.push_back(led);
  s.camera.pivot = {173, 130};
  s.camera.tx = sine(30, 0.3);
  s.camera.ty = sine(18, 0.45, 1.0);
  s.camera.angle = sine(0.1, 0.25, 0.5);
  return s;
}

// boxes-6dof at night: dim shapes on a dark background (edges of 0.3-1.1 log contrast against
// thresholds of 0.2), with the background activity of a dark sensor (scene_camera_model).
Scene night_boxes() {
  Scene s = boxes_6dof();
  s.name = "night-boxes";
  s.duration_us = 5'000'000;
  s.background = 0.06;
  const double dim[] = {0.2, 0.025, 0.16, 0.03, 0.12};
  for (std::size_t k = 0; k < s.shapes.size(); ++k) s.shapes[k].brightness = dim[k];
  return s;
}

// Ten-second scenes for tracks that last, like the seed paper's 10 s sequences.

// boxes-6dof's boxes under a 10 s camera motion of other frequencies and phases.
Scene boxes_10s() {
  Scene s = boxes_6dof();
  s.name = "boxes-10s";
  s.duration_us = 10'000'000;
  s.camera.tx = {0, 0, 22, 0.23, 1.3};
  s.camera.ty = {0, 0, 14, 0.31, 0.4};
  s.camera.angle = sine(0.18, 0.17, 2.1);
  s.camera.log_scale = sine(0.1, 0.13, 0.7);
  s.camera.perspective_x = sine(3.5e-4, 0.11, 1.1);
  s.camera.perspective_y = sine(2.5e-4, 0.09, 2.5);
  return s;
}

// A textured planar poster (rectangles and triangles of many greys) under smooth 6-DoF camera motion
// for 10 s, at DAVIS346's size.
Scene poster_10s() {
  Scene s{"poster-10s", {346, 260}, 0.5, {}, {}, 10'000'000};
  s.shapes.push_back(solid(rectangle(28, 20, 318, 240), 0.8));
  const double greys[] = {0.1, 0.35, 0.95, 0.2, 0.6, 0.05, 0.45, 0.9, 0.25};
  int k = 0;
  for (int row = 0; row < 3; ++row) {
    for (int col = 0; col < 3; ++col, ++k) {
      const double x = 45 + col * 95, y = 35 + row * 68;
      if ((row + col) % 2 == 0) {
        s.shapes.push_back(solid(rectangle(x, y, x + 70, y + 48), greys[k]));
      } else {
        s.shapes.push_back(solid({{x + 35, y}, {x + 72, y + 50}, {x - 2, y + 50}}, greys[k]));
      }
    }
  }
  s.camera.pivot = {173, 130};
  s.camera.tx = {0, 0, 24, 0.21, 0.3};
  s.camera.ty = {0, 0, 16, 0.27, 1.7};
  s.camera.angle = sine(0.15, 0.15, 0.9);
  s.camera.log_scale = sine(0.1, 0.12, 2.4);
  s.camera.perspective_x = sine(4e-4, 0.1, 0.2);
  s.camera.perspective_y = sine(3e-4, 0.08, 1.9);
  return s;
}

// A printed board of square fiducial markers (as ArUco / AprilTag boards) at DAVIS346's size: 4 x 3
// black markers, each with an inner pattern of white rectangles on a 5 x 5 grid of cells, on a white
// board under 10 s of 6-DoF camera motion. Neighbouring markers' outer edges are collinear across the
// white gaps between them, and the patterns' edges end close to one another: each is its own
// ground-truth line, so a whole line that bridges a gap or cuts a corner is counted as invented.
Scene tag_board() {
  Scene s{"tag-board", {346, 260}, 0.3, {}, {}, 10'000'000};
  constexpr double kCell = 8, kMarker = 7 * kCell, kGap = 18, kLeft = 34, kTop = 28;
  s.shapes.push_back(solid(
      rectangle(kLeft - 14, kTop - 14, kLeft + 4 * kMarker + 3 * kGap + 14, kTop + 3 * kMarker + 2 * kGap + 14), 0.9));
  // White rectangles (first column, first row, end column, end row) on the inner 5 x 5 cells; two
  // of one marker are at least a cell apart, so every edge is seen whole.
  struct Cells {
    int c0, r0, c1, r1;
  };
  static const std::vector<Cells> patterns[12] = {
      {{0, 0, 2, 1}, {3, 0, 5, 2}, {0, 2, 1, 5}, {2, 3, 4, 4}},
      {{0, 0, 1, 3}, {2, 0, 5, 1}, {2, 2, 3, 5}, {4, 2, 5, 4}},
      {{1, 0, 4, 2}, {0, 3, 2, 5}, {3, 3, 5, 4}},
      {{0, 0, 5, 1}, {0, 2, 2, 3}, {3, 2, 5, 5}, {0, 4, 2, 5}},
      {{0, 0, 2, 2}, {3, 1, 5, 3}, {1, 3, 2, 5}, {3, 4, 5, 5}},
      {{2, 0, 3, 5}, {0, 1, 1, 4}, {4, 0, 5, 2}, {4, 3, 5, 5}},
      {{0, 0, 3, 1}, {4, 0, 5, 3}, {0, 2, 2, 4}, {3, 4, 5, 5}},
      {{1, 1, 4, 2}, {0, 3, 1, 5}, {2, 3, 5, 5}},
      {{0, 0, 1, 1}, {2, 0, 3, 2}, {4, 0, 5, 5}, {0, 2, 1, 5}, {2, 3, 3, 5}},
      {{0, 1, 5, 2}, {0, 3, 2, 5}, {3, 3, 4, 4}},
      {{0, 0, 2, 3}, {3, 0, 4, 1}, {3, 2, 5, 3}, {0, 4, 5, 5}},
      {{1, 0, 2, 2}, {3, 0, 5, 1}, {3, 2, 4, 4}, {0, 3, 2, 5}},
  };
  for (int row = 0; row < 3; ++row) {
    for (int col = 0; col < 4; ++col) {
      const double x = kLeft + col * (kMarker + kGap), y = kTop + row * (kMarker + kGap);
      s.shapes.push_back(solid(rectangle(x, y, x + kMarker, y + kMarker), 0.08));
      for (const Cells& c : patterns[row * 4 + col]) {
        s.shapes.push_back(solid(
            rectangle(x + (1 + c.c0) * kCell, y + (1 + c.r0) * kCell, x + (1 + c.c1) * kCell, y + (1 + c.r1) * kCell),
            0.9));
      }
    }
  }
  s.camera.pivot = {173, 130};
  s.camera.tx = {0, 0, 20, 0.19, 0.8};
  s.camera.ty = {0, 0, 12, 0.26, 2.2};
  s.camera.angle = sine(0.16, 0.14, 0.4);
  s.camera.log_scale = sine(0.09, 0.11, 1.6);
  s.camera.perspective_x = sine(4e-4, 0.09, 2.7);
  s.camera.perspective_y = sine(3e-4, 0.12, 0.5);
  return s;
}

}  // namespace

const std::vector<std::string>& scene_names() {
  static const std::vector<std::string> names{"three-lines-fast", "circle-board", "boxes-6dof",    "multi-speed",
                                              "monitor-hd",       "noisy-boxes",  "flicker-lamps", "night-boxes",
                                              "boxes-10s",        "poster-10s",   "tag-board"};
  return names;
}

SimulatorConfig scene_camera_model(std::string_view name) {
  SimulatorConfig model;
  if (name == "noisy-boxes") {  // the noise of real sensors
    model.noise_rate_hz = 2;
    model.hot_pixels = 40;
    model.contrast_sigma = 0.08;
  } else if (name == "flicker-lamps") {
    model.readout_rate_eps = 1e6;  // a switching lamp's burst takes longer than the queue holds
    model.readout_queue_us = 500;
    model.timestamp_jitter_us = 30;
    model.hot_pixels = 10;
  } else if (name == "night-boxes") {
    model.dark_noise_hz = 3;
    model.hot_pixels = 20;
    model.contrast_sigma = 0.05;
  }
  return model;
}

Scene make_scene(std::string_view name) {
  if (name == "three-lines-fast") return three_lines_fast();
  if (name == "circle-board") return circle_board();
  if (name == "boxes-6dof") return boxes_6dof();
  if (name == "multi-speed") return multi_speed();
  if (name == "monitor-hd") return monitor_hd();
  if (name == "noisy-boxes") return noisy_boxes();
  if (name == "flicker-lamps") return flicker_lamps();
  if (name == "night-boxes") return night_boxes();
  if (name == "boxes-10s") return boxes_10s();
  if (name == "poster-10s") return poster_10s();
  if (name == "tag-board") return tag_board();
  std::string valid;
  for (const auto& n : scene_names()) valid += (valid.empty() ? "" : ", ") + n;
  throw std::invalid_argument("unknown scene '" + std::string(name) + "' (built-in scenes: " + valid + ")");
}

Scene vary_camera_motion(Scene scene, std::uint64_t seed) {
  if (seed == 0) return scene;
  SimRandom random(seed);
  const auto scale = [&random] {
    return std::exp(std::log(0.8) + random.uniform() * (std::log(1.25) - std::log(0.8)));
  };
  Motion& m = scene.camera;
  for (MotionChannel* channel : {&m.tx, &m.ty, &m.angle, &m.log_scale, &m.perspective_x, &m.perspective_y}) {
    if (channel->amplitude == 0) continue;
    channel->phase = 2.0 * std::numbers::pi * random.uniform();
    channel->amplitude *= scale();
    channel->frequency_hz *= scale();
  }
  scene.name += "/m" + std::to_string(seed);
  return scene;
}

Scene with_occluder(Scene scene, Timestamp hidden_us) {
  if (hidden_us <= 0) return scene;
  // The bar's middle moves as x(t) = w/2 - A cos(pi t): off the image on the left at t = 0 (A = w/2
  // + width), across it by t = 1 s, at pi A px/s in the image's middle. A point there is hidden for
  // width / (pi A) = hidden: width = hidden pi (w/2 + width).
  constexpr double kCrossingsPerSecond = 1.0;
  const double sweep = std::numbers::pi * kCrossingsPerSecond;  // pi A is the peak speed
  const double hidden_s = static_cast<double>(hidden_us) * 1e-6, w = scene.sensor.width, h = scene.sensor.height;
  if (hidden_s * sweep >= 1) {
    throw std::invalid_argument("an occlusion of " + std::to_string(hidden_us / 1000) +
                                " ms is longer than a bar sweeping "
                                "once a second can hide anything (at most 318 ms)");
  }
  const double width = hidden_s * sweep * (w / 2) / (1 - hidden_s * sweep);
  Shape bar;
  // Tall enough to span the image however the camera moves it.
  bar.polygon = {Vec2d(-width / 2, -h), Vec2d(width / 2, -h), Vec2d(width / 2, 2 * h), Vec2d(-width / 2, 2 * h)};
  bar.brightness = scene.background > 0.5 ? 0.1 : 0.9;
  bar.motion.tx = {.base = w / 2,
                   .amplitude = w / 2 + width,
                   .frequency_hz = kCrossingsPerSecond / 2,
                   .phase = -std::numbers::pi / 2};
  scene.shapes.push_back(bar);
  scene.name += "/o" + std::to_string(hidden_us / 1000);
  return scene;
}

}  // namespace evldt
