// The fused FilterChain (one pass per batch over one table) against the filters as they were
// (reference_filters.hpp: each filter its own arrays, a batch at a time): the same kept events,
// event for event, the same drops per filter and the same pixels masked, on the noisy simulated
// scenes and the real recordings of ../shared/real, in several orders and uneven batch sizes.

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "evldt/events/event_validator.hpp"
#include "evldt/filters/filter_chain.hpp"
#include "evldt/sim/event_simulator.hpp"
#include "evldt/sim/scenes.hpp"
#include "evldt/sources/event_source.hpp"
#include "reference_filters.hpp"

namespace evldt {
namespace {

struct Stream {
  std::string name;
  SensorSize sensor;
  EventBatch events;  // valid: on the sensor and in time order, within the validator's slack
};

/// A scene through its camera model (noise, hot pixels, flicker), the whole of it.
Stream simulate(const std::string& name) {
  const Scene scene = make_scene(name);
  EventSimulator simulator(scene, scene_camera_model(name));
  Stream stream{name, scene.sensor, {}};
  while (simulator.run_until(simulator.now_us() + 10'000, stream.events)) {
  }
  return stream;
}

constexpr Timestamp kSlackUs = 1000;  // the pipelines' default time slack: events up to 1 ms back pass

/// A recording as a pipeline sees it: what the validator keeps.
Stream read_recording(const std::filesystem::path& path) {
  const auto source = open_recording(path, std::nullopt, "", kSlackUs);
  EventBatch raw, batch;
  while (source->read(batch)) raw.append(batch, 0, batch.size());
  SensorSize sensor{1, 1};
  if (const auto geometry = source->geometry()) {
    sensor = *geometry;
  } else {
    for (std::size_t i = 0; i < raw.size(); ++i)
      sensor = {std::max<int>(sensor.width, raw.x[i] + 1), std::max<int>(sensor.height, raw.y[i] + 1)};
  }
  EventValidator validator(sensor, kSlackUs);
  validator.filter(raw);
  return {path.filename().string(), sensor, std::move(raw)};
}

const std::vector<Stream>& scenes() {
  static const std::vector<Stream> streams = [] {
    std::vector<Stream> all;
    for (const char* name : {"noisy-boxes", "flicker-lamps", "night-boxes", "boxes-6dof"})
      all.push_back(simulate(name));
    return all;
  }();
  return streams;
}

std::filesystem::path real_recordings() { return std::filesystem::path(EVLDT_SHARED_DIR) / "real"; }

/// Batch sizes that vary widely and never line up with the judging periods.
std::vector<std::size_t> uneven_sizes(std::size_t seed) {
  std::vector<std::size_t> sizes;
  std::size_t s = seed;
  for (int i = 0; i < 64; ++i) {
    s = s * 6364136223846793005u + 1442695040888963407u;
    const std::size_t kind = (s >> 60) % 4;
    sizes.push_back(kind == 0   ? 1 + (s >> 40) % 7
                    : kind == 1 ? 1 + (s >> 40) % 300
                    : kind == 2 ? 1 + (s >> 40) % 5000
                                : 1 + (s >> 40) % 70'000);
  }
  return sizes;
}

/// Runs `chain` over `events` in batches of the given sizes (cycled), in place or into a second
/// batch, and returns the events it kept.
template <typename Chain>
EventBatch run(Chain& chain, const EventBatch& events, const std::vector<std::size_t>& sizes, bool in_place) {
  EventBatch kept, batch, out;
  std::size_t at = 0;
  for (std::size_t k = 0; at < events.size(); ++k) {
    const std::size_t end = std::min(events.size(), at + sizes[k % sizes.size()]);
    batch.clear();
    batch.append(events, at, end);
    EventBatch& result = in_place ? batch : out;
    chain.filter(batch, result);
    kept.append(result, 0, result.size());
    at = end;
  }
  return kept;
}

struct Setting {
  const char* label;
  const char* chain;
  double min_noise_hz;  ///< background-activity drops uncorrelated events from this noise level on
  Timestamp refractory_us;
};

// The default chain and two other orders of the four filters; with background-activity always
// dropping and a long refractory period too, so that every filter drops on every stream.
constexpr Setting kSettings[] = {
    {"default", "refractory,hot-pixel,anti-flicker,background-activity", 1.0, 300},
    {"all four", "refractory,background-activity,hot-pixel,anti-flicker", 1.0, 100},
    {"all four, eager", "anti-flicker,refractory,hot-pixel,background-activity", 0.0, 2000},
};

/// Checks the fused chain against the reference on `stream` in every setting.
void expect_same_as_reference(const Stream& stream) {
  for (const Setting& setting : kSettings) {
    SCOPED_TRACE(stream.name + ", " + setting.label + " (" + setting.chain + ")");
    FilterConfig config;
    config.chain = parse_filter_chain(setting.chain);
    config.background_min_noise_hz = setting.min_noise_hz;
    config.refractory_us = setting.refractory_us;
    reference::FilterChain reference(config, stream.sensor);
    FilterChain fused(config, stream.sensor);
    const EventBatch expected = run(reference, stream.events, uneven_sizes(1), false);
    const EventBatch kept = run(fused, stream.events, uneven_sizes(2), true);

    const FilterCounts want = reference.counts(), got = fused.counts();
    std::printf(
        "  %-32s %-58s %9zu in %9zu kept  hot-pixel %7llu  anti-flicker %7llu  background %7llu  refractory %7llu\n",
        stream.name.c_str(), setting.chain, stream.events.size(), kept.size(),
        static_cast<unsigned long long>(got.hot_pixel), static_cast<unsigned long long>(got.anti_flicker),
        static_cast<unsigned long long>(got.background_activity), static_cast<unsigned long long>(got.refractory));
    EXPECT_EQ(got.events_in, want.events_in);
    EXPECT_EQ(got.passed, want.passed);
    EXPECT_EQ(got.hot_pixel, want.hot_pixel);
    EXPECT_EQ(got.anti_flicker, want.anti_flicker);
    EXPECT_EQ(got.background_activity, want.background_activity);
    EXPECT_EQ(got.refractory, want.refractory);
    // The same pixels masked; the order of those masked at one judging may differ (the chain scans
    // its plane of counts, the reference went down the pixels in the order they came).
    std::vector<std::uint32_t> masked(fused.masked_pixels().begin(), fused.masked_pixels().end());
    std::vector<std::uint32_t> masked_before(reference.masked_pixels().begin(), reference.masked_pixels().end());
    std::ranges::sort(masked);
    std::ranges::sort(masked_before);
    EXPECT_EQ(masked, masked_before);
    ASSERT_EQ(kept.size(), expected.size());
    for (std::size_t i = 0; i < kept.size(); ++i) {
      if (kept[i] != expected[i]) {
        ADD_FAILURE() << "kept event " << i << " differs: t " << kept.t[i] << " (" << kept.x[i] << ", " << kept.y[i]
                      << ") " << int{kept.p[i]} << ", the reference t " << expected.t[i] << " (" << expected.x[i]
                      << ", " << expected.y[i] << ") " << int{expected.p[i]};
        break;
      }
    }
  }
}

TEST(FusedChain, KeepsWhatTheFiltersOneByOneKeptOnTheNoisyScenes) {
  for (const Stream& stream : scenes()) expect_same_as_reference(stream);
}

TEST(FusedChain, KeepsWhatTheFiltersOneByOneKeptOnRealRecordings) {
  const std::filesystem::path real = real_recordings();
  if (!std::filesystem::is_directory(real))
    GTEST_SKIP() << "no real recordings at " << real << " (../shared is absent)";
  std::vector<std::filesystem::path> files;
  for (const auto& entry : std::filesystem::directory_iterator(real)) {
    if (entry.is_regular_file() && entry.path().extension() != ".md") files.push_back(entry.path());
  }
  std::ranges::sort(files);
  ASSERT_FALSE(files.empty());
  for (const auto& path : files) expect_same_as_reference(read_recording(path));
}

}  // namespace
}  // namespace evldt
