// evldt-bench: speed and memory of the core, and of receiving events off the wire, at every supported
// sensor size, on one core (--threads N: the detection and tracking passes and the pipeline's rounds
// on a pool of N). For each size a built-in scene is simulated (the first --window-ms), and each
// figure is the median of --repeats timed repeats, each repeat long enough (--min-time-ms) for the
// clock not to matter. A second table sets the per-event path (receive, filters, storage) against
// what memory allows: plain writes with the same access pattern and none of the work, the filters'
// (of the default chain's tables) prefetched as the chain prefetches; and storage with each message
// first sorted by home block.
// Every size runs in a child process of its own, so its peak RSS is its own.

#include <sys/mman.h>
#include <sys/wait.h>
#include <unistd.h>
#include <CLI/CLI.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "evldt/app/pipeline_options.hpp"
#include "evldt/calibration/camera_model.hpp"
#include "evldt/events/event_writer.hpp"
#include "evldt/pipeline/deterministic_pipeline.hpp"
#include "evldt/pipeline/event_intake.hpp"
#include "evldt/pipeline/whole_line_stage.hpp"
#include "evldt/sim/event_simulator.hpp"
#include "evldt/sim/scenes.hpp"
#include "evldt/sources/event_source.hpp"
#include "evldt/transport/event_batch_receiver.hpp"
#include "evldt/transport/messages.hpp"

namespace {

using namespace evldt;
using Clock = std::chrono::steady_clock;

struct SizeCase {
  const char* label;
  const char* scene;
};
// One scene per supported sensor size; 640x480 is the dense scene of the performance targets.
constexpr SizeCase kCases[] = {
    {"240x180", "boxes-6dof"},
    {"346x260", "multi-speed"},
    {"640x480", "three-lines-fast"},
    {"1280x720", "monitor-hd"},
};

/// A timed figure: seconds per operation over the repeats.
struct Timing {
  double median = 0, min = 0, max = 0;
};

/// What one size measures; plain data, sent from the child process through a pipe.
struct Figures {
  double events = 0;            ///< simulated events in the window
  double scene_rate_mev_s = 0;  ///< their rate in the scene
  Timing storage;               ///< per event
  Timing storage_aos;           ///< per event, from an array of Event structs
  Timing storage_by_block;      ///< per event, each message sorted by home block, then stored
  Timing storage_bound;         ///< per event, a plain ring write into each of its blocks
  Timing receive;               ///< per event: an LCM event batch decoded, checked and validated
  Timing detect;                ///< per pass, every block free
  double active_points = 0;     ///< active entries in the lattice the passes see
  double lines_created = 0;
  Timing track;  ///< per pass
  double lines_tracked = 0;
  Timing whole;                ///< per whole-line step, over the window's output steps from an empty state
  double whole_lines = 0;      ///< published at the window's last step
  Timing snapshot;             ///< per full lattice copy (the real-time loops' consistent view)
  Timing snapshot_1ms;         ///< per update of a view after 1 ms of the scene's events
  Timing filters;              ///< per event, the default noise filters from an empty state
  Timing filters_setup;        ///< per chain: building the filters' empty state (a service does it once, at start)
  Timing filters_bound;        ///< per event, a plain touch of the lines the default chain's tests touch
  Timing rectify;              ///< per event, moving it into the rectified image of a calibrated camera
  Timing pipeline;             ///< per event, the whole deterministic pipeline from an empty state
  Timing pipeline_unfiltered;  ///< the same without the noise filters
  double lattice_mb = 0;       ///< one lattice's storage
  double events_mb = 0;        ///< the simulated events (part of the RSS, not of evldt's state)
  double peak_rss_mb = 0;
};

struct BenchSettings {
  int repeats = 5;
  int threads = 1;  ///< of the detection and tracking passes and the pipeline's rounds
  double min_time_s = 0.1;
  Timestamp window_us = 300000;
  std::optional<std::vector<std::string>> filters;  ///< a chain to time instead of the default one
};

/// The median, least and most of a repeat's seconds.
Timing median_timing(std::vector<double> seconds) {
  std::sort(seconds.begin(), seconds.end());
  return {seconds[seconds.size() / 2], seconds.front(), seconds.back()};
}

/// Runs `op` enough times per repeat to last min_time_s, `repeats` times; seconds per call of `op`.
Timing time_op(const BenchSettings& settings, const std::function<void()>& op) {
  op();  // warm caches and first-touch pages
  std::size_t calls = 1;
  for (;;) {
    const auto start = Clock::now();
    for (std::size_t i = 0; i < calls; ++i) op();
    const double elapsed = std::chrono::duration<double>(Clock::now() - start).count();
    if (elapsed >= settings.min_time_s || calls >= (std::size_t{1} << 30)) break;
    calls = elapsed > 0
                ? std::max(calls * 2,
                           static_cast<std::size_t>(static_cast<double>(calls) * settings.min_time_s / elapsed * 1.2))
                : calls * 16;
  }
  std::vector<double> per_call;
  for (int r = 0; r < settings.repeats; ++r) {
    const auto start = Clock::now();
    for (std::size_t i = 0; i < calls; ++i) op();
    per_call.push_back(std::chrono::duration<double>(Clock::now() - start).count() / static_cast<double>(calls));
  }
  return median_timing(std::move(per_call));
}

Timing per_item(Timing t, double items) { return {t.median / items, t.min / items, t.max / items}; }

double peak_rss_mb() {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind("VmHWM:", 0) == 0) return std::stod(line.substr(6)) / 1024.0;  // kB
  }
  return 0;
}

