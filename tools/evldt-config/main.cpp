// evldt-config: the line pipeline's parameters. Prints the configuration a sensor size (and any
// flags or --config file given) resolves to, as a TOML file every tool takes back with --config;
// or, with --markdown, the page of every parameter (docs/configuration.md).
#include <CLI/CLI.hpp>
#include <cstdio>
#include <string>

#include "evldt/app/parameters.hpp"
#include "evldt/app/pipeline_options.hpp"

namespace {

/// A TOML value: numbers as they are, text quoted.
std::string toml_value(const evldt::Parameter& parameter, const std::string& value) {
  return parameter.type == evldt::Parameter::Type::Text ? "\"" + value + "\"" : value;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace evldt;
  CLI::App app{
      "evldt-config: the configuration of the line pipeline for a sensor size (--width and --height, or\n"
      "--config FILE) and any parameters given, printed as TOML that --config takes back; or, with\n"
      "--markdown, the page of every parameter with its range, unit and defaults (docs/configuration.md)."};
  PipelineOptions options;
  options.add_to(app);
  bool markdown = false;
  app.add_flag("--markdown", markdown, "Print docs/configuration.md instead");
  return run_main(app, argc, argv, [&] {
    if (markdown) {
      std::fputs(configuration_page().c_str(), stdout);
      return 0;
    }
    const auto sensor = options.sensor();
    if (!sensor) {
      std::fprintf(stderr, "give the sensor size: --width and --height, or --config config/<size>.toml\n");
      return 1;
    }
    const PipelineConfig config = options.resolve(*sensor);
    // config/<size>.toml are this output at the defaults (a test compares every size).
    std::printf(
        "# evldt's pipeline for a %dx%d sensor, written by evldt-config (docs/configuration.md).\n"
        "# Keys are the long command-line flags; a flag given on the command line overrides the file.\n",
        sensor->width, sensor->height);
    for (const Parameter& parameter : pipeline_parameters()) {
      std::string value = parameter.value_in(config);
      if (parameter.flag == "width") value = std::to_string(sensor->width);
      if (parameter.flag == "height") value = std::to_string(sensor->height);
      if (parameter.flag == "time-slack-us") value = std::to_string(options.time_slack_us());
      const std::string flag(parameter.flag);
      if (parameter.flag == "threads" && !options.given(flag)) {
        // This machine's default would pin another machine's: left unset.
        std::printf("# %s: unset, %s\n", flag.c_str(), std::string(parameter.default_text).c_str());
        continue;
      }
      std::printf("%s = %s\n", flag.c_str(), toml_value(parameter, value).c_str());
    }
    return 0;
  });
}
