#include <gtest/gtest.h>

#include <charconv>
#include <filesystem>
#include <fstream>

#include "evldt/app/parameters.hpp"
#include "evldt/app/pipeline_options.hpp"

namespace evldt {
namespace {

// Parses argv the way a tool does; returns CLI11's exit code (0 when accepted).
int parse(std::vector<std::string> args, PipelineOptions& options) {
  CLI::App app;
  options.add_to(app);
  args.insert(args.begin(), "tool");
  std::vector<const char*> argv;
  for (const auto& a : args) argv.push_back(a.c_str());
  try {
    app.parse(static_cast<int>(argv.size()), argv.data());
  } catch (const CLI::ParseError& e) {
    return e.get_exit_code();
  }
  return 0;
}

const std::filesystem::path kConfigDir = EVLDT_SOURCE_DIR "/config";

TEST(PipelineOptions, EachShippedConfigGivesTheDesignDefaults) {
  struct Expect {
    const char* file;
    SensorSize sensor;
    int block_size;
    float perturbation;
  };
  for (const Expect& e :
       {Expect{"240x180.toml", {240, 180}, 8, 0.8f}, Expect{"346x260.toml", {346, 260}, 8, 1.1f},
        Expect{"640x480.toml", {640, 480}, 14, 2.5f}, Expect{"1280x720.toml", {1280, 720}, 14, 2.5f}}) {
    PipelineOptions options;
    ASSERT_EQ(parse({"--config", (kConfigDir / e.file).string()}, options), 0) << e.file;
    ASSERT_TRUE(options.sensor()) << e.file;
    EXPECT_EQ(*options.sensor(), e.sensor);
    const PipelineConfig config = options.resolve(*options.sensor());
    EXPECT_EQ(config.lattice.block_size, e.block_size) << e.file;
    EXPECT_FLOAT_EQ(config.track.perturbation_px, e.perturbation) << e.file;
    EXPECT_FLOAT_EQ(config.score.fit_threshold, 0.2f);
    EXPECT_FLOAT_EQ(config.score.retry_share, 0.15f);
    EXPECT_EQ(config.schedule.track_period_us, 2000);
    EXPECT_EQ(config.schedule.detect_period_us, 4000);
    // Without the file, the same sensor gives the same values.
    const PipelineConfig defaults = PipelineOptions{}.resolve(e.sensor);
    EXPECT_EQ(defaults.lattice.block_size, config.lattice.block_size);
    EXPECT_FLOAT_EQ(defaults.track.perturbation_px, config.track.perturbation_px);
  }
}

TEST(PipelineOptions, CommandLineOverridesTheFile) {
  PipelineOptions options;
  ASSERT_EQ(
      parse({"--config", (kConfigDir / "640x480.toml").string(), "--block-size", "10", "--multi-block-norm", "union"},
            options),
      0);
  const PipelineConfig config = options.resolve(*options.sensor());
  EXPECT_EQ(config.lattice.block_size, 10);
  EXPECT_EQ(config.track.multi_block_norm, EffectiveRatioNorm::Union);
}

TEST(PipelineOptions, BadValuesAndUnknownKeysAreRefused) {
  const auto dir = std::filesystem::temp_directory_path() / ("evldt_options_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "unknown.toml") << "block-size = 8\nblock_sise = 3\n";
  std::ofstream(dir / "typed.toml") << "block-size = \"eight\"\n";
  std::ofstream(dir / "zero.toml") << "width = 0\nheight = 480\n";
  PipelineOptions a, b, c, d, e, f, g, h, i;
  EXPECT_NE(parse({"--config", (dir / "unknown.toml").string()}, a), 0);
  EXPECT_NE(parse({"--config", (dir / "typed.toml").string()}, b), 0);
  EXPECT_NE(parse({"--config", (dir / "missing.toml").string()}, c), 0);
  EXPECT_NE(parse({"--fit-threshold", "nan"}, d), 0);
  EXPECT_NE(parse({"--block-size", "-4"}, e), 0);
  EXPECT_NE(parse({"--multi-block-norm", "sum"}, f), 0);
  EXPECT_NE(parse({"--alpha", "inf"}, g), 0);
  EXPECT_NE(parse({"--width", "5000", "--height", "480"}, h), 0);  // beyond kMaxSensorSide
  EXPECT_NE(parse({"--config", (dir / "zero.toml").string()}, i), 0);
  PipelineOptions half;
  ASSERT_EQ(parse({"--width", "640"}, half), 0);
  EXPECT_THROW(static_cast<void>(half.sensor()), std::invalid_argument);
  std::filesystem::remove_all(dir);
}

TEST(Parameters, TheConfigurationPageIsTheTablesOwn) {
  std::ifstream file(EVLDT_SOURCE_DIR "/docs/configuration.md");
  ASSERT_TRUE(file) << "docs/configuration.md is missing";
  const std::string page((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  EXPECT_EQ(page, configuration_page())
      << "docs/configuration.md differs from the parameter table: write it again with\n"
         "  evldt-config --markdown > docs/configuration.md";
}

TEST(Parameters, EachSetsItsOwnFieldAndNoOther) {
  const SensorSize sensor{640, 480};
  const PipelineConfig defaults = PipelineOptions{}.resolve(sensor);
  const std::span<const Parameter> parameters = pipeline_parameters();
  for (const Parameter& parameter : parameters) {
    if (std::holds_alternative<std::monostate>(parameter.field)) continue;
    // A value other than the default, within the range: the lowest, else the highest (some bound
    // others: the flicker band's lowest stays below its highest).
    const std::string old_value = parameter.value_in(defaults);
    std::vector<std::string> candidates;
    if (parameter.flag == "calibration") {  // a file: a pinhole camera of the sensor's size
      const auto file = std::filesystem::temp_directory_path() / ("evldt_calib_" + std::to_string(::getpid()) + ".txt");
      std::ofstream(file) << "500 500 320 240\n";
      candidates.push_back(file.string());
    } else if (parameter.type == Parameter::Type::Text) {
      candidates.push_back(parameter.choices.empty() ? "none" : std::string(parameter.choices.back()));
      if (!parameter.choices.empty()) candidates.push_back(std::string(parameter.choices.front()));
    } else {
      const auto text = [](double number) {
        char out[32];
        return std::string(out, std::to_chars(out, out + sizeof out, number).ptr);
      };
      if (!parameter.above_min) candidates.push_back(text(parameter.min));
      candidates.push_back(text(parameter.max));
    }
    std::string value;
    PipelineConfig config;
    for (const std::string& candidate : candidates) {
      if (candidate == old_value) continue;
      PipelineOptions options;
      ASSERT_EQ(parse({"--" + std::string(parameter.flag), candidate}, options), 0)
          << parameter.flag << " " << candidate;
      try {
        config = options.resolve(sensor);
      } catch (const std::invalid_argument&) {
        continue;
      }
      value = candidate;
      break;
    }
    ASSERT_FALSE(value.empty()) << parameter.flag << ": no value other than the default resolves";
    for (const Parameter& other : parameters) {
      if (&other == &parameter) {
        EXPECT_EQ(other.value_in(config), value) << other.flag;
      } else {
        EXPECT_EQ(other.value_in(config), other.value_in(defaults))
            << "--" << parameter.flag << " changed " << other.flag;
      }
    }
  }
}

TEST(Parameters, TheShippedConfigsStateTheDefaultsOfTheirSize) {
  for (const char* file : {"240x180.toml", "346x260.toml", "640x480.toml", "1280x720.toml"}) {
    PipelineOptions options;
    ASSERT_EQ(parse({"--config", (kConfigDir / file).string()}, options), 0) << file;
    const SensorSize sensor = options.sensor().value();
    const PipelineConfig from_file = options.resolve(sensor);
    const PipelineConfig defaults = PipelineOptions{}.resolve(sensor);
    for (const Parameter& parameter : pipeline_parameters()) {
      EXPECT_EQ(parameter.value_in(from_file), parameter.value_in(defaults)) << file << ": " << parameter.flag;
    }
  }
}

TEST(Parameters, NumbersOutOfRangeOrOfTheWrongTypeAreRefused) {
  for (const Parameter& parameter : pipeline_parameters()) {
    if (parameter.type == Parameter::Type::Text) continue;
    PipelineOptions above, text, fraction;
    EXPECT_NE(parse({"--" + std::string(parameter.flag), std::to_string(parameter.max * 2 + 1)}, above), 0)
        << parameter.flag;
    EXPECT_NE(parse({"--" + std::string(parameter.flag), "many"}, text), 0) << parameter.flag;
    if (parameter.type == Parameter::Type::Integer) {
      EXPECT_NE(parse({"--" + std::string(parameter.flag), "2.5"}, fraction), 0) << parameter.flag;
    }
  }
}

}  // namespace
}  // namespace evldt