EventBatch simulate(const Scene& scene, Timestamp window_us) {
  Scene windowed = scene;
  windowed.duration_us = std::min(scene.duration_us, window_us);
  EventSimulator simulator(windowed, SimulatorConfig{});
  EventBatch events;
  while (simulator.run_until(simulator.now_us() + 10000, events)) {
  }
  return events;
}

/// The camera's messages hold up to this many events (one datagram each).
constexpr std::size_t kEventsPerMessage = 7000;

/// The events cut into the batches a service receives, one message each.
std::vector<EventBatch> as_messages(const EventBatch& events) {
  std::vector<EventBatch> batches;
  for (std::size_t begin = 0; begin < events.size(); begin += kEventsPerMessage) {
    batches.emplace_back().append(events, begin, std::min(events.size(), begin + kEventsPerMessage));
  }
  return batches;
}

/// Seconds to receive the events as the camera publishes them: what evldt-lines' receive thread
/// does before storage.
Timing time_receive(const BenchSettings& settings, SensorSize sensor, const EventBatch& events) {
  event_batch_t header;
  header.epoch = 1;
  header.source = "bench";
  header.width = static_cast<std::int16_t>(sensor.width);
  header.height = static_cast<std::int16_t>(sensor.height);
  std::vector<std::vector<std::uint8_t>> messages;
  for (const EventBatch& chunk : as_messages(events)) {
    header.seq = static_cast<std::int64_t>(messages.size());
    encode_event_batch(header, chunk, messages.emplace_back());
  }
  EventBatch received;
  return time_op(settings, [&] {
    // A new one each time (the sequence starts again), with the services' default 1 ms time slack.
    EventBatchReceiver receiver(sensor, 1000);
    for (const auto& message : messages) {
      if (!receiver.receive(message, received)) throw std::runtime_error("the receiver refused a benchmark message");
    }
  });
}

/// Where an axis's pixel is stored: the block whose active region holds it and the one on the side
/// of the half it lies in (as ScarfLattice places it); -1 where there is none.
std::pair<int, int> blocks_along(int pixel, int block_size, int blocks) {
  const int half = block_size / 2;
  const int shifted = pixel - half;
  const int home = shifted >= 0 ? shifted / block_size : -1;
  const int side = shifted - home * block_size < half ? home - 1 : home + 1;
  return {home < blocks ? home : -1, side >= 0 && side < blocks ? side : -1};
}

/// The memory bound of storage: each event written at the head of every ring that holds it, with
/// the lattice's access pattern and none of its bookkeeping (the rings of those blocks are listed
/// before timing; an event's missing blocks write into one spare ring).
Timing time_ring_writes(const EventBatch& events, const LatticeGeometry& geometry, const BenchSettings& settings) {
  const auto spare = static_cast<std::uint32_t>(geometry.block_count());
  std::vector<std::uint32_t> blocks;
  blocks.reserve(4 * events.size());
  for (std::size_t i = 0; i < events.size(); ++i) {
    const auto [home_x, side_x] = blocks_along(events.x[i], geometry.block_size, geometry.blocks_x);
    const auto [home_y, side_y] = blocks_along(events.y[i], geometry.block_size, geometry.blocks_y);
    for (const int row : {home_y, side_y}) {
      for (const int column : {home_x, side_x}) {
        blocks.push_back(row >= 0 && column >= 0 ? static_cast<std::uint32_t>(geometry.index(column, row)) : spare);
      }
    }
  }
  const auto capacity = static_cast<std::size_t>(geometry.capacity);
  std::vector<LatticeEntry> rings((spare + 1) * capacity);
  std::vector<std::uint16_t> heads(spare + 1);
  return time_op(settings, [&] {
    for (std::size_t k = 0; k < blocks.size(); ++k) {
      const std::uint32_t block = blocks[k];
      std::uint16_t& head = heads[block];
      rings[block * capacity + head] = LatticeEntry{static_cast<std::uint16_t>(k)};
      head = static_cast<std::uint16_t>(head + 1u == capacity ? 0u : head + 1u);
    }
  });
}

/// Storage by place: each message's events listed by home block (a stable counting sort, so each
/// block's in time order), then stored in that order. Holds its buffers, so a timed store allocates
/// nothing.
class BlockOrderedStore {
 public:
  explicit BlockOrderedStore(const LatticeGeometry& geometry)
      : geometry_(geometry),
        starts_(static_cast<std::size_t>(geometry.block_count()) + 2),
        block_of_(kEventsPerMessage),
        xs_(kEventsPerMessage),
        ys_(kEventsPerMessage) {}

