#pragma once
// Scoring a stream of predicted segments against ground truth, step by step: the heat-map counts at
// each tolerance, and the lifetime of every predicted id.

#include <span>
#include <vector>

#include "evldt/eval/accumulator.hpp"
#include "evldt/eval/line_heatmap.hpp"
#include "evldt/lines/deterministic_pipeline.hpp"
#include "evldt/sim/event_simulator.hpp"

namespace evldt {

class StepEvaluator {
 public:
  StepEvaluator(SensorSize sensor, std::vector<double> tolerance_fractions);
  /// One output step: predicted (id, segment) pairs against the ground-truth segments of that time.
  void add_step(Timestamp t, std::span<const std::uint64_t> ids, std::span<const Segment> predicted,
                std::span<const Segment> ground_truth);
  [[nodiscard]] const EvaluationAccumulator& accuracy() const { return accuracy_; }
  [[nodiscard]] const LifetimeTracker& lifetimes() const { return lifetimes_; }

 private:
  std::vector<HeatmapMatcher> matchers_;
  EvaluationAccumulator accuracy_;
  LifetimeTracker lifetimes_;
  std::vector<MatchCounts> counts_;
};

struct SceneRunResult {
  std::uint64_t events = 0;
  double scene_seconds = 0;
  PipelineCounters counters;
};

/// Simulates the scene, runs the deterministic pipeline on it and scores every output step against
/// the scene's exact visible edges.
SceneRunResult evaluate_scene(const Scene& scene, const SimulatorConfig& sim, const PipelineConfig& config,
                              Timestamp step_us, StepEvaluator& evaluator);

/// Ground-truth segments of a scene at time t, as float segments.
std::vector<Segment> scene_ground_truth(const Scene& scene, Timestamp t);

}  // namespace evldt
