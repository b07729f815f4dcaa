#include "evldt/eval/scene_evaluation.hpp"

#include "evldt/events/event_validator.hpp"

namespace evldt {

StepEvaluator::StepEvaluator(SensorSize sensor, std::vector<double> tolerance_fractions)
    : accuracy_(tolerance_fractions), counts_(tolerance_fractions.size()) {
  for (const double fraction : tolerance_fractions) matchers_.emplace_back(sensor, fraction);
}

void StepEvaluator::add_step(Timestamp t, std::span<const std::uint64_t> ids, std::span<const Segment> predicted,
                             std::span<const Segment> ground_truth) {
  for (std::size_t i = 0; i < matchers_.size(); ++i) counts_[i] = matchers_[i].match(predicted, ground_truth);
  accuracy_.add_step(counts_, predicted.size(), ground_truth.size());
  lifetimes_.observe_step(t, ids);
}

std::vector<Segment> scene_ground_truth(const Scene& scene, Timestamp t) {
  std::vector<Segment> out;
  for (const GtSegment& g : scene.visible_edges(t)) out.push_back({g.a.cast<float>(), g.b.cast<float>()});
  return out;
}

SceneRunResult evaluate_scene(const Scene& scene, const SimulatorConfig& sim, const PipelineConfig& config,
                              Timestamp step_us, StepEvaluator& evaluator) {
  EventSimulator simulator(scene, sim);
  EventValidator validator(scene.sensor, 0);
  DeterministicPipeline pipeline(config);
  std::vector<std::uint64_t> ids;
  std::vector<Segment> predicted;
  pipeline.set_output(step_us, [&](Timestamp t, const LineMap& lines, const ScarfLattice&) {
    ids.clear();
    predicted.clear();
    for (const TrackedLine& line : lines.lines()) {
      ids.push_back(line.id);
      predicted.push_back(line.segment);
    }
    evaluator.add_step(t, ids, predicted, scene_ground_truth(scene, t));
  });
  SceneRunResult result;
  EventBatch batch;
  while (true) {
    batch.clear();
    const bool more = simulator.run_until(simulator.now_us() + step_us, batch);
    result.events += batch.size();
    validator.filter(batch);
    pipeline.process(batch);
    if (!more) break;
  }
  result.scene_seconds = static_cast<double>(scene.duration_us) * 1e-6;
  result.counters = pipeline.counters();
  return result;
}

}  // namespace evldt