  void store(const EventBatch& events, ScarfLattice& lattice) {
    for (std::size_t begin = 0; begin < events.size(); begin += kEventsPerMessage) {
      const std::size_t count = std::min(kEventsPerMessage, events.size() - begin);
      std::fill(starts_.begin(), starts_.end(), 0u);
      for (std::size_t i = 0; i < count; ++i) {
        // Events in no block's active region (the margins) go last.
        const int block = geometry_.block_at(static_cast<float>(events.x[begin + i]) + 0.5f,
                                             static_cast<float>(events.y[begin + i]) + 0.5f);
        block_of_[i] =
            block >= 0 ? static_cast<std::uint32_t>(block) : static_cast<std::uint32_t>(geometry_.block_count());
        ++starts_[block_of_[i] + 1];
      }
      for (std::size_t b = 1; b < starts_.size(); ++b) starts_[b] += starts_[b - 1];
      for (std::size_t i = 0; i < count; ++i) {
        const std::uint32_t at = starts_[block_of_[i]]++;
        xs_[at] = events.x[begin + i];
        ys_[at] = events.y[begin + i];
      }
      lattice.insert(std::span(xs_).first(count), std::span(ys_).first(count));
    }
  }

 private:
  LatticeGeometry geometry_;
  std::vector<std::uint32_t> starts_, block_of_;
  std::vector<std::uint16_t> xs_, ys_;
};

/// The memory bound of the default filters: per event, one plain read or write of each cell their
/// tests read (its pixel's 32-byte record, its count, and the 3 x 3 cells of the background
/// surface), in tables of their sizes, with none of their logic.
Timing time_filter_touches(const std::vector<EventBatch>& messages, SensorSize sensor, const BenchSettings& settings) {
  const auto width = static_cast<std::size_t>(sensor.width), height = static_cast<std::size_t>(sensor.height);
  const std::size_t stride = width + 2;
  // In huge pages where the kernel gives them on request, as the chain's table is: asked for before
  // the first write faults the pages in.
  const auto huge_zeroed = []<typename T>(std::size_t count, T) {
    std::unique_ptr<T[]> table(new T[count]);  // left untouched: no page is faulted in yet
    auto* const bytes = reinterpret_cast<std::byte*>(table.get());
    const std::size_t lead = (4096 - reinterpret_cast<std::uintptr_t>(bytes) % 4096) % 4096;
    if (count * sizeof(T) > lead) madvise(bytes + lead, count * sizeof(T) - lead, MADV_HUGEPAGE);
    std::fill_n(table.get(), count, T{});
    return table;
  };
  const auto records = huge_zeroed(width * height, PixelState{});
  const auto counts = huge_zeroed(width * height, std::uint32_t{});
  const auto surface = huge_zeroed(stride * (height + 2), std::uint32_t{});
  volatile std::uint32_t kept_reads = 0;  // so the reads are made
  const Timing timing = time_op(settings, [&] {
    std::uint32_t seen = 0;
    for (const EventBatch& message : messages) {
      for (std::size_t i = 0; i < message.size(); ++i) {
        if (i + 16 < message.size()) {  // as the chain prefetches
          const std::size_t ax = message.x[i + 16], ay = message.y[i + 16];
          __builtin_prefetch(&records[ay * width + ax], 1);
          __builtin_prefetch(&counts[ay * width + ax], 1);
          for (std::size_t row = 0; row < 3; ++row) {
            __builtin_prefetch(&surface[(ay + row) * stride + ax], 1);
            __builtin_prefetch(&surface[(ay + row) * stride + ax + 2], 1);
          }
        }
        const std::size_t x = message.x[i], y = message.y[i], pixel = y * width + x;
        const auto t = static_cast<std::uint32_t>(message.t[i]);
        records[pixel].refractory = t;
        ++counts[pixel];
        const std::uint32_t* const above = surface.get() + y * stride + x;
        seen += above[0] + above[1] + above[2] + above[2 * stride] + above[2 * stride + 1] + above[2 * stride + 2] +
                above[stride] + above[stride + 2];
        surface[(y + 1) * stride + x + 1] = t;
      }
    }
    kept_reads = seen;
  });
  return timing;
}

/// Storing events in the lattice, from the batch's columns and from an array of structs.
void measure_storage(const EventBatch& events, const PipelineConfig& config, const BenchSettings& settings,
                     Figures& f) {
  const SensorSize sensor = config.lattice.sensor;
  const double n = f.events;
  ScarfLattice lattice(sensor, config.lattice.block_size, config.lattice.alpha);
  f.lattice_mb = static_cast<double>(lattice.memory_bytes()) / 1e6;
  f.storage = per_item(time_op(settings, [&] { lattice.insert(events); }), n);
  std::vector<Event> structs(events.size());
  for (std::size_t i = 0; i < events.size(); ++i) structs[i] = events[i];
  f.storage_aos = per_item(time_op(settings,
                                   [&] {
                                     for (const Event& e : structs) lattice.insert(e.x, e.y);
                                   }),
                           n);
  BlockOrderedStore by_block(lattice.geometry());
  f.storage_by_block = per_item(time_op(settings, [&] { by_block.store(events, lattice); }), n);
  f.storage_bound = per_item(time_ring_writes(events, lattice.geometry(), settings), n);
}

