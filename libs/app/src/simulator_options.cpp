#include "evldt/app/simulator_options.hpp"

#include <cmath>

#include "evldt/app/pipeline_options.hpp"
#include "evldt/sim/scenes.hpp"

namespace evldt {

void SimulatorOptions::add_to(CLI::App& app, bool scene_required) {
  std::string names;
  for (const auto& n : scene_names()) names += (names.empty() ? "" : ", ") + n;
  auto* scene = app.add_option("--scene", scene_, "Built-in simulated scene: " + names)->check(CLI::IsMember(scene_names()));
  if (scene_required) scene->default_val(std::string(kDefaultScene))->capture_default_str();
  auto* group = app.add_option_group("Simulator", "Event-camera model of the built-in scenes");
  group->add_option("--duration-s", duration_s_, "Scene duration in seconds (default: the scene's own)")
      ->check(finite_number() & CLI::Range(0.001, 3600.0));
  group->add_option("--seed", config_.seed, "Random seed (thresholds, noise)")->capture_default_str();
  group->add_option("--contrast", config_.contrast_on, "Contrast threshold C+ (log intensity)")
      ->capture_default_str()
      ->check(finite_number() & CLI::Range(0.01, 5.0))
      ->each([this](const std::string&) { config_.contrast_off = config_.contrast_on; });
  group->add_option("--contrast-sigma", config_.contrast_sigma, "Per-pixel threshold spread (std dev)")
      ->capture_default_str()
      ->check(finite_number() & CLI::Range(0.0, 1.0));
  group->add_option("--refractory-us", config_.refractory_us, "Pixel refractory period")
      ->capture_default_str()
      ->check(CLI::Range(Timestamp{0}, Timestamp{1'000'000}));
  group->add_option("--noise-rate-hz", config_.noise_rate_hz, "Background noise events per pixel per second")
      ->capture_default_str()
      ->check(finite_number() & CLI::Range(0.0, 1000.0));
  group->add_option("--hot-pixels", config_.hot_pixels, "Number of hot pixels")->capture_default_str()->check(CLI::Range(0, 100000));
}

Scene SimulatorOptions::scene() const {
  Scene s = make_scene(scene_);
  if (duration_s_) s.duration_us = static_cast<Timestamp>(std::llround(*duration_s_ * 1e6));
  return s;
}

}  // namespace evldt
