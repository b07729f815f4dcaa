#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <set>
#include <thread>

#include "evldt/pipeline/deterministic_pipeline.hpp"
#include "evldt/pipeline/realtime_engine.hpp"
#include "evldt/sim/event_simulator.hpp"
#include "evldt/sim/scenes.hpp"
#include "support/sweeping_edge.hpp"

namespace evldt {
namespace {

constexpr SensorSize kSensor{240, 180};

bool on_lattice_line(float coordinate, int block_size) {
  const float k = (coordinate - static_cast<float>(block_size / 2)) / static_cast<float>(block_size);
  return std::abs(k - std::round(k)) * static_cast<float>(block_size) < 1e-3f;
}

// A vertical edge sweeping right at 200 px/s from x = 30 to x = 90 over 0.3 s. Its ends lie on block
// borders (y = 20 and 164): an end inside a block leaves a square blob of events there, which can
// score as a short line of the wrong orientation (measured by the accuracy benchmark, not here).
EventBatch vertical_sweep() {
  return testing::sweep_events({Point2(30, 20), Point2(30, 164), Point2(200, 0), 0, 300000}, kSensor);
}

struct Observation {
  Timestamp t;
  TrackedLine line;
};

std::vector<Observation> run(const EventBatch& events, const PipelineConfig& config, Timestamp step_us) {
  DeterministicPipeline pipeline(config);
  std::vector<Observation> seen;
  pipeline.set_output(step_us, [&](const OutputStep& step) {
    for (const TrackedLine& line : step.segments.lines()) seen.push_back({step.t, line});
  });
  pipeline.process(events);
  return seen;
}

TEST(Pipeline, DetectsASweepingEdgeOnBlockBordersAndTracksItWithStableIds) {
  const PipelineConfig config = default_config_for(kSensor);
  ASSERT_EQ(config.lattice.block_size, 8);
  const auto seen = run(vertical_sweep(), config, 10000);
  ASSERT_FALSE(seen.empty());

  std::map<std::uint64_t, std::set<int>> columns_by_id;  // admin block columns each id has lived in
  const LatticeGeometry g = LatticeGeometry::make(kSensor, 8, 1.0);
  for (const Observation& o : seen) {
    const Segment& s = o.line.segment;
    // Each endpoint lies on a lattice line.
    EXPECT_TRUE(on_lattice_line(s.q0.x(), 8) || on_lattice_line(s.q0.y(), 8)) << s.q0.transpose();
    EXPECT_TRUE(on_lattice_line(s.q1.x(), 8) || on_lattice_line(s.q1.y(), 8)) << s.q1.transpose();
    // The segment follows the true edge x = 30 + 200 t, and is near vertical. The lattice holds the
    // last two pixel columns the edge crossed and a line moves at most dq = 0.8 px per 2 ms round, so
    // it trails the edge by one to three pixels.
    const float edge_x = 30.0f + 200.0f * static_cast<float>(o.t) * 1e-6f;
    const float lag = edge_x - s.centre().x();
    EXPECT_GE(lag, -0.5f) << "t=" << o.t << " id=" << o.line.id;
    EXPECT_LE(lag, 3.0f) << "t=" << o.t << " id=" << o.line.id;
    EXPECT_LT(std::abs(s.q1.x() - s.q0.x()), 0.3f * std::abs(s.q1.y() - s.q0.y()));
    // It is administered by the block under its centre's row.
    EXPECT_EQ(g.row(o.line.admin_block), g.row(g.block_at(s.centre().x(), s.centre().y())));
    columns_by_id[o.line.id].insert(g.column(o.line.admin_block));
  }
  // The 144 px edge spans 18 block rows and is seen in each, by one line per row at a time.
  std::map<Timestamp, std::multiset<int>> rows_at;
  for (const Observation& o : seen) rows_at[o.t].insert(g.row(o.line.admin_block));
  const auto& last = rows_at.rbegin()->second;
  EXPECT_GE(last.size(), 16u);
  for (const int row : last) EXPECT_EQ(last.count(row), 1u) << "two lines in block row " << row;
  // Lines keep their id while the edge crosses several block columns (60 px = 7.5 blocks).
  std::size_t long_lived = 0;
  for (const auto& [id, columns] : columns_by_id) long_lived += columns.size() >= 5 ? 1 : 0;
  EXPECT_GE(long_lived, 10u);
}

TEST(Pipeline, TwoRunsAreIdentical) {
  const PipelineConfig config = default_config_for(kSensor);
  const auto events = vertical_sweep();
  const auto a = run(events, config, 5000);
  const auto b = run(events, config, 5000);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].t, b[i].t);
    EXPECT_EQ(a[i].line.id, b[i].line.id);
    EXPECT_EQ(a[i].line.segment.q0, b[i].line.segment.q0);
    EXPECT_EQ(a[i].line.segment.q1, b[i].line.segment.q1);
    EXPECT_EQ(a[i].line.score, b[i].line.score);
  }
}

