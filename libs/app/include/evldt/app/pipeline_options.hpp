#pragma once
// Command-line and TOML options of the line pipeline, shared by every tool and service so a flag
// means the same everywhere. Values left unset fall back to the defaults for the sensor size.

#include <CLI/CLI.hpp>
#include <functional>
#include <optional>
#include <string>

#include "evldt/lines/params.hpp"

namespace evldt {

class PipelineOptions {
 public:
  /// Adds --config (TOML, keys = long flag names; unknown keys are an error) and the pipeline flags.
  void add_to(CLI::App& app);

  /// Sensor size given on the command line or in the config file, if any.
  [[nodiscard]] std::optional<SensorSize> sensor() const;
  /// The full configuration for `sensor`: its defaults, then every option that was set.
  /// Throws std::invalid_argument on a value out of range.
  [[nodiscard]] PipelineConfig resolve(SensorSize sensor) const;
  [[nodiscard]] Timestamp time_slack_us() const { return time_slack_us_; }

 private:
  std::optional<int> width_, height_, block_size_, fit_iterations_, threads_;
  std::optional<double> alpha_;
  std::optional<float> fit_threshold_, inlier_ratio_, max_bend_, perturbation_, reassociation_angle_, reassociation_offset_;
  std::optional<float> whole_angle_, whole_offset_, whole_gap_, whole_min_length_, whole_corner_reach_, whole_corner_angle_,
      whole_event_reach_;
  std::optional<std::string> multi_block_norm_;
  std::optional<Timestamp> track_period_, detect_period_, bad_track_patience_, reassociation_window_,
      whole_keep_id_, whole_end_memory_;
  std::optional<std::string> filters_;
  std::optional<Timestamp> ba_window_, filter_refractory_, hot_window_;
  std::optional<double> ba_min_noise_hz_, hot_rate_, hot_ratio_, flicker_min_hz_, flicker_max_hz_;
  Timestamp time_slack_us_ = 1000;
};

/// CLI11's Range accepts NaN (every comparison with it is false): floating options also need this.
const CLI::Validator& finite_number();

/// The end of every tool's main: adds --log-level, parses the command line (a usage error is exit
/// status 1, --help 0), sends logs to stderr at that level, and runs `body`, turning an
/// escaping exception into a logged error and exit status 1.
int run_main(CLI::App& app, int argc, char** argv, const std::function<int()>& body);

}  // namespace evldt