/// A detection pass with every block free, on the lattice at the window's end.
void measure_detection(const ScarfLattice& state, const PipelineConfig& config, WorkerPool& pool,
                       const BenchSettings& settings, Figures& f) {
  LineMap detected(state.geometry());
  f.detect = time_op(settings, [&] {
    // A fresh detector with every block free: the most work a pass can have (a detector skips the
    // blocks that failed before and have not changed since).
    LineDetector detector(state.geometry(), config.score, &pool);
    detected.clear();
    f.lines_created = detector.detect(state, detected, 0);
  });
}

/// A tracking pass over the lines at the window's end, every line scored.
void measure_tracking(const DeterministicPipeline& busy, WorkerPool& pool, const BenchSettings& settings, Figures& f) {
  const ScarfLattice& state = busy.lattice();
  const PipelineConfig& config = busy.config();
  LineTracker tracker(state.geometry(), config.score, config.track, &pool);
  LineMap start = busy.lines();
  // Every line scored: the most work a pass can have (a pass reuses the score of a line settled on
  // blocks that have not changed since).
  for (std::size_t i = 0; i < start.lines().size(); ++i) start.settled_version(i) = 0;
  f.lines_tracked = static_cast<double>(start.lines().size());
  LineMap tracked = start;
  const Timing copy = time_op(settings, [&] { tracked = start; });
  const Timing track_and_copy = time_op(settings, [&] {
    tracked = start;
    tracker.track(state, tracked, 0);
  });
  f.track = {track_and_copy.median - copy.median, track_and_copy.min - copy.median, track_and_copy.max - copy.median};
}

/// The whole-line steps over the window's output steps, from an empty state.
void measure_whole_lines(const std::vector<std::pair<Timestamp, std::vector<TrackedLine>>>& output_steps,
                         const ScarfLattice& state, const PipelineConfig& config, const BenchSettings& settings,
                         Figures& f) {
  BenchSettings replays = settings;
  replays.min_time_s = 0;  // a replay of every step is long enough
  f.whole = per_item(time_op(replays,
                             [&] {
                               WholeLineStage whole(config);
                               // Against the lattice at the window's end, as the service checks its gaps,
                               // corners and remembered ends against its latest copy.
                               for (const auto& [t, lines] : output_steps) whole.step(t, lines, &state);
                               f.whole_lines = static_cast<double>(whole.lines().size());
                             }),
                     static_cast<double>(std::max<std::size_t>(output_steps.size(), 1)));
}

/// The lattice copies of the real-time loops.
void measure_snapshots(const EventBatch& events, const ScarfLattice& state, const PipelineConfig& config,
                       const BenchSettings& settings, Figures& f) {
  const SensorSize sensor = config.lattice.sensor;
  const double n = f.events;
  // The snapshot of a real-time loop: in full (a new source), and after 1 ms of events (only the
  // blocks they changed).
  ScarfLattice view(sensor, config.lattice.block_size, config.lattice.alpha);
  ScarfLattice live(sensor, config.lattice.block_size, config.lattice.alpha);
  live.insert(events);
  f.snapshot = time_op(settings, [&] {
    view.copy_state_from(state);
    view.copy_state_from(live);
  });
  f.snapshot = {f.snapshot.median / 2, f.snapshot.min / 2, f.snapshot.max / 2};
  // Updates are timed one by one (the storage between them is not): each repeat stores the next
  // 1 ms chunks of the window and times the view update after each.
  const std::size_t per_ms =
      std::max<std::size_t>(1, static_cast<std::size_t>(n * 1000.0 / static_cast<double>(settings.window_us)));
  view.copy_state_from(live);
  std::vector<double> update_seconds;
  for (int r = 0; r < settings.repeats; ++r) {
    double total = 0;
    std::size_t updates = 0;
    for (std::size_t begin = 0; begin < events.size() && (updates < 50 || total < settings.min_time_s);
         begin += per_ms) {
      const std::size_t count = std::min(per_ms, events.size() - begin);
      live.insert(std::span(events.x).subspan(begin, count), std::span(events.y).subspan(begin, count));
      const auto update_start = Clock::now();
      view.copy_state_from(live);
      total += std::chrono::duration<double>(Clock::now() - update_start).count();
      ++updates;
    }
    update_seconds.push_back(total / static_cast<double>(updates));
  }
  f.snapshot_1ms = median_timing(std::move(update_seconds));
}