TEST(Pipeline, OneTwoAndFourThreadsGiveTheSameOutput) {
  // The busy HD scene: enough lines and blocks that every round is split over the pool.
  Scene scene = make_scene("monitor-hd");
  scene.duration_us = 60'000;
  EventSimulator simulator(scene, SimulatorConfig{});
  EventBatch events;
  simulator.run_until(scene.duration_us, events);
  PipelineConfig config = default_config_for(scene.sensor);
  std::map<int, std::vector<Observation>> by_threads;
  std::map<int, PipelineCounters> counters;
  std::map<int, std::vector<std::uint64_t>> released;
  for (const int threads : {1, 2, 4}) {
    config.threads = threads;
    DeterministicPipeline pipeline(config);
    auto& seen = by_threads[threads];
    std::size_t most_lines = 0;
    pipeline.set_output(2000, [&](const OutputStep& step) {
      most_lines = std::max(most_lines, step.segments.lines().size());
      for (const TrackedLine& line : step.segments.lines()) seen.push_back({step.t, line});
    });
    pipeline.process(events);
    ASSERT_GE(most_lines, 4 * LineTracker::kMinLinesToSplit);
    ASSERT_GE(pipeline.lattice().geometry().block_count(), LineDetector::kMinBlocksToSplit);
    counters[threads] = pipeline.counters();
    for (int reason = 0; reason < kReleaseReasonCount; ++reason) {
      released[threads].push_back(pipeline.lines().released(static_cast<ReleaseReason>(reason)));
    }
    released[threads].push_back(pipeline.lines().created());
    released[threads].push_back(pipeline.lines().reassociated());
  }
  const auto& one = by_threads[1];
  ASSERT_GT(one.size(), 10'000u);
  for (const int threads : {2, 4}) {
    const auto& other = by_threads[threads];
    ASSERT_EQ(one.size(), other.size()) << threads << " threads";
    for (std::size_t i = 0; i < one.size(); ++i) {
      ASSERT_EQ(one[i].t, other[i].t);
      ASSERT_EQ(one[i].line.id, other[i].line.id) << threads << " threads, at " << one[i].t;
      ASSERT_EQ(one[i].line.segment.q0, other[i].line.segment.q0);
      ASSERT_EQ(one[i].line.segment.q1, other[i].line.segment.q1);
      ASSERT_EQ(one[i].line.score, other[i].line.score);
      ASSERT_EQ(one[i].line.status, other[i].line.status);
      ASSERT_EQ(one[i].line.admin_block, other[i].line.admin_block);
      ASSERT_EQ(one[i].line.first_seen_us, other[i].line.first_seen_us);
      ASSERT_EQ(one[i].line.last_good_us, other[i].line.last_good_us);
    }
    EXPECT_EQ(released[1], released[threads]) << threads << " threads: releases by reason, created, reassociated";
    EXPECT_EQ(counters[1].track_rounds, counters[threads].track_rounds);
    EXPECT_EQ(counters[1].detect_rounds, counters[threads].detect_rounds);
  }
}

// The schedule tests feed single events, which the noise filters would drop as isolated.
PipelineConfig unfiltered() {
  PipelineConfig config = default_config_for(kSensor);
  config.filters.chain.clear();
  return config;
}

TEST(Pipeline, RoundsRunOnEventTimeAndLongGapsAreSkipped) {
  PipelineConfig config = unfiltered();
  config.schedule.track_period_us = 1000;
  config.schedule.detect_period_us = 2000;
  DeterministicPipeline pipeline(config);
  std::vector<Timestamp> steps;
  pipeline.set_output(1000, [&](const OutputStep& step) { steps.push_back(step.t); });
  EventBatch batch;
  batch.push_back(0, 50, 50, 1);
  batch.push_back(4500, 50, 50, 1);        // rounds at 1000..4000
  batch.push_back(3600000000, 50, 50, 1);  // an hour later: only the rounds of the last 8 periods run
  pipeline.process(batch);
  EXPECT_EQ(pipeline.counters().events, 3u);
  EXPECT_EQ(pipeline.counters().track_rounds, 4u + 9u);  // t - 8000 .. t inclusive
  EXPECT_EQ(pipeline.counters().detect_rounds, 2u + 5u);
  EXPECT_EQ(steps.size(), 4u + 9u);
  EXPECT_EQ(steps[3], 4000);
  EXPECT_EQ(steps[4], 3600000000 - 8000);
  EXPECT_GT(pipeline.counters().skipped_rounds, 3000000u);
}

TEST(Pipeline, OutputStepsFallOnMultiplesOfThePeriodWhateverTheFirstEventTime) {
  DeterministicPipeline pipeline(unfiltered());
  std::vector<Timestamp> steps;
  pipeline.set_output(1000, [&](const OutputStep& step) { steps.push_back(step.t); });
  EventBatch batch;
  batch.push_back(1234, 50, 50, 1);
  batch.push_back(4100, 50, 50, 1);
  pipeline.process(batch);
  EXPECT_EQ(steps, (std::vector<Timestamp>{2000, 3000, 4000}));  // the grid ground truth is sampled on
}

TEST(Pipeline, AfterTheClockWentBackRoundsRunOnTheNewClock) {
  PipelineConfig config = unfiltered();
  DeterministicPipeline pipeline(config);
  EventBatch before;
  before.push_back(50'000'000, 50, 50, 1);
  before.push_back(50'100'000, 50, 50, 1);
  pipeline.process(before);
  const std::uint64_t rounds_before = pipeline.counters().track_rounds;
  // The camera clock began again (the validator followed it): the sweep arrives at t = 0..0.3 s.
  pipeline.process(vertical_sweep());
  EXPECT_EQ(pipeline.counters().clock_restarts, 1u);
  EXPECT_GE(pipeline.counters().track_rounds - rounds_before, 140u);  // 0.3 s of 2 ms rounds
  EXPECT_FALSE(pipeline.lines().lines().empty());
}

// Waits until each loop's last round ran on a lattice at most a period older than `newest_us`: a
// state, not a time, so a loaded machine (a sanitizer, both cores busy) only makes the test slower.
// Every round due is then run, as the deterministic schedule would; rounds the engine skips when it
// falls behind are another test's business.
bool wait_for_rounds_within_a_period(const RealtimeEngine& engine, Timestamp newest_us) {
  const ScheduleParams& schedule = engine.config().schedule;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  for (;;) {
    const EngineCounters c = engine.counters();
    if (c.tracked_us > newest_us - schedule.track_period_us && c.detected_us > newest_us - schedule.detect_period_us) {
      return true;
    }
    if (std::chrono::steady_clock::now() > deadline) return false;
    std::this_thread::sleep_for(std::chrono::microseconds(200));
  }
}

TEST(RealtimeEngine, FindsTheSweepingEdgeOnItsOwnThreads) {
  const PipelineConfig config = default_config_for(kSensor);
  RealtimeEngine engine(config);
  engine.set_first_line_id(1000);
  engine.start();
  const EventBatch events = vertical_sweep();
  EventBatch chunk;
  // Fed in 2 ms slices, each once the rounds have caught up with the one before: the edge moves
  // 0.4 px a slice and a line at most dq = 0.8 px a round, so lines keep up with it however late
  // the loops' threads run (a test that only slept between slices failed on a loaded machine, its
  // line 12 px behind the edge).
  std::size_t i = 0;
  for (Timestamp slice_end = 2000; i < events.size(); slice_end += 2000) {
    chunk.clear();
    for (; i < events.size() && events.t[i] < slice_end; ++i) chunk.push_back(events[i]);
    if (chunk.empty()) continue;
    engine.process(chunk);
    ASSERT_TRUE(wait_for_rounds_within_a_period(engine, chunk.t.back())) << "no round within a minute";
  }
  // And the rounds on the lattice that holds every event (the input's pause brings them on).
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while ((engine.counters().tracked_us < events.t.back() || engine.counters().detected_us < events.t.back()) &&
         std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  engine.stop();
  std::vector<TrackedLine> lines;
  engine.snapshot(lines);
  const auto counters = engine.counters();
  EXPECT_EQ(counters.filtered.events_in, events.size());
  EXPECT_EQ(counters.events, counters.filtered.passed);
  EXPECT_GT(counters.events, events.size() * 99 / 100);  // the edge's events are correlated: nearly all pass
  EXPECT_EQ(counters.tracked_us, events.t.back());
  EXPECT_EQ(counters.detected_us, events.t.back());
  EXPECT_GT(counters.detect_rounds, 0u);
  EXPECT_GT(counters.track_rounds, 0u);
  ASSERT_GE(lines.size(), 10u);
  // The deterministic pipeline trails the edge (at x = 90 by now) by 1-3 px; a round here may run on
  // a lattice up to a slice older than the deterministic one would.
  for (const TrackedLine& line : lines) {
    EXPECT_GE(line.id, 1000u);
    EXPECT_NEAR(line.segment.centre().x(), 88.0f, 4.0f);
    EXPECT_NEAR(line.segment.q0.x(), line.segment.q1.x(), 2.0f);  // vertical, as the edge
  }
}

}  // namespace
}  // namespace evldt

