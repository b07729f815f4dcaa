#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

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
  for (const Expect& e : {Expect{"240x180.toml", {240, 180}, 8, 0.8f}, Expect{"346x260.toml", {346, 260}, 10, 1.1f},
                          Expect{"640x480.toml", {640, 480}, 14, 2.5f}, Expect{"1280x720.toml", {1280, 720}, 14, 2.5f}}) {
    PipelineOptions options;
    ASSERT_EQ(parse({"--config", (kConfigDir / e.file).string()}, options), 0) << e.file;
    ASSERT_TRUE(options.sensor()) << e.file;
    EXPECT_EQ(*options.sensor(), e.sensor);
    const PipelineConfig config = options.resolve(*options.sensor());
    EXPECT_EQ(config.lattice.block_size, e.block_size) << e.file;
    EXPECT_FLOAT_EQ(config.track.perturbation_px, e.perturbation) << e.file;
    EXPECT_FLOAT_EQ(config.score.fit_threshold, 0.2f);
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
  ASSERT_EQ(parse({"--config", (kConfigDir / "640x480.toml").string(), "--block-size", "10", "--multi-block-norm", "union"},
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

}  // namespace
}  // namespace evldt