/// What a batch goes through before storage: the noise filters, and rectification.
void measure_intake(const std::vector<EventBatch>& messages, const PipelineConfig& config,
                    const BenchSettings& settings, Figures& f) {
  const SensorSize sensor = config.lattice.sensor;
  const double n = f.events;
  // A service builds its chain (and its zeroed per-pixel table) once, at start: that is timed apart
  // from the filtering, each repeat on a chain built just before it.
  std::vector<double> setup_seconds, filter_seconds;
  for (int r = 0; r <= settings.repeats; ++r) {  // the first warms the caches and is not counted
    const auto setup_start = Clock::now();
    EventIntake filters_only(config);
    const auto filter_start = Clock::now();
    for (const EventBatch& message : messages) filters_only.prepare(message);
    const auto filter_end = Clock::now();
    if (r == 0) continue;
    setup_seconds.push_back(std::chrono::duration<double>(filter_start - setup_start).count());
    filter_seconds.push_back(std::chrono::duration<double>(filter_end - filter_start).count());
  }
  f.filters_setup = median_timing(setup_seconds);
  f.filters = per_item(median_timing(filter_seconds), n);
  f.filters_bound = per_item(time_filter_touches(messages, sensor, settings), n);
  // Rectification of a calibrated camera: a barrel lens as strong as the DAVIS240C's, scaled to
  // the sensor (the table is made once, at start; each event costs a lookup).
  CameraModel lens;
  lens.fx = lens.fy = 0.83 * sensor.width;
  lens.cx = 0.5 * sensor.width - 0.5;
  lens.cy = 0.5 * sensor.height - 0.5;
  lens.distortion = CameraModel::Distortion::RadialTangential;
  lens.coefficients = {-0.35, 0.15, 0.0, 0.0, 0.0};
  PipelineConfig rectify_only = config;
  rectify_only.filters.chain.clear();
  rectify_only.rectification = rectification_table(lens, sensor);
  f.rectify = per_item(time_op(settings,
                               [&] {
                                 EventIntake intake(rectify_only);
                                 for (const EventBatch& message : messages) intake.prepare(message);
                               }),
                       n);
}

/// The whole deterministic pipeline, with and without the noise filters, from an empty state.
void measure_pipeline(const std::vector<EventBatch>& messages, const PipelineConfig& config,
                      const BenchSettings& settings, Figures& f) {
  BenchSettings once = settings;
  once.min_time_s = 0;  // a pass over the whole window is long enough
  const double n = f.events;
  const auto run_pipeline = [&](const PipelineConfig& pipeline_config) {
    DeterministicPipeline pipeline(pipeline_config);
    for (const EventBatch& message : messages) pipeline.process(message);
  };
  f.pipeline = per_item(time_op(once, [&] { run_pipeline(config); }), n);
  PipelineConfig unfiltered = config;
  unfiltered.filters.chain.clear();
  f.pipeline_unfiltered = per_item(time_op(once, [&] { run_pipeline(unfiltered); }), n);
}

Figures measure(const SizeCase& size_case, const BenchSettings& settings) {
  const Scene scene = make_scene(size_case.scene);
  const EventBatch events = simulate(scene, settings.window_us);
  PipelineConfig config = default_config_for(scene.sensor);
  if (settings.filters) config.filters.chain = *settings.filters;
  config.threads = settings.threads;
  WorkerPool pool(settings.threads);
  const auto n = static_cast<double>(events.size());
  Figures f;
  f.events = n;
  f.scene_rate_mev_s = events.empty() ? 0 : n / static_cast<double>(events.t.back() - events.t.front() + 1);
  f.events_mb = n * (sizeof(Timestamp) + 2 * sizeof(std::uint16_t) + sizeof(std::int8_t)) / 1e6;

  measure_storage(events, config, settings, f);
  f.receive = per_item(time_receive(settings, scene.sensor, events), n);

  // The passes run on the state at the end of the window; the whole-line steps on its output steps.
  DeterministicPipeline busy(config);
  std::vector<std::pair<Timestamp, std::vector<TrackedLine>>> output_steps;
  busy.set_output(10000, [&](const OutputStep& step) {
    output_steps.emplace_back(step.t,
                              std::vector<TrackedLine>(step.segments.lines().begin(), step.segments.lines().end()));
  });
  busy.process(events);
  const ScarfLattice& state = busy.lattice();
  for (int block = 0; block < state.geometry().block_count(); ++block) f.active_points += state.active_count(block);
  measure_detection(state, config, pool, settings, f);
  measure_tracking(busy, pool, settings, f);
  measure_whole_lines(output_steps, state, config, settings, f);
  measure_snapshots(events, state, config, settings, f);

  // Filters and pipelines take the events in the batches a service receives: one batch of the
  // whole window would time the streaming of a filtered copy as large (with its page faults in a
  // new pipeline), which no service makes.
  const std::vector<EventBatch> messages = as_messages(events);
  measure_intake(messages, config, settings, f);
  measure_pipeline(messages, config, settings, f);
  f.peak_rss_mb = peak_rss_mb();
  return f;
}

