#include "evldt/app/pipeline_options.hpp"

#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>
#include <algorithm>
#include <charconv>
#include <cmath>
#include <stdexcept>

#include "evldt/app/parameters.hpp"
#include "evldt/calibration/camera_model.hpp"
#include "evldt/pipeline/worker_pool.hpp"

namespace evldt {

const CLI::Validator& finite_number() {
  static const CLI::Validator validator(
      [](std::string& text) -> std::string {
        double value = 0;
        if (!CLI::detail::lexical_cast(text, value) || !std::isfinite(value))
          return "'" + text + "' is not a finite number";
        return {};
      },
      "FINITE");
  return validator;
}

namespace {

/// Checks a parameter's command-line text against its type and range, as CLI11's validators do.
CLI::Validator checked(const Parameter& parameter) {
  if (parameter.type == Parameter::Type::Text) {
    if (parameter.choices.empty()) return CLI::Validator([](const std::string&) { return std::string{}; }, "");
    return CLI::IsMember(std::vector<std::string>(parameter.choices.begin(), parameter.choices.end()));
  }
  const Parameter* p = &parameter;  // the table outlives every validator
  return CLI::Validator(
      [p](const std::string& text) -> std::string {
        double value = 0;
        if (p->type == Parameter::Type::Integer) {
          std::int64_t integer = 0;
          const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), integer);
          if (error != std::errc{} || end != text.data() + text.size()) return "'" + text + "' is not an integer";
          value = static_cast<double>(integer);
        } else if (!CLI::detail::lexical_cast(text, value) || !std::isfinite(value)) {
          return "'" + text + "' is not a finite number";
        }
        if (value < p->min || value > p->max || (p->above_min && value == p->min)) {
          return "Value " + text + " not in range " + p->range_text();
        }
        return {};
      },
      "in " + p->range_text());
}

}  // namespace

void PipelineOptions::add_to(CLI::App& app) {
  app.allow_config_extras(CLI::config_extras_mode::error);
  app.set_config("--config", "", "TOML file of options (keys are the long flag names, e.g. block-size = 14)");
  const std::span<const Parameter> parameters = pipeline_parameters();
  values_.assign(parameters.size(), std::nullopt);
  std::vector<std::pair<std::string_view, CLI::Option_group*>> groups;
  for (std::size_t i = 0; i < parameters.size(); ++i) {
    const Parameter& parameter = parameters[i];
    auto group = std::find_if(groups.begin(), groups.end(), [&](const auto& g) { return g.first == parameter.group; });
    if (group == groups.end()) {
      const std::string name(parameter.group);
      groups.emplace_back(
          parameter.group,
          app.add_option_group(
              name, name == "Pipeline"
                        ? "Line detection and tracking; unset values follow the sensor size (docs/configuration.md)"
                        : "Run before storage, in the order given"));
      group = std::prev(groups.end());
    }
    std::string help(parameter.help);
    if (!parameter.unit.empty()) help += " [" + std::string(parameter.unit) + "]";
    if (!parameter.default_text.empty()) help += " (default: " + std::string(parameter.default_text) + ")";
    const char* type = parameter.type == Parameter::Type::Integer ? "INT"
                       : parameter.type == Parameter::Type::Real  ? "FLOAT"
                                                                  : "TEXT";
    group->second->add_option("--" + std::string(parameter.flag), values_[i], help)
        ->type_name(type)
        ->check(checked(parameter));
  }
}

const std::optional<std::string>& PipelineOptions::given(std::string_view flag) const {
  const std::span<const Parameter> parameters = pipeline_parameters();
  for (std::size_t i = 0; i < parameters.size(); ++i) {
    if (parameters[i].flag == flag) return values_.at(i);
  }
  throw std::logic_error("no pipeline parameter --" + std::string(flag));
}

Timestamp PipelineOptions::time_slack_us() const {
  const auto& text = values_.empty() ? std::optional<std::string>{} : given("time-slack-us");
  return text ? std::stoll(*text) : 1000;
}

std::optional<SensorSize> PipelineOptions::sensor() const {
  if (values_.empty()) return std::nullopt;  // add_to was not called
  const auto& width = given("width");
  const auto& height = given("height");
  if (width.has_value() != height.has_value())
    throw std::invalid_argument("give both --width and --height, or neither");
  if (!width) return std::nullopt;
  return SensorSize{std::stoi(*width), std::stoi(*height)};
}

PipelineConfig PipelineOptions::resolve(SensorSize sensor) const {
  PipelineConfig config = default_config_for(sensor);
  config.threads = default_worker_threads();
  const std::span<const Parameter> parameters = pipeline_parameters();
  for (std::size_t i = 0; i < values_.size(); ++i) {
    if (values_[i]) parameters[i].set(config, *values_[i]);
  }
  check_filter_config(config.filters);
  if (config.calibration != "none") {
    try {
      config.rectification = rectification_table(read_camera_model(config.calibration), sensor);
    } catch (const std::runtime_error& error) {  // a file that cannot be read is a bad value too
      throw std::invalid_argument(std::string("--calibration ") + error.what());
    }
  }
  return config;
}

int run_main(CLI::App& app, int argc, char** argv, const std::function<int()>& body) {
  std::string level = "info";
  app.add_option("--log-level", level, "Log level: trace, debug, info, warn, error, off")
      ->capture_default_str()
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error", "off"}));
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& error) {
    return app.exit(error) == 0 ? 0 : 1;  // --help is 0; every usage error is 1
  }
  // Logs and progress go to stderr, so stdout carries only a tool's results and summary.
  if (!spdlog::get("evldt")) spdlog::set_default_logger(spdlog::stderr_color_mt("evldt"));
  spdlog::set_level(spdlog::level::from_str(level));
  try {
    return body();
  } catch (const std::exception& error) {
    spdlog::error("{}", error.what());
    return 1;
  }
}

}  // namespace evldt
