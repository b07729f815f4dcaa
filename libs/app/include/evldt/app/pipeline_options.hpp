#pragma once
// Command-line and TOML options of the line pipeline (the parameters of parameters.hpp), shared by
// every tool and service so a flag means the same everywhere. Values left unset fall back to the
// defaults for the sensor size.

#include <CLI/CLI.hpp>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "evldt/pipeline/pipeline_config.hpp"

namespace evldt {

class PipelineOptions {
 public:
  /// Adds --config (TOML, keys = long flag names; unknown keys are an error) and the pipeline flags.
  void add_to(CLI::App& app);

  /// Sensor size given on the command line or in the config file, if any.
  [[nodiscard]] std::optional<SensorSize> sensor() const;
  /// The full configuration for `sensor`: its defaults, then every option that was set.
  /// Throws std::invalid_argument on a value out of range or a calibration file that cannot be read.
  [[nodiscard]] PipelineConfig resolve(SensorSize sensor) const;
  /// --time-slack-us, 1000 unless given.
  [[nodiscard]] Timestamp time_slack_us() const;
  /// The text given for a parameter of pipeline_parameters(), by flag; nullopt if unset.
  [[nodiscard]] const std::optional<std::string>& given(std::string_view flag) const;

 private:
  std::vector<std::optional<std::string>> values_;  ///< one per pipeline_parameters() entry
};

/// CLI11's Range accepts NaN (every comparison with it is false): floating options also need this.
const CLI::Validator& finite_number();

/// The end of every tool's main: adds --log-level, parses the command line (a usage error is exit
/// status 1, --help 0), sends logs to stderr at that level, and runs `body`, turning an
/// escaping exception into a logged error and exit status 1.
int run_main(CLI::App& app, int argc, char** argv, const std::function<int()>& body);

}  // namespace evldt