/// Runs measure() in a child process so each size's peak RSS is its own.
std::optional<Figures> measure_in_child(const SizeCase& size_case, const BenchSettings& settings) {
  std::fflush(nullptr);
  int fds[2];
  if (pipe(fds) != 0) throw std::runtime_error("pipe failed");
  const pid_t pid = fork();
  if (pid < 0) throw std::runtime_error("fork failed");
  if (pid == 0) {
    close(fds[0]);
    int status = 0;
    try {
      const Figures f = measure(size_case, settings);
      status = write(fds[1], &f, sizeof f) == static_cast<ssize_t>(sizeof f) ? 0 : 1;
    } catch (const std::exception& error) {
      std::fprintf(stderr, "evldt-bench: %s: %s\n", size_case.label, error.what());
      status = 1;
    }
    _exit(status);
  }
  close(fds[1]);
  Figures f;
  const ssize_t got = read(fds[0], &f, sizeof f);
  close(fds[0]);
  int status = 0;
  waitpid(pid, &status, 0);
  if (got != static_cast<ssize_t>(sizeof f) || !WIFEXITED(status) || WEXITSTATUS(status) != 0) return std::nullopt;
  return f;
}

void print_header() {
  std::printf("%-9s %-17s %7s %9s %9s %9s %10s %11s %10s %12s %9s %8s %8s %8s %8s %8s %10s %9s %9s %8s\n", "size",
              "scene", "Mev/s*", "storage", "(AoS)", "receive", "detect", "ns/point", "track", "ns/line", "whole",
              "(lines)", "copy", "1ms-upd", "filters", "rectify", "pipeline", "(no filt)", "lattice", "RSS");
  std::printf("%-9s %-17s %7s %9s %9s %9s %10s %11s %10s %12s %9s %8s %8s %8s %8s %8s %10s %9s %9s %8s\n", "", "",
              "scene", "Mev/s", "Mev/s", "Mev/s", "Hz", "(points)", "Hz", "(lines)", "Hz", "", "us", "us", "Mev/s",
              "Mev/s", "Mev/s", "Mev/s", "MB", "MB");
}

void print_row(const SizeCase& c, const Figures& f) {
  char points[32], lines[32];
  std::snprintf(points, sizeof points, "%.1f (%.0f)", f.detect.median * 1e9 / std::max(f.active_points, 1.0),
                f.active_points);
  std::snprintf(lines, sizeof lines, "%.0f (%.0f)", f.track.median * 1e9 / std::max(f.lines_tracked, 1.0),
                f.lines_tracked);
  std::printf(
      "%-9s %-17s %7.2f %9.1f %9.1f %9.1f %10.0f %11s %10.0f %12s %9.0f %8.0f %8.1f %8.1f %8.1f %8.1f %10.2f %9.2f "
      "%9.2f %8.0f\n",
      c.label, c.scene, f.scene_rate_mev_s, 1e-6 / f.storage.median, 1e-6 / f.storage_aos.median,
      1e-6 / f.receive.median, 1.0 / f.detect.median, points, 1.0 / f.track.median, lines, 1.0 / f.whole.median,
      f.whole_lines, f.snapshot.median * 1e6, f.snapshot_1ms.median * 1e6, 1e-6 / f.filters.median,
      1e-6 / f.rectify.median, 1e-6 / f.pipeline.median, 1e-6 / f.pipeline_unfiltered.median, f.lattice_mb,
      f.peak_rss_mb);
  std::fflush(stdout);
}

/// The per-event path before any round, against what memory allows (the plain writes with its
/// access pattern).
void print_event_path(const std::vector<std::pair<SizeCase, Figures>>& results) {
  std::printf("\nper-event path, ns an event (medians); bound: plain writes with the same access pattern\n");
  std::printf("%-9s %8s %8s %8s %7s %8s %9s %8s %7s %8s\n", "size", "receive", "filters", "(bound)", "ratio", "storage",
              "by block", "(bound)", "ratio", "path");
  for (const auto& [c, f] : results) {
    const double receive = f.receive.median * 1e9, filters = f.filters.median * 1e9, storage = f.storage.median * 1e9;
    std::printf("%-9s %8.1f %8.1f %8.1f %7.2f %8.1f %9.1f %8.1f %7.2f %8.1f\n", c.label, receive, filters,
                f.filters_bound.median * 1e9, f.filters.median / f.filters_bound.median, storage,
                f.storage_by_block.median * 1e9, f.storage_bound.median * 1e9,
                f.storage.median / f.storage_bound.median, receive + filters + storage);
  }
}

void write_timing(std::ofstream& out, const char* name, Timing t, const char* unit, double scale) {
  out << "      \"" << name << "\": {\"unit\": \"" << unit << "\", \"median\": " << t.median * scale
      << ", \"min\": " << t.min * scale << ", \"max\": " << t.max * scale << "},\n";
}

