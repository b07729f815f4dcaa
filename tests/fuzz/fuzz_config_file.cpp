// Fuzz target for --config files (TOML read by CLI11 into the pipeline options every tool shares).
// Checks: a file is either refused with CLI11's parse error or gives options whose resolved
// configuration is usable (std::invalid_argument for values that only clash at resolution).

#include <cmath>
#include <cstdint>
#include <stdexcept>

#include "evldt/app/pipeline_options.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const evldt::fuzz::TempFile file({data, size}, ".toml");
  evldt::PipelineOptions options;
  CLI::App app;
  options.add_to(app);
  const std::string path = file.path().string();
  const char* argv[] = {"evldt-fuzz", "--config", path.c_str()};
  try {
    app.parse(3, argv);
  } catch (const CLI::ParseError&) {
    return 0;  // refused, with the key or value named
  }
  try {
    const evldt::PipelineConfig config = options.resolve(options.sensor().value_or(evldt::SensorSize{640, 480}));
    evldt::fuzz::require(config.lattice.sensor.valid() && std::isfinite(config.lattice.alpha) &&
                             std::isfinite(config.score.fit_threshold),
                         "an accepted config resolved to unusable values");
  } catch (const std::invalid_argument&) {
    // e.g. only one of width and height, or a block size the sensor cannot hold: a clear error.
  }
  return 0;
}
