#pragma once
// Command-line options selecting a built-in simulated scene and its event-camera model, shared by
// evldt-sim, evldt-offline and evldt-camera.

#include <CLI/CLI.hpp>
#include <optional>
#include <string>

#include "evldt/sim/event_simulator.hpp"

namespace evldt {

class SimulatorOptions {
 public:
  /// scene_required: the scene flag must be given (otherwise it selects the simulator as source).
  void add_to(CLI::App& app, bool scene_required);
  [[nodiscard]] bool scene_selected() const { return !scene_.empty(); }
  [[nodiscard]] const std::string& scene_name() const { return scene_; }
  /// The scene with the duration, motion-seed and occluder overrides applied; throws
  /// std::invalid_argument on an unknown name.
  [[nodiscard]] Scene scene() const;
  /// The scene's camera model (the default one without a scene), with the flags given applied.
  [[nodiscard]] SimulatorConfig config() const;

 private:
  std::string scene_;
  std::optional<double> duration_s_;
  std::uint64_t seed_ = 1;
  std::uint64_t motion_seed_ = 0;
  int occlude_ms_ = 0;
  std::optional<double> contrast_, contrast_sigma_, noise_rate_hz_, dark_noise_hz_, readout_rate_eps_;
  std::optional<Timestamp> refractory_us_, jitter_us_;
  std::optional<int> hot_pixels_;
  std::optional<std::string> lens_;
};

}  // namespace evldt