void write_json(const std::filesystem::path& path, const BenchSettings& settings,
                const std::vector<std::pair<SizeCase, Figures>>& results) {
  std::ofstream out(path);
  if (!out) throw std::runtime_error("cannot write " + path.string());
  out << "{\n  \"repeats\": " << settings.repeats << ",\n  \"threads\": " << settings.threads
      << ",\n  \"min_time_s\": " << settings.min_time_s << ",\n  \"window_us\": " << settings.window_us
      << ",\n  \"sizes\": [\n";
  for (std::size_t i = 0; i < results.size(); ++i) {
    const auto& [c, f] = results[i];
    out << "    {\n      \"size\": \"" << c.label << "\",\n      \"scene\": \"" << c.scene << "\",\n"
        << "      \"events\": " << f.events << ",\n      \"scene_rate_mev_s\": " << f.scene_rate_mev_s << ",\n";
    write_timing(out, "storage_ns_per_event", f.storage, "ns", 1e9);
    write_timing(out, "storage_aos_ns_per_event", f.storage_aos, "ns", 1e9);
    write_timing(out, "storage_by_block_ns_per_event", f.storage_by_block, "ns", 1e9);
    write_timing(out, "storage_bound_ns_per_event", f.storage_bound, "ns", 1e9);
    write_timing(out, "receive_ns_per_event", f.receive, "ns", 1e9);
    write_timing(out, "detect_pass_us", f.detect, "us", 1e6);
    write_timing(out, "track_pass_us", f.track, "us", 1e6);
    write_timing(out, "whole_line_step_us", f.whole, "us", 1e6);
    write_timing(out, "snapshot_us", f.snapshot, "us", 1e6);
    write_timing(out, "snapshot_after_1ms_us", f.snapshot_1ms, "us", 1e6);
    write_timing(out, "filters_ns_per_event", f.filters, "ns", 1e9);
    write_timing(out, "filters_setup_ms", f.filters_setup, "ms", 1e3);
    write_timing(out, "filters_bound_ns_per_event", f.filters_bound, "ns", 1e9);
    write_timing(out, "rectify_ns_per_event", f.rectify, "ns", 1e9);
    write_timing(out, "pipeline_ns_per_event", f.pipeline, "ns", 1e9);
    write_timing(out, "pipeline_unfiltered_ns_per_event", f.pipeline_unfiltered, "ns", 1e9);
    out << "      \"storage_mev_s\": " << 1e-6 / f.storage.median << ",\n"
        << "      \"receive_mev_s\": " << 1e-6 / f.receive.median << ",\n"
        << "      \"detect_hz\": " << 1.0 / f.detect.median << ",\n"
        << "      \"detect_ns_per_active_point\": " << f.detect.median * 1e9 / std::max(f.active_points, 1.0) << ",\n"
        << "      \"active_points\": " << f.active_points << ",\n      \"lines_created\": " << f.lines_created << ",\n"
        << "      \"track_hz\": " << 1.0 / f.track.median << ",\n"
        << "      \"track_ns_per_line\": " << f.track.median * 1e9 / std::max(f.lines_tracked, 1.0) << ",\n"
        << "      \"lines_tracked\": " << f.lines_tracked << ",\n"
        << "      \"whole_line_hz\": " << 1.0 / f.whole.median << ",\n"
        << "      \"whole_lines\": " << f.whole_lines << ",\n"
        << "      \"filters_mev_s\": " << 1e-6 / f.filters.median << ",\n"
        << "      \"rectify_mev_s\": " << 1e-6 / f.rectify.median << ",\n"
        << "      \"pipeline_mev_s\": " << 1e-6 / f.pipeline.median << ",\n"
        << "      \"pipeline_unfiltered_mev_s\": " << 1e-6 / f.pipeline_unfiltered.median << ",\n"
        << "      \"lattice_mb\": " << f.lattice_mb << ",\n      \"events_mb\": " << f.events_mb << ",\n"
        << "      \"peak_rss_mb\": " << f.peak_rss_mb << "\n    }" << (i + 1 < results.size() ? "," : "") << "\n";
  }
  out << "  ]\n}\n";
}

/// Decoding speed of a recording: read whole through the reader evldt-offline uses (container,
/// decoder, no pipeline), the median of the repeats, on one core.
void print_decode_speed(const std::filesystem::path& path, int repeats) {
  std::vector<double> seconds;
  std::uint64_t events = 0;
  std::string name;
  for (int r = 0; r < repeats; ++r) {
    const auto started = Clock::now();
    const auto source = open_recording(path, std::nullopt, "", std::numeric_limits<Timestamp>::max() / 4);
    EventBatch batch;
    events = 0;
    while (source->read(batch)) events += batch.size();
    seconds.push_back(std::chrono::duration<double>(Clock::now() - started).count());
    name = source->name();
  }
  const double median = median_timing(std::move(seconds)).median;
  std::printf("%-40s %10llu events %8.1f Mev/s  %s\n", path.filename().string().c_str(),
              static_cast<unsigned long long>(events), static_cast<double>(events) * 1e-6 / median, name.c_str());
}