namespace evldt {
namespace {

// A stream replayed at a tenth of real time: 0.5 ms of event time every 5 ms of wall time. The rounds
// follow the event time (a tracking round per 2 ms of it, a detection round per 4 ms), not the wall
// clock, which would ask for ten times as many; and when the input stops, a last round takes in the
// last events without waiting for a period of event time. With `shedding`, a batch was shed first.
// Counts that hold at any speed: each slice waits for the rounds due (so none is skipped however late
// the loops run), and the pause is 2 s, so a sleep that overshoots on a loaded machine is no pause; a
// loop starved of the CPU for 2 s while the other runs its round may still add a round on a pause
// (27 detection rounds were seen once in 25 runs with the machine loaded four times over), hence kPauseRounds.
constexpr std::uint64_t kPauseRounds = 3;
EngineCounters run_slowly(bool shedding) {
  PipelineConfig config = default_config_for(kSensor);
  config.schedule.input_pause_ms = 2000;
  RealtimeEngine engine(config);
  engine.start();
  if (shedding) engine.shed(0);
  const int factor = shedding ? config.schedule.shedding_period_factor : 1;
  const Timestamp track_period = factor * config.schedule.track_period_us;
  const Timestamp detect_period = factor * config.schedule.detect_period_us;
  const EventBatch events = vertical_sweep();
  constexpr Timestamp kSliceUs = 500, kEventTimeUs = 100'000;
  EventBatch chunk;
  std::size_t i = 0;
  for (Timestamp slice_end = kSliceUs; slice_end <= kEventTimeUs; slice_end += kSliceUs) {
    chunk.clear();
    for (; i < events.size() && events.t[i] < slice_end; ++i) chunk.push_back(events[i]);
    chunk.push_back(slice_end - 1, 5, 5, 1);  // a pixel in the margin: event time moves on in every slice
    engine.process(chunk);
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    for (EngineCounters c = engine.counters();
         c.tracked_us <= slice_end - 1 - track_period || c.detected_us <= slice_end - 1 - detect_period;
         c = engine.counters()) {
      if (std::chrono::steady_clock::now() > deadline) {
        ADD_FAILURE() << "no round due at " << slice_end - 1 << " us within a minute";
        return engine.counters();
      }
      std::this_thread::sleep_for(std::chrono::microseconds(200));
    }
  }
  const Timestamp last = kEventTimeUs - 1;
  std::vector<TrackedLine> lines;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (engine.snapshot(lines).lattice_us < last && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  engine.stop();
  EXPECT_EQ(engine.snapshot(lines).lattice_us, last);  // the pause ran a round on the last events
  return engine.counters();
}

TEST(RealtimeEngine, RoundsFollowEventTimeNotWallTime) {
  const EngineCounters counters = run_slowly(false);
  // 100 ms of event time: a round each period (2 ms tracking, 4 ms detection) of it, each on a lattice
  // at most a slice (0.5 ms) past its due time, and one more on the pause at the end: 40-51 and 22-26,
  // and a few on pauses. Rounds at the wall-time rate would be 500 and 250 over the 1 s.
  EXPECT_GE(counters.track_rounds, 40u);
  EXPECT_LE(counters.track_rounds, 51u + kPauseRounds);
  EXPECT_GE(counters.detect_rounds, 22u);
  EXPECT_LE(counters.detect_rounds, 26u + kPauseRounds);
  EXPECT_EQ(counters.detect_rounds_without_bend_test, 0u);
}

// While batches are shed (the service is past its means) the rounds run shedding_period_factor
// periods apart, for a second of event time after the last batch shed, and detection skips the
// bend test: the CPU goes to storage.
TEST(RealtimeEngine, RoundsRunFurtherApartWhileShedding) {
  ASSERT_EQ(default_config_for(kSensor).schedule.shedding_period_factor, 2);
  const EngineCounters counters = run_slowly(true);
  // The stretched schedule, 4 ms and 8 ms, each round at most a slice late, one more on the pause at
  // the end: 22-26 tracking and 11-14 detection rounds, and a few on pauses.
  EXPECT_GE(counters.track_rounds, 22u);
  EXPECT_LE(counters.track_rounds, 26u + kPauseRounds);
  EXPECT_GE(counters.detect_rounds, 11u);
  EXPECT_LE(counters.detect_rounds, 14u + kPauseRounds);
  EXPECT_EQ(counters.detect_rounds_without_bend_test, counters.detect_rounds);
}

}  // namespace
}  // namespace evldt
