#include "evldt/app/simulator_options.hpp"

#include <cmath>

#include "evldt/app/pipeline_options.hpp"
#include "evldt/calibration/camera_model.hpp"
#include "evldt/sim/scenes.hpp"

namespace evldt {

void SimulatorOptions::add_to(CLI::App& app, bool scene_required) {
  std::string names;
  for (const auto& n : scene_names()) names += (names.empty() ? "" : ", ") + n;
  auto* scene =
      app.add_option("--scene", scene_, "Built-in simulated scene: " + names)->check(CLI::IsMember(scene_names()));
  if (scene_required) scene->default_val(std::string(kDefaultScene))->capture_default_str();
  auto* group = app.add_option_group("Simulator", "Event-camera model of the built-in scenes");
  group->add_option("--duration-s", duration_s_, "Scene duration in seconds (default: the scene's own)")
      ->check(finite_number() & CLI::Range(0.001, 3600.0));
  group->add_option("--seed", seed_, "Random seed (thresholds, noise)")->capture_default_str();
  group
      ->add_option("--motion-seed", motion_seed_,
                   "Another recording of the scene: new phases, amplitudes and frequencies of the camera motion "
                   "(0: the scene's own)")
      ->capture_default_str();
  group
      ->add_option("--occlude-ms", occlude_ms_,
                   "A bar in front of the scene sweeps across the image once a second and back, hiding each edge it "
                   "passes for about this long (0: none)")
      ->capture_default_str()
      ->check(CLI::Range(0, 300));
  group->add_option("--contrast", contrast_, "Contrast threshold C+ = C- (log intensity; default 0.2)")
      ->check(finite_number() & CLI::Range(0.01, 5.0));
  group
      ->add_option("--contrast-sigma", contrast_sigma_,
                   "Per-pixel threshold spread (std dev; default 0.03, the scene's own)")
      ->check(finite_number() & CLI::Range(0.0, 1.0));
  group->add_option("--refractory-us", refractory_us_, "Pixel refractory period (default 100)")
      ->check(CLI::Range(Timestamp{0}, Timestamp{1'000'000}));
  group
      ->add_option("--noise-rate-hz", noise_rate_hz_,
                   "Background noise events per pixel per second (default 0.1, the scene's own)")
      ->check(finite_number() & CLI::Range(0.0, 1000.0));
  group
      ->add_option("--dark-noise-hz", dark_noise_hz_,
                   "More background noise per pixel per second, times (1 - brightness)")
      ->check(finite_number() & CLI::Range(0.0, 1000.0));
  group->add_option("--hot-pixels", hot_pixels_, "Number of hot pixels (default 0, the scene's own)")
      ->check(CLI::Range(0, 100000));
  group
      ->add_option("--readout-rate-eps", readout_rate_eps_,
                   "Readout bandwidth in events/s; 0: unlimited (default, the scene's own)")
      ->check(finite_number() & CLI::Range(0.0, 1e10));
  group->add_option("--jitter-us", jitter_us_, "Timestamps up to this much later (default 0, the scene's own)")
      ->check(CLI::Range(Timestamp{0}, Timestamp{100'000}));
  group
      ->add_option("--lens", lens_,
                   "The scene through this calibrated lens (a file --calibration reads): events in sensor pixels, the "
                   "scene's exact lines rectified")
      ->check(CLI::ExistingFile);
}

SimulatorConfig SimulatorOptions::config() const {
  SimulatorConfig config = scene_.empty() ? SimulatorConfig{} : scene_camera_model(scene_);
  config.seed = seed_;
  if (contrast_) config.contrast_on = config.contrast_off = *contrast_;
  if (contrast_sigma_) config.contrast_sigma = *contrast_sigma_;
  if (refractory_us_) config.refractory_us = *refractory_us_;
  if (noise_rate_hz_) config.noise_rate_hz = *noise_rate_hz_;
  if (dark_noise_hz_) config.dark_noise_hz = *dark_noise_hz_;
  if (hot_pixels_) config.hot_pixels = *hot_pixels_;
  if (readout_rate_eps_) config.readout_rate_eps = *readout_rate_eps_;
  if (jitter_us_) config.timestamp_jitter_us = *jitter_us_;
  if (lens_ && !scene_.empty()) {
    const CameraModel model = read_camera_model(*lens_);
    const SensorSize sensor = make_scene(scene_).sensor;
    if (model.size.width > 0 && !(model.size == sensor)) {
      throw std::invalid_argument("--lens: the calibration is of a " + std::to_string(model.size.width) + "x" +
                                  std::to_string(model.size.height) + " camera, the scene's sensor " +
                                  std::to_string(sensor.width) + "x" + std::to_string(sensor.height));
    }
    config.lens = std::make_shared<const std::vector<float>>(undistorted_pixel_centres(model, sensor));
  }
  return config;
}

Scene SimulatorOptions::scene() const {
  Scene s = vary_camera_motion(make_scene(scene_), motion_seed_);
  if (duration_s_) s.duration_us = static_cast<Timestamp>(std::llround(*duration_s_ * 1e6));
  return with_occluder(std::move(s), Timestamp{occlude_ms_} * 1000);
}

}  // namespace evldt