/// The same events in every file format evldt writes: three-lines-fast, 0.3 s (2.3 M events).
std::vector<std::filesystem::path> write_format_samples(const std::filesystem::path& dir) {
  std::filesystem::create_directories(dir);
  Scene scene = make_scene("three-lines-fast");
  scene.duration_us = 300'000;
  EventSimulator simulator(scene, SimulatorConfig{});
  EventBatch events;
  simulator.run_until(scene.duration_us, events);
  std::vector<std::filesystem::path> paths;
  for (const auto& [format, name] :
       {std::pair{EventFormat::Evt3, "sample.raw"}, std::pair{EventFormat::Evt2, "sample_evt2.raw"},
        std::pair{EventFormat::Evt21, "sample_evt21.raw"}, std::pair{EventFormat::Dat, "sample.dat"},
        std::pair{EventFormat::EcdText, "sample.txt"}}) {
    EventWriter writer(dir / name, format, scene.sensor);
    writer.write(events);
    writer.close();
    paths.push_back(dir / name);
  }
  return paths;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "evldt-bench: speed and memory of SCARF storage, a detection pass, a tracking pass, the lattice\n"
      "snapshot and the whole deterministic pipeline at every sensor size, on one core (--threads: the\n"
      "passes and rounds on more). Prints a table (medians over the repeats) and writes the figures as\n"
      "JSON."};
  BenchSettings settings;
  std::vector<std::string> sizes;
  std::filesystem::path json_path;
  double window_ms = 300;
  app.add_option("--sizes", sizes, "Sensor sizes to measure (default: all)")
      ->check(CLI::IsMember({"240x180", "346x260", "640x480", "1280x720"}));
  app.add_option("--repeats", settings.repeats, "Timed repeats per figure (the median is reported)")
      ->capture_default_str()
      ->check(CLI::Range(1, 101));
  double min_time_ms = 100;
  app.add_option("--min-time-ms", min_time_ms, "Shortest repeat; a figure's calls are batched to last this long")
      ->capture_default_str()
      ->check(CLI::Range(1.0, 10000.0) & finite_number());
  app.add_option("--window-ms", window_ms, "Scene time simulated per size; passes run on the state at its end")
      ->capture_default_str()
      ->check(CLI::Range(10.0, 10000.0) & finite_number());
  app.add_option("--threads", settings.threads,
                 "Threads of the detection and tracking passes and of the pipeline's rounds (storage, receiving and\n"
                 "filters stay on one)")
      ->capture_default_str()
      ->check(CLI::Range(1, 64));
  app.add_option("--json", json_path, "Write the figures as JSON");
  std::string filters;
  app.add_option("--filters", filters,
                 "Noise filters of the filter and pipeline figures, in order, or none (default: the\n"
                 "configuration's; names: hot-pixel, background-activity, refractory, anti-flicker)");
  std::vector<std::filesystem::path> decode_files;
  app.add_option("--decode", decode_files,
                 "Instead: decoding speed of these recordings (any format evldt reads; none given: the same scene\n"
                 "written in every format evldt writes, in a temporary folder)")
      ->expected(0, -1);
  return run_main(app, argc, argv, [&] {
    if (app.count("--decode") > 0) {
      std::printf("evldt-bench --decode: one core, medians of %d reads of each whole file\n", settings.repeats);
      const auto samples_dir = std::filesystem::temp_directory_path() / ("evldt-bench-" + std::to_string(::getpid()));
      std::erase(decode_files, std::filesystem::path());  // "--decode" alone
      if (decode_files.empty()) decode_files = write_format_samples(samples_dir);
      for (const auto& path : decode_files) print_decode_speed(path, settings.repeats);
      std::filesystem::remove_all(samples_dir);
      return 0;
    }
    settings.window_us = static_cast<Timestamp>(window_ms * 1e3);
    settings.min_time_s = min_time_ms * 1e-3;
    if (app.count("--filters") > 0) settings.filters = parse_filter_chain(filters);
    std::printf(
        "evldt-bench: %d thread(s) for the passes and rounds, medians of %d repeats; *scene = event rate of the\n"
        "simulated scene; filters: %s\n",
        settings.threads, settings.repeats,
        settings.filters ? format_filter_chain(*settings.filters).c_str() : "the configuration's");
    print_header();
    std::vector<std::pair<SizeCase, Figures>> results;
    bool failed = false;
    for (const SizeCase& c : kCases) {
      if (!sizes.empty() && std::find(sizes.begin(), sizes.end(), c.label) == sizes.end()) continue;
      if (const auto figures = measure_in_child(c, settings)) {
        results.emplace_back(c, *figures);
        print_row(c, *figures);
      } else {
        std::printf("%-9s %-17s failed (see the error above)\n", c.label, c.scene);
        failed = true;
      }
    }
    print_event_path(results);
    if (!json_path.empty()) {
      write_json(json_path, settings, results);
      std::printf("wrote %s\n", json_path.string().c_str());
    }
    return failed ? 1 : 0;
  });
}
