#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <random>
#include <stdexcept>
#include <vector>

#include "evldt/eval/assignment.hpp"
#include "evldt/eval/scene_evaluation.hpp"
#include "evldt/eval/tracking_metrics.hpp"

namespace evldt {
namespace {

// ---- the id assignment ---------------------------------------------------------------------------

double chosen_weight(std::span<const WeightedPair> pairs, const std::vector<std::size_t>& chosen) {
  double total = 0;
  for (const std::size_t c : chosen) total += pairs[c].weight;
  return total;
}

/// Every one-to-one choice of pairs, tried exhaustively.
double brute_force_best(std::size_t rows, std::size_t columns, const std::vector<WeightedPair>& pairs) {
  std::vector<bool> column_used(columns, false);
  std::function<double(std::size_t)> best_from = [&](std::size_t row) -> double {
    if (row == rows) return 0.0;
    double best = best_from(row + 1);  // the row stays unmatched
    for (const WeightedPair& p : pairs) {
      if (p.row != row || column_used[p.column]) continue;
      column_used[p.column] = true;
      best = std::max(best, p.weight + best_from(row + 1));
      column_used[p.column] = false;
    }
    return best;
  };
  return best_from(0);
}

TEST(MaxWeightMatching, EqualsExhaustiveSearchOnRandomSparseGraphs) {
  std::mt19937 random(7);
  for (int trial = 0; trial < 400; ++trial) {
    const std::size_t rows = 1 + random() % 7, columns = 1 + random() % 6;
    std::vector<WeightedPair> pairs;
    for (std::uint32_t r = 0; r < rows; ++r) {
      for (std::uint32_t c = 0; c < columns; ++c) {
        if (random() % 3 == 0) pairs.push_back({r, c, 1.0 + static_cast<double>(random() % 50)});
      }
    }
    const std::vector<std::size_t> chosen = max_weight_matching(rows, columns, pairs);
    std::vector<bool> row_used(rows, false), column_used(columns, false);
    for (const std::size_t c : chosen) {
      ASSERT_FALSE(row_used[pairs[c].row]) << "trial " << trial;
      ASSERT_FALSE(column_used[pairs[c].column]) << "trial " << trial;
      row_used[pairs[c].row] = column_used[pairs[c].column] = true;
    }
    EXPECT_DOUBLE_EQ(chosen_weight(pairs, chosen), brute_force_best(rows, columns, pairs)) << "trial " << trial;
  }
}

TEST(MaxWeightMatching, GivesUpAGreedyPairForTwoBetterOnes) {
  // Greedy takes (0, 0) = 10 and is left with nothing; the best is (0, 1) + (1, 0) = 9 + 9.
  const std::vector<WeightedPair> pairs = {{0, 0, 10}, {0, 1, 9}, {1, 0, 9}};
  EXPECT_EQ(max_weight_matching(2, 2, pairs), (std::vector<std::size_t>{1, 2}));
}

TEST(MaxWeightMatching, RejectsPairsOutOfRangeAndBadWeights) {
  const std::vector<WeightedPair> outside = {{0, 3, 1.0}};
  EXPECT_THROW((void)max_weight_matching(1, 3, outside), std::invalid_argument);
  const std::vector<WeightedPair> zero = {{0, 0, 0.0}};
  EXPECT_THROW((void)max_weight_matching(1, 1, zero), std::invalid_argument);
  const std::vector<WeightedPair> nan = {{0, 0, std::nan("")}};
  EXPECT_THROW((void)max_weight_matching(1, 1, nan), std::invalid_argument);
  EXPECT_TRUE(max_weight_matching(3, 0, {}).empty());
}

// ---- tracking metrics over steps -------------------------------------------------------------------

Segment horizontal(float y, float x0, float x1) { return {Point2(x0, y), Point2(x1, y)}; }

constexpr double kTolerance = 2.0;
constexpr SensorSize kTrackSensor{200, 150};
const Segment kLine = horizontal(20, 10, 110);  // 100 px long

void step(TrackingEvaluator& evaluator, Timestamp t, std::vector<std::uint64_t> ids, std::vector<Segment> predicted,
          std::vector<std::uint64_t> truth_ids = {5}, std::vector<Segment> truth = {kLine}) {
  evaluator.add_step(t, ids, predicted, truth_ids, truth);
}

TEST(TrackingEvaluator, OneIdOverTheWholeLifeIsPerfect) {
  TrackingEvaluator evaluator(kTrackSensor, kTolerance);
  for (Timestamp t = 0; t < 10; ++t) step(evaluator, t, {42}, {horizontal(21, 10, 110)});
  const TrackingSummary s = evaluator.summary();
  EXPECT_EQ(s.ground_truth_lines, 1u);
  EXPECT_DOUBLE_EQ(s.coverage, 1.0);
  EXPECT_DOUBLE_EQ(s.ids_per_line, 1.0);
  EXPECT_EQ(s.id_switches, 0u);
  EXPECT_NEAR(s.idf1, 1.0, 1e-9);
  ASSERT_EQ(evaluator.lines().size(), 1u);
  EXPECT_EQ(evaluator.lines()[0].owners.size(), 10u);
  EXPECT_EQ(evaluator.lines()[0].owners.back().id, 42u);
}

TEST(TrackingEvaluator, TwoHalvesWithTheirOwnIdsHalveIdf1ButDoNotSwitch) {
  TrackingEvaluator evaluator(kTrackSensor, kTolerance);
  for (Timestamp t = 0; t < 10; ++t) step(evaluator, t, {1, 2}, {horizontal(20, 10, 60), horizontal(20, 60, 110)});
  const TrackingSummary s = evaluator.summary();
  EXPECT_DOUBLE_EQ(s.coverage, 1.0);
  EXPECT_DOUBLE_EQ(s.ids_per_line, 2.0);
  EXPECT_EQ(s.id_switches, 0u);
  // Only one id can be the line's: half of the predicted and half of the true length.
  EXPECT_NEAR(s.id_true_positive_px, 500.0, 1e-6);
  EXPECT_NEAR(s.idf1, 0.5, 1e-9);
}

TEST(TrackingEvaluator, AHandOverIsOneSwitchAndTheRepresentativeHoldsWhileItMatches) {
  TrackingEvaluator evaluator(kTrackSensor, kTolerance);
  for (Timestamp t = 0; t < 4; ++t) step(evaluator, t, {1}, {horizontal(20, 10, 40)});
  // Id 2 now covers more of the line, but id 1 still matches: it stays the representative.
  for (Timestamp t = 4; t < 6; ++t) step(evaluator, t, {1, 2}, {horizontal(20, 10, 40), horizontal(20, 40, 110)});
  for (Timestamp t = 6; t < 10; ++t) step(evaluator, t, {2}, {horizontal(20, 40, 110)});
  const GroundTruthLineTrack& line = evaluator.lines().at(0);
  EXPECT_EQ(line.owners[5].id, 1u);
  EXPECT_EQ(line.owners[6].id, 2u);
  EXPECT_EQ(line.id_switches, 1u);
  EXPECT_EQ(line.distinct_ids, 2u);
}

TEST(TrackingEvaluator, AGapCostsCoverageButTheSameIdAfterItIsNoSwitch) {
  TrackingEvaluator evaluator(kTrackSensor, kTolerance);
  step(evaluator, 0, {9}, {kLine});
  step(evaluator, 1, {}, {});
  step(evaluator, 2, {9}, {kLine});
  step(evaluator, 3, {}, {}, {}, {});  // the line is not visible: not part of its life
  const GroundTruthLineTrack& line = evaluator.lines().at(0);
  EXPECT_EQ(line.visible_steps, 3u);
  EXPECT_EQ(line.matched_steps, 2u);
  EXPECT_EQ(line.id_switches, 0u);
  EXPECT_FALSE(line.owners[1].matched);
  EXPECT_NEAR(evaluator.summary().coverage, 2.0 / 3.0, 1e-12);
}

TEST(TrackingEvaluator, ASegmentMatchesOnlyWhenEnoughOfItLiesOnTheLine) {
  // 100 px long, leaving the line at x = 110: 42 px or 62 px of it within the tolerance (the part on
  // the line and the 2 px beyond its end).
  const Segment mostly_off = {Point2(70, 20), Point2(170, 20)};
  const Segment mostly_on = {Point2(50, 20), Point2(150, 20)};
  TrackingEvaluator evaluator(kTrackSensor, kTolerance);
  step(evaluator, 0, {1}, {mostly_off});
  step(evaluator, 1, {2}, {mostly_on});
  const GroundTruthLineTrack& line = evaluator.lines().at(0);
  EXPECT_FALSE(line.owners[0].matched);
  EXPECT_TRUE(line.owners[1].matched);
  const TrackingSummary s = evaluator.summary();
  EXPECT_NEAR(s.predicted_px, 200.0, 1e-4);
  EXPECT_NEAR(s.id_true_positive_px, 62.0, 1e-4);  // the part within the tolerance only
  EXPECT_NEAR(s.ground_truth_px, 200.0, 1e-4);
}

TEST(TrackingEvaluator, PiecesOfOneLineCountEachSampleOnce) {
  // The line is seen as two overlapping pieces (e.g. clipped around an occluder, drawn twice).
  TrackingEvaluator evaluator(kTrackSensor, kTolerance);
  step(evaluator, 0, {1}, {kLine}, {5, 5}, {horizontal(20, 10, 80), horizontal(20, 50, 110)});
  EXPECT_NEAR(evaluator.summary().id_true_positive_px, 100.0, 1e-4);
}

TEST(TrackingEvaluator, AnIdThatJumpsLinesIsGivenToTheLineItCoveredLonger) {
  const Segment other = horizontal(50, 10, 110);
  TrackingEvaluator evaluator(kTrackSensor, kTolerance);
  for (Timestamp t = 0; t < 3; ++t) step(evaluator, t, {7}, {kLine}, {5, 6}, {kLine, other});
  for (Timestamp t = 3; t < 10; ++t) step(evaluator, t, {7}, {other}, {5, 6}, {kLine, other});
  const TrackingSummary s = evaluator.summary();
  EXPECT_NEAR(s.id_true_positive_px, 700.0, 1e-4);
  EXPECT_NEAR(s.idf1, 2 * 700.0 / (1000.0 + 2000.0), 1e-9);
  EXPECT_EQ(s.lines_never_matched, 0u);
}

TEST(TrackingEvaluator, RejectsMismatchedSpansAndStepsOutOfOrder) {
  TrackingEvaluator evaluator(kTrackSensor, kTolerance);
  const std::vector<std::uint64_t> two = {1, 2};
  const std::vector<Segment> one = {kLine};
  EXPECT_THROW(evaluator.add_step(0, two, one, {}, {}), std::invalid_argument);
  evaluator.add_step(5, {}, {}, {}, {});
  EXPECT_THROW(evaluator.add_step(4, {}, {}, {}, {}), std::invalid_argument);
  EXPECT_THROW(TrackingEvaluator(kTrackSensor, -1.0), std::invalid_argument);
  EXPECT_THROW(TrackingEvaluator(kTrackSensor, 1.0, 0.0), std::invalid_argument);
  EXPECT_THROW(TrackingEvaluator(SensorSize{0, 10}, 1.0), std::invalid_argument);
}

TEST(TrackingEvaluator, OnlyTheSegmentsPartOnTheSensorIsMeasured) {
  TrackingEvaluator evaluator(kTrackSensor, kTolerance);
  // From x = 10 to 1e30: sampled on the sensor only (the 190 px up to x = 200), in no time.
  step(evaluator, 0, {1}, {horizontal(20, 10, 1e30f)});
  const TrackingSummary s = evaluator.summary();
  EXPECT_NEAR(s.predicted_px, 190.0, 1e-3);
  EXPECT_NEAR(s.id_true_positive_px, 100.0 + kTolerance, 1e-3);
  EXPECT_TRUE(evaluator.lines().at(0).owners.at(0).matched);  // 102 of 190 px: more than half
}

TEST(TrackingEvaluator, NothingPredictedIsNoIdentityAndNoCoverage) {
  TrackingEvaluator evaluator(kTrackSensor, kTolerance);
  for (Timestamp t = 0; t < 3; ++t) step(evaluator, t, {}, {});
  const TrackingSummary s = evaluator.summary();
  EXPECT_EQ(s.coverage, 0.0);
  EXPECT_TRUE(std::isnan(s.ids_per_line));
  EXPECT_TRUE(std::isnan(s.id_precision));
  EXPECT_EQ(s.idf1, 0.0);
  EXPECT_EQ(s.lines_never_matched, 1u);
}

TEST(StreamEvaluatorTracking, ScoresTheHeldPredictionAtEveryGroundTruthStep) {
  GroundTruthSteps truth;
  truth.times = {0, 10, 20, 30};
  truth.segments_at = [](std::size_t, std::vector<Segment>& segments, std::vector<std::uint64_t>& ids) {
    segments.assign(1, kLine);
    ids.assign(1, 5);
  };
  // 200 x 150: 1% of the diagonal is 2.5 px.
  StreamEvaluator evaluator(SensorSize{200, 150}, {0.01}, std::move(truth), 15);
  const std::vector<std::uint64_t> ids = {3};
  const std::vector<Segment> on_line = {kLine};
  evaluator.add_prediction(0, ids, on_line);
  evaluator.add_prediction(20, ids, on_line);  // held at 30; 10 is scored with the prediction of 0
  evaluator.finish();
  const TrackingSummary s = evaluator.tracking().summary();
  EXPECT_DOUBLE_EQ(s.coverage, 1.0);
  EXPECT_NEAR(s.idf1, 1.0, 1e-9);
  EXPECT_EQ(evaluator.tracking().lines().at(0).owners.size(), 4u);
}

// ---- why ids switch, and what identity costs -----------------------------------------------------------

TEST(TrackingEvaluatorCauses, EachSwitchIsCountedUnderWhatBecameOfTheOldId) {
  const Segment other_line = horizontal(80, 10, 110);
  const std::vector<std::uint64_t> both = {5, 6};
  const std::vector<Segment> lines = {kLine, other_line};
  TrackingEvaluator evaluator(kTrackSensor, kTolerance);
  Timestamp t = 0;
  // Id 1 stands for line 5, then moves to line 6 while id 2 takes line 5: "to another edge".
  step(evaluator, t++, {1}, {kLine}, both, lines);
  step(evaluator, t++, {1, 2}, {other_line, kLine}, both, lines);
  // Id 2 is not published for a step (id 3 stands in) and comes back: "returned" (and back to 2).
  step(evaluator, t++, {3}, {kLine}, both, lines);
  step(evaluator, t++, {2}, {kLine}, both, lines);
  // Id 2 drifts off every line while id 4 covers line 5: "off the edge".
  step(evaluator, t++, {2, 4}, {horizontal(50, 10, 110), kLine}, both, lines);
  // Id 4 ends; after a step with nothing on the line, id 5 is born there: "detected again", after a gap.
  step(evaluator, t++, {}, {}, both, lines);
  step(evaluator, t++, {5, 6}, {kLine, other_line}, both, lines);
  // Id 5 ends; id 6, published before, takes the line over: "taken over".
  step(evaluator, t++, {6}, {horizontal(20, 10, 110)}, both, lines);
  const TrackingSummary s = evaluator.summary();
  const IdSwitchCauses& c = s.switch_causes;
  EXPECT_EQ(c.to_other_edge, 1u);
  EXPECT_EQ(c.returned, 1u);
  EXPECT_EQ(c.off_edge, 1u);
  // Also line 6: id 1 left it at step 2, and id 6 found it again at step 6, after a gap.
  EXPECT_EQ(c.redetected, 2u);
  EXPECT_EQ(c.after_gap, 2u);
  // Also 3 -> 2 at step 3: id 3 ended, and 2 was published before it.
  EXPECT_EQ(c.taken_over, 2u);
  EXPECT_EQ(s.id_switches, 7u);
}

TEST(TrackingEvaluatorCauses, LengthMatchedUnderAnotherIdIsWhatOneIdPerLineWouldRecover) {
  TrackingEvaluator evaluator(kTrackSensor, kTolerance);
  for (Timestamp t = 0; t < 10; ++t) step(evaluator, t, {1, 2}, {horizontal(20, 10, 60), horizontal(20, 60, 110)});
  const TrackingSummary s = evaluator.summary();
  EXPECT_NEAR(s.unassigned_matched_px, 500.0, 1e-6);
  EXPECT_NEAR(2 * (s.id_true_positive_px + s.unassigned_matched_px) / (s.predicted_px + s.ground_truth_px), 1.0, 1e-9);
}

// ---- motion ---------------------------------------------------------------------------------------

TEST(TrackingEvaluatorVelocity, ComparesEachMatchAlongTheTrueLinesNormal) {
  TrackingEvaluator evaluator(kTrackSensor, kTolerance);
  const std::vector<std::uint64_t> truth_ids = {5};
  const std::vector<Segment> truth = {kLine};  // drawn left to right: its normal points down the image
  const std::vector<float> truth_velocity = {100.0f};
  const std::vector<std::uint64_t> ids = {1};
  // Drawn the other way round, so its own normal points up: -90 along it is +90 along the line's.
  const std::vector<Segment> reversed = {horizontal(20, 110, 10)};
  for (const float velocity : {-90.0f, -130.0f, -100.0f}) {
    const std::vector<float> predicted_velocity = {velocity};
    evaluator.add_step(0, ids, reversed, truth_ids, truth, predicted_velocity, truth_velocity);
  }
  // Without velocities a step adds nothing to them.
  evaluator.add_step(1, ids, reversed, truth_ids, truth);
  const TrackingSummary s = evaluator.summary();
  EXPECT_EQ(s.velocity_pairs, 3u);
  EXPECT_NEAR(s.velocity_error_median, 10.0, 1e-4);  // errors 10, 30, 0
  EXPECT_NEAR(s.velocity_relative_median, 0.1, 1e-6);
  const std::vector<float> two = {1.0f, 2.0f};
  EXPECT_THROW(evaluator.add_step(2, ids, reversed, truth_ids, truth, two, truth_velocity), std::invalid_argument);
}

TEST(TrackingEvaluatorVelocity, SlowTrueLinesAreLeftOutOfTheRelativeErrorAndNoPairsIsUndefined) {
  TrackingEvaluator evaluator(kTrackSensor, kTolerance);
  EXPECT_TRUE(std::isnan(evaluator.summary().velocity_error_median));
  const std::vector<std::uint64_t> ids = {1}, truth_ids = {5};
  const std::vector<Segment> on_line = {kLine};
  const std::vector<float> predicted = {3.0f}, slow = {static_cast<float>(kMinRelativeSpeed / 2)};
  evaluator.add_step(0, ids, on_line, truth_ids, on_line, predicted, slow);
  const TrackingSummary s = evaluator.summary();
  EXPECT_EQ(s.velocity_pairs, 1u);
  EXPECT_NEAR(s.velocity_error_median, 2.0, 1e-6);
  EXPECT_TRUE(std::isnan(s.velocity_relative_median));
}

TEST(StreamEvaluatorVelocity, TheTrueVelocityIsTheCentralDifferenceOfTheLinesPlace) {
  // The line moves down 1 px per 10 ms step (100 px/s along its normal) and turns slightly.
  GroundTruthSteps truth;
  truth.times = {0, 10'000, 20'000, 30'000};
  truth.segments_at = [](std::size_t index, std::vector<Segment>& segments, std::vector<std::uint64_t>& ids) {
    const auto k = static_cast<float>(index);
    segments.assign(1, Segment{Point2(10, 20 + k), Point2(110, 20 + k + 0.01f * k)});
    ids.assign(1, 5);
  };
  StreamEvaluator evaluator(SensorSize{200, 150}, {0.01}, truth, 15'000);
  const std::vector<std::uint64_t> ids = {3};
  for (std::size_t i = 0; i < truth.times.size(); ++i) {
    std::vector<Segment> segments;
    std::vector<std::uint64_t> truth_ids;
    truth.segments_at(i, segments, truth_ids);
    const std::vector<float> velocity = {100.0f};
    evaluator.add_prediction(truth.times[i], ids, segments, velocity);
  }
  evaluator.finish();
  const TrackingSummary s = evaluator.tracking().summary();
  EXPECT_EQ(s.velocity_pairs, 4u);
  EXPECT_LT(s.velocity_error_median, 1.0);
  EXPECT_LT(s.velocity_relative_median, 0.01);
}

}  // namespace
}  // namespace evldt
