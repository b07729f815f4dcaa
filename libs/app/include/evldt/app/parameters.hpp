#pragma once
// The line pipeline's parameters, each declared once here: its flag (also its TOML key), the field
// of PipelineConfig it sets, its type and range, its unit and one line of help. The command line
// and the TOML reader (PipelineOptions) and docs/configuration.md (evldt-config --markdown) all come
// from this table, and the defaults per sensor size from default_config_for: adding a parameter is
// one entry.

#include <span>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "evldt/pipeline/pipeline_config.hpp"

namespace evldt {

struct Parameter {
  enum class Type { Integer, Real, Text };
  /// A field of PipelineConfig that takes text (a list or a choice): read and written as text.
  struct TextField {
    std::string (*get)(const PipelineConfig&);
    void (*set)(PipelineConfig&, const std::string&);  ///< throws std::invalid_argument on a bad value
  };
  /// Where the value goes; std::monostate for the few that are not part of PipelineConfig (the
  /// sensor size, the time slack), which PipelineOptions reads by flag.
  using Field = std::variant<std::monostate, int& (*)(PipelineConfig&), Timestamp& (*)(PipelineConfig&),
                             float& (*)(PipelineConfig&), double& (*)(PipelineConfig&), TextField>;

  std::string_view flag{};   ///< without "--"
  std::string_view group{};  ///< the --help group and the page's section
  Type type = Type::Real;
  double min = 0, max = 0;                  ///< numbers: the range, both ends included
  bool above_min = false;                   ///< numbers: min itself excluded
  std::vector<std::string_view> choices{};  ///< text: the values allowed (empty: checked when set)
  std::string_view unit{};                  ///< "px", "b" (block sides), "us", "degrees", "Hz", or empty
  std::string_view help{};
  Field field{};
  /// The default where it is not PipelineConfig's for the sensor size (a machine's, the header's).
  std::string_view default_text{};

  /// The value in `config`, as the command line takes it ("" for a parameter outside it).
  [[nodiscard]] std::string value_in(const PipelineConfig& config) const;
  /// Sets the value from its command-line text (already checked against type and range).
  void set(PipelineConfig& config, const std::string& text) const;
  /// The range or choices as the page shows them.
  [[nodiscard]] std::string range_text() const;
};

/// Every parameter, in the order of --help and the page.
std::span<const Parameter> pipeline_parameters();

/// docs/configuration.md: the parameters by group, with their defaults for each sensor size of config/.
std::string configuration_page();

}  // namespace evldt
