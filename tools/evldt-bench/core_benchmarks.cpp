// Micro-benchmarks of the core on simulated scenes: SCARF storage (and the batch layout behind it),
// one detection pass and one tracking pass over a busy lattice. Run: build/release/tools/evldt-bench/evldt-bench-core

#include <benchmark/benchmark.h>

#include <map>
#include <string>

#include "evldt/lines/deterministic_pipeline.hpp"
#include "evldt/sim/event_simulator.hpp"
#include "evldt/sim/scenes.hpp"

namespace {

using namespace evldt;

// Events of the first `duration_us` of a scene, simulated once per process.
const EventBatch& scene_events(const std::string& name, Timestamp duration_us) {
  static std::map<std::string, EventBatch> cache;
  auto [it, inserted] = cache.try_emplace(name);
  if (inserted) {
    Scene scene = make_scene(name);
    scene.duration_us = duration_us;
    EventSimulator simulator(scene, SimulatorConfig{});
    while (simulator.run_until(simulator.now_us() + 10000, it->second)) {
    }
  }
  return it->second;
}

constexpr Timestamp kBusyWindowUs = 300000;

void StorageSoA(benchmark::State& state) {
  const EventBatch& events = scene_events("three-lines-fast", kBusyWindowUs);
  ScarfLattice lattice({640, 480}, 14, 1.0);
  for (auto _ : state) {
    lattice.insert(events);
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(events.size()));
}
BENCHMARK(StorageSoA)->Unit(benchmark::kMillisecond);

// The alternative batch layout: an array of 16-byte Event structs.
void StorageAoS(benchmark::State& state) {
  const EventBatch& batch = scene_events("three-lines-fast", kBusyWindowUs);
  std::vector<Event> events(batch.size());
  for (std::size_t i = 0; i < batch.size(); ++i) events[i] = batch[i];
  ScarfLattice lattice({640, 480}, 14, 1.0);
  for (auto _ : state) {
    for (const Event& e : events) lattice.insert(e.x, e.y);
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(events.size()));
}
BENCHMARK(StorageAoS)->Unit(benchmark::kMillisecond);

// Pipeline state half-way through a busy scene, for the pass benchmarks.
struct BusyState {
  explicit BusyState(const std::string& name) : pipeline(default_config_for(make_scene(name).sensor)) {
    pipeline.process(scene_events(name, kBusyWindowUs));
  }
  DeterministicPipeline pipeline;
};

void DetectionPass(benchmark::State& state, const std::string& scene) {
  BusyState busy(scene);
  const ScarfLattice& lattice = busy.pipeline.lattice();
  const PipelineConfig& config = busy.pipeline.config();
  LineDetector detector(lattice.geometry(), config.score);
  LineMap lines(lattice.geometry());
  int created = 0;
  for (auto _ : state) {
    lines.clear();  // every block free: the most work a pass can have
    created = detector.detect(lattice, lines, 0);
  }
  state.counters["lines_created"] = created;
  state.counters["passes_per_s"] = benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK_CAPTURE(DetectionPass, three_lines_fast_640x480, std::string("three-lines-fast"))->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(DetectionPass, circle_board_640x480, std::string("circle-board"))->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(DetectionPass, boxes_6dof_240x180, std::string("boxes-6dof"))->Unit(benchmark::kMicrosecond);

void TrackingPass(benchmark::State& state, const std::string& scene) {
  BusyState busy(scene);
  const ScarfLattice& lattice = busy.pipeline.lattice();
  const PipelineConfig& config = busy.pipeline.config();
  LineTracker tracker(lattice.geometry(), config.score, config.track);
  const LineMap start = busy.pipeline.lines();
  LineMap lines = start;
  for (auto _ : state) {
    lines = start;  // copying the line map costs well under 1% of a pass
    tracker.track(lattice, lines, 0);
  }
  state.counters["lines_tracked"] = static_cast<double>(start.lines().size());
  state.counters["passes_per_s"] = benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK_CAPTURE(TrackingPass, three_lines_fast_640x480, std::string("three-lines-fast"))->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(TrackingPass, circle_board_640x480, std::string("circle-board"))->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(TrackingPass, boxes_6dof_240x180, std::string("boxes-6dof"))->Unit(benchmark::kMicrosecond);

// The cost of the real-time engine's consistent view: one full lattice copy.
void LatticeSnapshot(benchmark::State& state) {
  BusyState busy("three-lines-fast");
  ScarfLattice view({640, 480}, 14, 1.0);
  for (auto _ : state) {
    view.copy_state_from(busy.pipeline.lattice());
    benchmark::ClobberMemory();
  }
}
BENCHMARK(LatticeSnapshot)->Unit(benchmark::kMicrosecond);

void WholePipeline(benchmark::State& state, const std::string& scene) {
  const EventBatch& events = scene_events(scene, kBusyWindowUs);
  const PipelineConfig config = default_config_for(make_scene(scene).sensor);
  for (auto _ : state) {
    DeterministicPipeline pipeline(config);
    pipeline.process(events);
    benchmark::DoNotOptimize(pipeline.lines().lines().size());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(events.size()));
}
BENCHMARK_CAPTURE(WholePipeline, three_lines_fast_640x480, std::string("three-lines-fast"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(WholePipeline, boxes_6dof_240x180, std::string("boxes-6dof"))->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
