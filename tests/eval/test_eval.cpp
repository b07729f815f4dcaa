#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <opencv2/imgcodecs.hpp>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "eval/reference_matching.hpp"
#include "evldt/eval/accumulator.hpp"
#include "evldt/eval/line_heatmap.hpp"
#include "evldt/eval/plots.hpp"
#include "evldt/eval/scene_evaluation.hpp"
#include "evldt/eval/whole_line_support.hpp"
#include "evldt/sim/scenes.hpp"

namespace evldt {
namespace {

// 100 x 75: the diagonal is 125 px, so 1% is 1.25 px (1 px, not sqrt(2)) and 2% is 2.5 px (up to
// sqrt(5), not sqrt(8)): no pixel distance lies near a tolerance.
constexpr SensorSize kSensor{100, 75};
constexpr std::size_t kWidth = 100;

/// Horizontal segment through the middle of row y, over the pixels x0 .. x1 (x1 - x0 + 1 pixels).
Segment row_segment(int y, int x0, int x1) {
  const float yc = static_cast<float>(y) + 0.5f;
  return {Point2(static_cast<float>(x0) + 0.5f, yc), Point2(static_cast<float>(x1) + 0.5f, yc)};
}

std::size_t line_pixels(const std::vector<std::uint8_t>& map) {
  return static_cast<std::size_t>(std::count(map.begin(), map.end(), std::uint8_t{1}));
}

void expect_prf(const Prf& actual, double precision, double recall, double f) {
  EXPECT_DOUBLE_EQ(actual.precision, precision);
  EXPECT_DOUBLE_EQ(actual.recall, recall);
  EXPECT_DOUBLE_EQ(actual.f, f);
}

TEST(Rasterise, MarksEveryPixelAlongTheSegmentAndClipsAtTheBorder) {
  std::vector<std::uint8_t> map;
  const std::vector<Segment> inside = {row_segment(20, 10, 50)};
  rasterise(inside, kSensor, map);
  ASSERT_EQ(map.size(), 100u * 75u);
  EXPECT_EQ(line_pixels(map), 41u);
  EXPECT_EQ(map[20 * kWidth + 10], 1);
  EXPECT_EQ(map[20 * kWidth + 50], 1);
  EXPECT_EQ(map[20 * kWidth + 51], 0);

  const std::vector<Segment> partly_off = {{Point2(-10.5f, 5.5f), Point2(5.5f, 5.5f)},      // x 0 .. 5 visible
                                           {Point2(50.5f, 70.5f), Point2(50.5f, 300.0f)}};  // y 70 .. 74 visible
  rasterise(partly_off, kSensor, map);
  EXPECT_EQ(line_pixels(map), 6u + 5u);

  // A shallow diagonal sampled at <= 0.25 px marks every column it crosses.
  const std::vector<Segment> diagonal = {{Point2(0.2f, 0.7f), Point2(30.9f, 17.1f)}};
  rasterise(diagonal, kSensor, map);
  for (int x = 0; x <= 30; ++x) {
    int marked = 0;
    for (int y = 0; y < kSensor.height; ++y) marked += map[static_cast<std::size_t>(y) * kWidth + x];
    EXPECT_GE(marked, 1) << "column " << x;
  }

  const std::vector<Segment> off_or_broken = {{Point2(-5, -5), Point2(-1, -9)},
                                              {Point2(std::nanf(""), 3), Point2(10, 3)}};
  rasterise(off_or_broken, kSensor, map);
  EXPECT_EQ(line_pixels(map), 0u);
}

TEST(Prf, WhatHasNoDenominatorIsUndefinedNeverPerfect) {
  const Prf nothing = prf({});
  EXPECT_TRUE(std::isnan(nothing.precision) && std::isnan(nothing.recall) && std::isnan(nothing.f));
  const Prf on_empty_scene = prf({10, 0, 0});
  EXPECT_EQ(on_empty_scene.precision, 0);
  EXPECT_TRUE(std::isnan(on_empty_scene.recall));
  EXPECT_EQ(on_empty_scene.f, 0);
  const Prf nothing_predicted = prf({0, 10, 0});
  EXPECT_TRUE(std::isnan(nothing_predicted.precision));
  EXPECT_EQ(nothing_predicted.recall, 0);
  EXPECT_EQ(nothing_predicted.f, 0);
  expect_prf(prf({10, 20, 5}), 0.5, 0.25, 2 * 0.5 * 0.25 / 0.75);
}

TEST(HeatmapMatcher, ToleranceIsAFractionOfTheDiagonal) {
  EXPECT_NEAR(HeatmapMatcher(kSensor, 0.01).tolerance_px(), 1.25, 1e-12);
  EXPECT_NEAR(HeatmapMatcher({640, 480}, 0.02).tolerance_px(), 16.0, 1e-9);
  EXPECT_THROW(HeatmapMatcher({0, 10}, 0.01), std::invalid_argument);
  EXPECT_THROW(HeatmapMatcher(kSensor, -0.01), std::invalid_argument);
  HeatmapMatcher matcher(kSensor, 0.01);
  const std::vector<std::uint8_t> wrong_size(10, 0), right_size(100 * 75, 0);
  EXPECT_THROW((void)matcher.match_maps(wrong_size, right_size), std::invalid_argument);
}

TEST(HeatmapMatcher, PerfectPredictionScoresOne) {
  const std::vector<Segment> scene = {row_segment(20, 10, 50), row_segment(45, 10, 50), {Point2(5, 5), Point2(40, 70)}};
  HeatmapMatcher matcher(kSensor, 0.01);
  const MatchCounts counts = matcher.match(scene, scene);
  EXPECT_EQ(counts.predicted, counts.ground_truth);
  EXPECT_EQ(counts.matched, counts.ground_truth);
  expect_prf(prf(counts), 1, 1, 1);
  EXPECT_EQ(matcher.match({}, {}), (MatchCounts{0, 0, 0}));
}

TEST(HeatmapMatcher, ShiftWithinToleranceMatchesAndBeyondItDoesNot) {
  const std::vector<Segment> truth = {row_segment(20, 10, 50)};
  HeatmapMatcher matcher(kSensor, 0.02);                        // 2.5 px
  const std::vector<Segment> near = {row_segment(22, 10, 50)};  // 2 px away
  expect_prf(prf(matcher.match(near, truth)), 1, 1, 1);
  const std::vector<Segment> far = {row_segment(24, 10, 50)};  // 4 px away
  const MatchCounts counts = matcher.match(far, truth);
  EXPECT_EQ(counts, (MatchCounts{41, 41, 0}));
  expect_prf(prf(counts), 0, 0, 0);
  // Slid along itself: by 2 px every pixel still finds a partner 2 px away; by 4 px two pixels at
  // either end have none.
  const std::vector<Segment> slid_2 = {row_segment(20, 12, 52)}, slid_4 = {row_segment(20, 14, 54)};
  EXPECT_EQ(matcher.match(slid_2, truth), (MatchCounts{41, 41, 41}));
  EXPECT_EQ(matcher.match(slid_4, truth), (MatchCounts{41, 41, 39}));
}

TEST(HeatmapMatcher, MissingLineLowersRecallOnly) {
  const std::vector<Segment> truth = {row_segment(20, 10, 50), row_segment(45, 10, 50)};
  const std::vector<Segment> predicted = {row_segment(20, 10, 50)};
  HeatmapMatcher matcher(kSensor, 0.01);
  const MatchCounts counts = matcher.match(predicted, truth);
  EXPECT_EQ(counts, (MatchCounts{41, 82, 41}));
  expect_prf(prf(counts), 1.0, 0.5, 2.0 / 3.0);
}

TEST(HeatmapMatcher, SpuriousLineLowersPrecisionOnly) {
  const std::vector<Segment> truth = {row_segment(20, 10, 50), row_segment(45, 10, 50)};
  const std::vector<Segment> predicted = {row_segment(20, 10, 50), row_segment(45, 10, 50), row_segment(65, 10, 50)};
  HeatmapMatcher matcher(kSensor, 0.01);
  const MatchCounts counts = matcher.match(predicted, truth);
  EXPECT_EQ(counts, (MatchCounts{123, 82, 82}));
  expect_prf(prf(counts), 2.0 / 3.0, 1.0, 0.8);
}

TEST(HeatmapMatcher, MatchesOneToOne) {
  const std::vector<Segment> truth = {row_segment(20, 10, 50)};
  HeatmapMatcher matcher(kSensor, 0.01);  // 1.25 px: both predictions below lie within it
  // Two predictions of the one line, 1 px apart: each ground-truth pixel can vouch for only one.
  const std::vector<Segment> doubled = {row_segment(20, 10, 50), row_segment(21, 10, 50)};
  const MatchCounts counts = matcher.match(doubled, truth);
  EXPECT_EQ(counts, (MatchCounts{82, 41, 41}));
  expect_prf(prf(counts), 0.5, 1.0, 2.0 / 3.0);
  // Two identical predictions draw the same pixels: the line map keeps one of them.
  const std::vector<Segment> identical = {row_segment(20, 10, 50), row_segment(20, 10, 50)};
  EXPECT_EQ(matcher.match(identical, truth), (MatchCounts{41, 41, 41}));
}

TEST(HeatmapMatcher, FindsTheMaximumWhereGreedyPairingFallsShort) {
  // Predicted a = (10, 10) comes first and takes its nearest ground truth g1 = (10, 10), although
  // it could also take g2 = (8, 10); predicted b = (12, 10) reaches only g1. Augmenting b -> g1 -> a
  // -> g2 matches both.
  std::vector<std::uint8_t> predicted(kWidth * 75, 0), truth(kWidth * 75, 0);
  predicted[10 * kWidth + 10] = 1;
  predicted[10 * kWidth + 12] = 1;
  truth[10 * kWidth + 10] = 1;
  truth[10 * kWidth + 8] = 1;
  HeatmapMatcher matcher(kSensor, 0.02);  // 2.5 px
  EXPECT_EQ(matcher.match_maps(predicted, truth), (MatchCounts{2, 2, 2}));
}

TEST(HeatmapMatcher, HandlesEmptySidesTinySensorsAndHugeTolerances) {
  HeatmapMatcher matcher(kSensor, 0.01);
  const std::vector<Segment> line = {row_segment(20, 10, 50)};
  EXPECT_EQ(matcher.match(line, {}), (MatchCounts{41, 0, 0}));
  EXPECT_EQ(matcher.match({}, line), (MatchCounts{0, 41, 0}));
  // A radius far beyond the sensor: every pixel reaches every other.
  HeatmapMatcher everything({3, 2}, 10.0);
  const std::vector<Segment> top = {{Point2(0, 0.5f), Point2(2.9f, 0.5f)}},
                             corner = {{Point2(2.5f, 1.5f), Point2(2.5f, 1.5f)}};
  EXPECT_EQ(everything.match(top, corner), (MatchCounts{3, 1, 1}));
}

TEST(HeatmapMatcher, RepeatedCallsGiveTheSameCounts) {
  std::mt19937 random(7);
  std::uniform_real_distribution<float> coordinate(0.0f, 75.0f);
  std::vector<Segment> predicted, truth;
  for (int i = 0; i < 40; ++i) {
    predicted.push_back(
        {Point2(coordinate(random), coordinate(random)), Point2(coordinate(random), coordinate(random))});
    truth.push_back({Point2(coordinate(random), coordinate(random)), Point2(coordinate(random), coordinate(random))});
  }
  HeatmapMatcher matcher(kSensor, 0.02);
  const MatchCounts first = matcher.match(predicted, truth);
  EXPECT_GT(first.matched, 0u);
  (void)matcher.match(truth, predicted);  // different sizes in between must not leak into the next call
  EXPECT_EQ(matcher.match(predicted, truth), first);
  EXPECT_EQ(HeatmapMatcher(kSensor, 0.02).match(predicted, truth), first);
}

// Max-cardinality (Hopcroft-Karp) against the BSDS-style min-cost assignment with outlier cost
// 100 * tolerance. Measured over the 60 seeded cases below (64 x 48 sensor, tolerances 1%, 2% and
// 5% of the diagonal, 58 .. 268 pixels per side, crossing and jittered segments): the counts never
// differed (difference 0 in every case). Trading one match for shorter pairs pays only when it
// shortens about 200 pairs by about the tolerance each, which these sizes cannot reach.
TEST(HeatmapMatcher, AgreesWithTheMinCostReference) {
  constexpr SensorSize sensor{64, 48};
  std::mt19937 random(2024);
  std::uniform_real_distribution<float> x(0.0f, 64.0f), y(0.0f, 48.0f), angle(0.0f, 6.2831853f), length(6.0f, 25.0f),
      jitter(-2.5f, 2.5f);
  std::uniform_int_distribution<int> count(4, 12);
  const auto random_segment = [&]() {
    const Point2 centre(x(random), y(random));
    const float a = angle(random);
    const Point2 half = 0.5f * length(random) * Point2(std::cos(a), std::sin(a));
    return Segment{centre - half, centre + half};
  };
  std::uint64_t largest_difference = 0, compared = 0;
  for (int trial = 0; trial < 20; ++trial) {
    std::vector<Segment> truth, predicted;
    const int lines = count(random);
    for (int i = 0; i < lines; ++i) {
      const Segment s = random_segment();
      truth.push_back(s);
      // A jittered copy of most lines, and some spurious ones.
      if (i % 3 != 2) {
        predicted.push_back(
            {s.q0 + Point2(jitter(random), jitter(random)), s.q1 + Point2(jitter(random), jitter(random))});
      }
      if (i % 2 == 0) predicted.push_back(random_segment());
    }
    for (const double fraction : {0.01, 0.02, 0.05}) {
      HeatmapMatcher matcher(sensor, fraction);
      const MatchCounts counts = matcher.match(predicted, truth);
      if (counts.predicted > kReferenceMaxPixels || counts.ground_truth > kReferenceMaxPixels) continue;
      const std::uint64_t reference = min_cost_matched_count_reference(sensor, fraction, predicted, truth);
      EXPECT_LE(reference, counts.matched) << "trial " << trial << " fraction " << fraction;
      largest_difference = std::max(largest_difference, counts.matched - reference);
      ++compared;
    }
  }
  EXPECT_GE(compared, 50u);
  EXPECT_EQ(largest_difference, 0u);
  // A low outlier cost makes the assignment drop far pairs, which max-cardinality keeps.
  const std::vector<Segment> truth = {row_segment(10, 5, 40)};
  const std::vector<Segment> shifted = {row_segment(12, 5, 40)};
  EXPECT_EQ(HeatmapMatcher(sensor, 0.05).match(shifted, truth).matched, 36u);
  EXPECT_EQ(min_cost_matched_count_reference(sensor, 0.05, shifted, truth, 0.2), 0u);  // pair 2 px > 2 * 0.8 px
}

TEST(EvaluationAccumulator, SumsCountsOverSteps) {
  EvaluationAccumulator accumulator;  // 1% and 2%
  ASSERT_EQ(accumulator.tolerance_fractions().size(), 2u);
  EXPECT_TRUE(std::isnan(accumulator.summed_prf(0).f));  // nothing scored is not a score
  const std::vector<MatchCounts> first = {{100, 80, 60}, {100, 80, 70}};
  const std::vector<MatchCounts> second = {{50, 70, 40}, {50, 70, 50}};
  accumulator.add_step(first, 10, 8);
  accumulator.add_step(second, 5, 7);
  EXPECT_EQ(accumulator.steps(), 2u);
  EXPECT_EQ(accumulator.total(0), (MatchCounts{150, 150, 100}));
  EXPECT_EQ(accumulator.total(1), (MatchCounts{150, 150, 120}));
  expect_prf(accumulator.summed_prf(0), 2.0 / 3.0, 2.0 / 3.0, 2.0 / 3.0);
  expect_prf(accumulator.summed_prf(1), 0.8, 0.8, 0.8);
  EXPECT_DOUBLE_EQ(accumulator.mean_predicted_segments(), 7.5);
  EXPECT_DOUBLE_EQ(accumulator.mean_ground_truth_segments(), 7.5);
  EXPECT_THROW(accumulator.add_step(std::span(first).first(1), 1, 1), std::invalid_argument);
  EXPECT_THROW(EvaluationAccumulator(std::vector<double>{}), std::invalid_argument);
}

TEST(EvaluationAccumulator, TakesMatcherResults) {
  EvaluationAccumulator accumulator({0.01, 0.02});
  HeatmapMatcher tight(kSensor, 0.01), loose(kSensor, 0.02);
  const std::vector<Segment> truth = {row_segment(20, 10, 50), row_segment(45, 10, 50)};
  const std::vector<Segment> predicted = {row_segment(22, 10, 50)};  // 2 px off: only the loose tolerance
  const std::vector<Segment> perfect = truth;
  for (const auto& step : {predicted, perfect}) {
    const MatchCounts counts[2] = {tight.match(step, truth), loose.match(step, truth)};
    accumulator.add_step(counts, step.size(), truth.size());
  }
  EXPECT_EQ(accumulator.total(0), (MatchCounts{123, 164, 82}));
  EXPECT_EQ(accumulator.total(1), (MatchCounts{123, 164, 123}));
  EXPECT_DOUBLE_EQ(accumulator.mean_predicted_segments(), 1.5);
}

// ---- scoring over the ground truth's steps ------------------------------------------------------

// Ground truth at t = 0, 10, 20, 30, 40: one horizontal line that moves down 2 px a step (more than
// the 1% tolerance of 1.25 px, less than the 2% one of 2.5 px).
constexpr Timestamp kGtPeriod = 10;
constexpr int kGtSteps = 5;

Segment moving_line(std::size_t step) { return row_segment(10 + 2 * static_cast<int>(step), 10, 50); }

GroundTruthSteps moving_truth() {
  GroundTruthSteps steps;
  for (int k = 0; k < kGtSteps; ++k) steps.times.push_back(k * kGtPeriod);
  steps.segments_at = [](std::size_t index, std::vector<Segment>& segments, std::vector<std::uint64_t>& ids) {
    segments.assign(1, moving_line(index));
    ids.assign(1, 3);
  };
  return steps;
}

StreamEvaluator moving_evaluator() {
  return StreamEvaluator(kSensor, {0.01, 0.02}, moving_truth(),
                         std::llround(StreamEvaluator::kHoldPeriods * kGtPeriod));
}

void predict(StreamEvaluator& evaluator, Timestamp t, std::uint64_t id, std::vector<Segment> segments) {
  const std::vector<std::uint64_t> ids(segments.size(), id);
  evaluator.add_prediction(t, ids, segments);
}

TEST(StreamEvaluator, AnEmptyPredictionMissesEveryStep) {
  StreamEvaluator evaluator = moving_evaluator();
  evaluator.finish();
  EXPECT_EQ(evaluator.accuracy().steps(), static_cast<std::uint64_t>(kGtSteps));
  EXPECT_EQ(evaluator.accuracy().total(0), (MatchCounts{0, 41u * kGtSteps, 0}));
  const Prf result = evaluator.accuracy().summed_prf(0);
  EXPECT_TRUE(std::isnan(result.precision));  // reported n/a
  EXPECT_EQ(result.recall, 0);
  EXPECT_EQ(result.f, 0);
  EXPECT_EQ(evaluator.coverage().steps_without_prediction, static_cast<std::uint64_t>(kGtSteps));
}

TEST(StreamEvaluator, OneStepOfPredictionIsHeldForOnePeriodAndRecallIsOverAllSteps) {
  StreamEvaluator evaluator = moving_evaluator();
  predict(evaluator, 20, 1, {moving_line(2)});  // exact at t = 20; held at t = 30 (10 <= 15), not at 40 (20 > 15)
  evaluator.finish();
  // Step 20 matches all 41 pixels; step 30 compares the line of 20 with the one 2 px lower: no match at 1%.
  EXPECT_EQ(evaluator.accuracy().total(0), (MatchCounts{2 * 41, 5 * 41, 41}));
  EXPECT_EQ(evaluator.accuracy().total(1), (MatchCounts{2 * 41, 5 * 41, 2 * 41}));
  EXPECT_DOUBLE_EQ(evaluator.accuracy().summed_prf(1).recall, 2.0 / 5.0);
  const StepCoverage& coverage = evaluator.coverage();
  EXPECT_EQ(coverage.ground_truth_steps, 5u);
  EXPECT_EQ(coverage.steps_without_prediction, 3u);  // 0, 10 (before it) and 40 (beyond its hold)
  EXPECT_EQ(coverage.predicted_steps, 1u);
  EXPECT_EQ(coverage.predicted_steps_scored, 1u);
}

// ---- what an events-only camera can see -----------------------------------------------------------

// Speeds along a piece are linear between its ends: the part below the threshold either way is hidden.
TEST(SplitByNormalSpeed, HidesThePartOfAPieceMovingSlowerThanTheThreshold) {
  const std::vector<Segment> truth = {{Point2(0, 0), Point2(100, 0)},
                                      {Point2(0, 10), Point2(100, 10)},
                                      {Point2(0, 20), Point2(100, 20)},
                                      {Point2(0, 30), Point2(100, 30)}};
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const std::vector<float> at_q0 = {-4, 1, 5, nan}, at_q1 = {4, -1, 3, 0};
  std::vector<Segment> visible, hidden;
  split_by_normal_speed(truth, at_q0, at_q1, 2, visible, hidden);
  // A turning line: seen at both ends, not where it turns (|v| < 2 for s in (0.25, 0.75)); one that
  // creeps: not at all; one that moves: whole; one of unknown speed: counted as seen.
  ASSERT_EQ(visible.size(), 4u);
  ASSERT_EQ(hidden.size(), 2u);
  EXPECT_FLOAT_EQ(visible[0].q1.x(), 25);
  EXPECT_FLOAT_EQ(hidden[0].q0.x(), 25);
  EXPECT_FLOAT_EQ(hidden[0].q1.x(), 75);
  EXPECT_FLOAT_EQ(visible[1].q0.x(), 75);
  EXPECT_FLOAT_EQ(hidden[1].q0.y(), 10);
  EXPECT_FLOAT_EQ(hidden[1].q1.x(), 100);
  EXPECT_FLOAT_EQ(visible[2].q0.y(), 20);
  EXPECT_FLOAT_EQ(visible[3].q0.y(), 30);
  EXPECT_THROW(split_by_normal_speed(truth, at_q0, {}, 2, visible, hidden), std::invalid_argument);
}

// Two true lines, one moving across itself and one along itself (no events): the second and what is
// predicted on it are left out of the visible score; a prediction on neither still counts against.
TEST(StreamEvaluator, VisibleOnlyLeavesOutAnEdgeMovingAlongItselfAndWhatIsPredictedOnIt) {
  const auto along_itself = [](std::size_t step) {
    return row_segment(40, 10 + static_cast<int>(step), 50 + static_cast<int>(step));
  };
  GroundTruthSteps truth = moving_truth();
  truth.segments_at = [&](std::size_t index, std::vector<Segment>& segments, std::vector<std::uint64_t>& ids) {
    segments = {moving_line(index), along_itself(index)};
    ids = {3, 4};
  };
  for (const bool off_edge : {false, true}) {
    SCOPED_TRACE(off_edge);
    StreamEvaluator evaluator(kSensor, {0.01}, truth, std::llround(StreamEvaluator::kHoldPeriods * kGtPeriod));
    evaluator.score_visible_only(VisibleOnly::by_speed(2.0f));
    for (int k = 0; k < kGtSteps; ++k) {
      const auto index = static_cast<std::size_t>(k);
      predict(evaluator, k * kGtPeriod, 1,
              {moving_line(index), off_edge ? row_segment(70, 10, 50) : along_itself(index)});
    }
    evaluator.finish();
    const Prf full = evaluator.accuracy().summed_prf(0);
    ASSERT_TRUE(evaluator.visible_accuracy().has_value());
    const Prf visible = evaluator.visible_accuracy()->summed_prf(0);
    EXPECT_EQ(evaluator.visible_truth_pixels(), evaluator.hidden_truth_pixels());  // two lines of 41 px
    EXPECT_DOUBLE_EQ(visible.recall, 1.0);
    if (off_edge) {
      EXPECT_DOUBLE_EQ(full.recall, 0.5);
      EXPECT_DOUBLE_EQ(visible.precision, 0.5);
    } else {
      EXPECT_DOUBLE_EQ(full.precision, 1.0);
      EXPECT_DOUBLE_EQ(visible.precision, 1.0);
    }
  }
  StreamEvaluator evaluator = moving_evaluator();
  EXPECT_THROW(evaluator.score_visible_only(VisibleOnly::by_speed(-1.0f)), std::invalid_argument);
}

// The paper's view: counts summed up to each second. Steps at 0, 0.5, 1.5, 2 and 2.5 s, the same
// line each; it is predicted exactly in the first second only.
TEST(StreamEvaluator, CumulativePerSecondSumsTheStepsUpToEachSecond) {
  GroundTruthSteps truth;
  truth.times = {0, 500'000, 1'500'000, 2'000'000, 2'500'000};
  truth.segments_at = [](std::size_t, std::vector<Segment>& segments, std::vector<std::uint64_t>& ids) {
    segments.assign(1, moving_line(0));
    ids.assign(1, 3);
  };
  StreamEvaluator evaluator(kSensor, {0.01}, truth, 100'000);
  predict(evaluator, 0, 1, {moving_line(0)});
  predict(evaluator, 500'000, 1, {moving_line(0)});
  evaluator.finish();
  const auto seconds = evaluator.per_second();
  ASSERT_EQ(seconds.size(), 3u);  // 0 and 0.5 s in the first, 1.5 and 2 s in the second, 2.5 s in the third
  EXPECT_EQ(seconds[0].steps, 2u);
  EXPECT_EQ(seconds[1].steps, 2u);
  EXPECT_EQ(seconds[2].steps, 1u);
  EXPECT_DOUBLE_EQ(seconds[0].cumulative.recall, 1.0);
  EXPECT_DOUBLE_EQ(seconds[1].cumulative.recall, 2.0 / 4.0);
  EXPECT_DOUBLE_EQ(seconds[2].cumulative.recall, 2.0 / 5.0);
  EXPECT_DOUBLE_EQ(seconds[2].cumulative.precision, 1.0);
  EXPECT_DOUBLE_EQ(seconds[2].cumulative.recall, evaluator.accuracy().summed_prf(0).recall);
  EXPECT_EQ(evaluator.seconds_origin(), Timestamp{0});
}

// A second that holds no step says so (the table prints '-' there), and still carries the sums so far.
TEST(StreamEvaluator, PerSecondCountsTheStepsOfEachSecondAndNoneWhereThereAreNone) {
  GroundTruthSteps truth;
  truth.times = {200'000, 2'500'000};
  truth.segments_at = [](std::size_t, std::vector<Segment>& segments, std::vector<std::uint64_t>& ids) {
    segments.assign(1, moving_line(0));
    ids.assign(1, 3);
  };
  StreamEvaluator evaluator(kSensor, {0.01}, truth, 100'000);
  predict(evaluator, 200'000, 1, {moving_line(0)});
  evaluator.finish();
  const auto seconds = evaluator.per_second();
  ASSERT_EQ(seconds.size(), 3u);
  EXPECT_EQ(seconds[0].steps, 1u);
  EXPECT_EQ(seconds[1].steps, 0u);
  EXPECT_EQ(seconds[2].steps, 1u);
  EXPECT_DOUBLE_EQ(seconds[1].cumulative.recall, 1.0);
  EXPECT_DOUBLE_EQ(seconds[2].cumulative.recall, 0.5);
}

// The steps of an lcm-log's recorded span (evldt-eval --segments LOG): each kept step keeps its own
// segments (the times alone were once cut, and the later steps were scored against the first ones').
TEST(GroundTruthSteps, StepsWithinASpanKeepTheirOwnSegments) {
  std::vector<GroundTruthRow> rows;
  for (int k = 0; k < 5; ++k) rows.push_back({k * 10'000, GtSegment{k, Vec2d(k, 0), Vec2d(k, 20)}});
  const GroundTruthSteps within = steps_within(csv_ground_truth_steps(rows), 15'000, 40'000);
  ASSERT_EQ(within.times, (std::vector<Timestamp>{20'000, 30'000, 40'000}));
  std::vector<Segment> segments;
  std::vector<std::uint64_t> ids;
  for (std::size_t i = 0; i < within.times.size(); ++i) {
    within.segments_at(i, segments, ids);
    ASSERT_EQ(ids.size(), 1u);
    EXPECT_EQ(ids[0], i + 2);
    EXPECT_FLOAT_EQ(segments[0].q0.x(), static_cast<float>(i + 2));
  }
}

// A clock anywhere in the 64-bit range (DV writes Unix-epoch microseconds): the same table as the
// clock from 0, and nothing allocated by the clock's value.
TEST(StreamEvaluator, CumulativePerSecondIsTheSameOnAClockShiftedToTheEpochOrTheEndOfTheRange) {
  auto seconds_from = [](Timestamp origin) {
    GroundTruthSteps truth;
    for (const Timestamp t : {0, 500'000, 1'500'000, 2'000'000, 2'500'000}) truth.times.push_back(origin + t);
    truth.segments_at = [](std::size_t, std::vector<Segment>& segments, std::vector<std::uint64_t>& ids) {
      segments.assign(1, moving_line(0));
      ids.assign(1, 3);
    };
    StreamEvaluator evaluator(kSensor, {0.01}, truth, 100'000);
    predict(evaluator, origin, 1, {moving_line(0)});
    predict(evaluator, origin + 500'000, 1, {moving_line(0)});
    evaluator.finish();
    std::vector<double> recalls;
    for (const auto& second : evaluator.per_second()) recalls.push_back(second.cumulative.recall);
    return recalls;
  };
  const std::vector<double> from_zero = seconds_from(0);
  ASSERT_EQ(from_zero.size(), 3u);
  EXPECT_EQ(seconds_from(1'600'000'000'000'000), from_zero);  // 2020 in Unix-epoch microseconds
  EXPECT_EQ(seconds_from(-7'000'000'000'000'000), from_zero);
  EXPECT_EQ(seconds_from(std::numeric_limits<Timestamp>::max() / 1'000'000 * 1'000'000 - 3'000'000), from_zero);
}

TEST(StreamEvaluator, StepsSpanningMoreSecondsThanTheTableHoldsAreAClearError) {
  GroundTruthSteps truth;
  truth.times = {0, static_cast<Timestamp>(StreamEvaluator::kMaxSeconds + 1) * 1'000'000};
  truth.segments_at = [](std::size_t, std::vector<Segment>& segments, std::vector<std::uint64_t>& ids) {
    segments.assign(1, moving_line(0));
    ids.assign(1, 3);
  };
  StreamEvaluator evaluator(kSensor, {0.01}, truth, 100'000);
  predict(evaluator, 0, 1, {moving_line(0)});
  EXPECT_THROW(evaluator.finish(), std::length_error);
}

TEST(StreamEvaluator, APredictionThatLagsOnePeriodIsScoredAgainstTheTruthOfItsStep) {
  // The prediction stamped t shows the truth of t - 10: every step compares a line with the one 2 px
  // above it, and step 0 has nothing yet.
  StreamEvaluator lagging = moving_evaluator();
  for (int k = 1; k < kGtSteps; ++k) predict(lagging, k * kGtPeriod, 7, {moving_line(static_cast<std::size_t>(k - 1))});
  lagging.finish();
  HeatmapMatcher tight(kSensor, 0.01), loose(kSensor, 0.02);
  MatchCounts expected_tight{0, 41, 0}, expected_loose{0, 41, 0};
  for (std::size_t k = 1; k < kGtSteps; ++k) {
    const std::vector<Segment> predicted = {moving_line(k - 1)}, truth = {moving_line(k)};
    expected_tight += tight.match(predicted, truth);
    expected_loose += loose.match(predicted, truth);
  }
  EXPECT_EQ(lagging.accuracy().total(0), expected_tight);
  EXPECT_EQ(lagging.accuracy().total(1), expected_loose);
  EXPECT_EQ(expected_tight.matched, 0u);
  EXPECT_EQ(expected_loose.matched, 4u * 41u);
  EXPECT_EQ(lagging.coverage().steps_without_prediction, 1u);

  // Stamped half a period late instead (t + 5 shows the truth of t): each step sees the one before.
  StreamEvaluator half_late = moving_evaluator();
  for (int k = 0; k < kGtSteps; ++k)
    predict(half_late, k * kGtPeriod + 5, 7, {moving_line(static_cast<std::size_t>(k))});
  half_late.finish();
  EXPECT_EQ(half_late.accuracy().total(0), expected_tight);
  EXPECT_EQ(half_late.accuracy().total(1), expected_loose);
  EXPECT_EQ(half_late.coverage().predicted_steps_outside, 1u);  // t = 45, after the last step
}

TEST(StreamEvaluator, PredictionsOutsideTheGroundTruthRangeAreCountedNotScored) {
  StreamEvaluator evaluator = moving_evaluator();
  predict(evaluator, -100, 1, {moving_line(0)});  // long before the first step
  for (int k = 0; k < kGtSteps; ++k) predict(evaluator, k * kGtPeriod, 2, {moving_line(static_cast<std::size_t>(k))});
  predict(evaluator, 41, 3, {row_segment(70, 0, 99)});  // after the last step
  predict(evaluator, 500, 3, {row_segment(70, 0, 99)});
  evaluator.finish();
  EXPECT_EQ(evaluator.accuracy().total(0), (MatchCounts{5 * 41, 5 * 41, 5 * 41}));
  EXPECT_EQ(evaluator.coverage().predicted_steps, 8u);
  EXPECT_EQ(evaluator.coverage().predicted_steps_scored, 5u);
  EXPECT_EQ(evaluator.coverage().predicted_steps_outside, 3u);
  EXPECT_EQ(evaluator.lifetimes().ids(), 3u);  // every predicted step counts for lifetimes
  EXPECT_THROW(evaluator.add_prediction(600, {}, {}), std::logic_error);
}

TEST(StreamEvaluator, AStallInsideTheStreamCostsRecallAndTimeMayNotGoBack) {
  StreamEvaluator evaluator = moving_evaluator();
  predict(evaluator, 0, 1, {moving_line(0)});
  predict(evaluator, 0, 1, {moving_line(0)});   // the same time again replaces the step
  predict(evaluator, 40, 1, {moving_line(4)});  // nothing for 10, 20, 30: a stall
  EXPECT_THROW(predict(evaluator, 39, 1, {}), std::invalid_argument);
  evaluator.finish();
  // Steps 0 and 40 exact; 10 holds the line of 0 (2 px off: loose tolerance only); 20 and 30 empty.
  EXPECT_EQ(evaluator.accuracy().total(0), (MatchCounts{3 * 41, 5 * 41, 2 * 41}));
  EXPECT_EQ(evaluator.accuracy().total(1), (MatchCounts{3 * 41, 5 * 41, 3 * 41}));
  EXPECT_EQ(evaluator.coverage().steps_without_prediction, 2u);
  EXPECT_EQ(evaluator.coverage().predicted_steps, 2u);
}

TEST(StreamEvaluator, MedianStepSpacingIsTheNominalOutputPeriod) {
  const std::vector<Timestamp> jittered = {0, 9, 21, 30, 30, 41, 200};
  EXPECT_EQ(median_step_spacing(jittered), 11);  // gaps 9, 12, 9, 11, 159
  EXPECT_EQ(median_step_spacing(std::vector<Timestamp>{5}), 0);
}

TEST(LifetimeTracker, StatsAndHistogram) {
  LifetimeTracker tracker;
  EXPECT_EQ(tracker.summary().count, 0u);
  EXPECT_TRUE(tracker.histogram(10).empty());
  const std::vector<std::uint64_t> first_step = {1, 3};
  tracker.observe_step(80'000, first_step);  // id 3 first seen late: order does not matter
  tracker.observe(0, 1);
  tracker.observe(10'000, 1);
  tracker.observe(5'000, 2);  // seen once: lives 0 ms
  tracker.observe(20'000, 3);
  tracker.observe(30'000, 1);
  tracker.observe(80'000, 1);  // id 1: 0 .. 80 ms
  const std::vector<IdLifetime> lifetimes = tracker.lifetimes();
  ASSERT_EQ(lifetimes.size(), 3u);
  EXPECT_EQ(lifetimes[0].id, 1u);
  EXPECT_DOUBLE_EQ(lifetimes[0].lifetime_ms(), 80.0);
  EXPECT_DOUBLE_EQ(lifetimes[1].lifetime_ms(), 0.0);
  EXPECT_EQ(lifetimes[2].first_us, 20'000);
  EXPECT_DOUBLE_EQ(lifetimes[2].lifetime_ms(), 60.0);

  const LifetimeSummary summary = tracker.summary();
  EXPECT_EQ(summary.count, 3u);
  EXPECT_DOUBLE_EQ(summary.mean_ms, 140.0 / 3.0);
  const double mean = 140.0 / 3.0;
  EXPECT_NEAR(summary.std_ms, std::sqrt(((80 - mean) * (80 - mean) + mean * mean + (60 - mean) * (60 - mean)) / 3.0),
              1e-12);
  EXPECT_DOUBLE_EQ(summary.max_ms, 80.0);

  EXPECT_EQ(tracker.histogram(25.0), (std::vector<std::uint64_t>{1, 0, 1, 1}));     // 0 | - | 60 | 80
  EXPECT_EQ(tracker.histogram(20.0), (std::vector<std::uint64_t>{1, 0, 0, 1, 1}));  // 80 opens bin 4
  EXPECT_THROW((void)tracker.histogram(0.0), std::invalid_argument);
  EXPECT_THROW((void)tracker.histogram(1e-9), std::length_error);
}

class PlotFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    directory_ = std::filesystem::temp_directory_path() /
                 ("evldt_eval_test_" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    std::filesystem::create_directories(directory_);
  }
  void TearDown() override { std::filesystem::remove_all(directory_); }

  static void expect_chart(const std::filesystem::path& path) {
    const cv::Mat image = cv::imread(path.string(), cv::IMREAD_COLOR);
    ASSERT_FALSE(image.empty()) << path;
    EXPECT_EQ(image.cols, kPlotWidth);
    EXPECT_EQ(image.rows, kPlotHeight);
    EXPECT_LT(cv::mean(image)[0], 255.0);  // something was drawn
  }

  std::filesystem::path directory_;
};

TEST_F(PlotFiles, PrCurveIsAReadablePng) {
  const std::vector<PrPoint> points = {{0.5, 0.9, 0.4, 0.0}, {0.1, 0.5, 0.85, 0.0}, {0.3, 0.75, 0.7, 0.0}};
  std::vector<PrPoint> with_f = points;
  for (PrPoint& p : with_f) p.f = 2 * p.precision * p.recall / (p.precision + p.recall);
  write_pr_curve_png(directory_ / "pr.png", with_f, "precision / recall at 1%");
  expect_chart(directory_ / "pr.png");
  write_pr_curve_png(directory_ / "empty.png", {}, "no points");
  expect_chart(directory_ / "empty.png");
}

TEST_F(PlotFiles, HistogramIsAReadablePng) {
  write_histogram_png(directory_ / "histogram.png", {4, 9, 2, 0, 1}, 20.0, "lifetimes");
  expect_chart(directory_ / "histogram.png");
  write_histogram_png(directory_ / "many.png", std::vector<std::uint64_t>(2000, 3), 0.5, "many bins");
  expect_chart(directory_ / "many.png");
  write_histogram_png(directory_ / "empty.png", {}, 1.0, "nothing");
  expect_chart(directory_ / "empty.png");
  EXPECT_THROW(write_histogram_png(directory_ / "bad.png", {1}, 0.0, "bad"), std::invalid_argument);
}

TEST_F(PlotFiles, WriteFailureNamesThePath) {
  const std::filesystem::path missing = directory_ / "no_such_dir" / "chart.png";
  try {
    write_histogram_png(missing, {1, 2}, 1.0, "x");
    FAIL() << "expected std::runtime_error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(missing.string()), std::string::npos) << e.what();
  }
  EXPECT_THROW(write_pr_curve_png(missing, {}, "x"), std::runtime_error);
}

}  // namespace
}  // namespace evldt

namespace evldt {
namespace {

double scene_f_at_1_percent(const std::string& name, Timestamp duration_us, bool filtered) {
  Scene scene = make_scene(name);
  scene.duration_us = duration_us;
  PipelineConfig config = default_config_for(scene.sensor);
  if (!filtered) config.filters.chain.clear();
  constexpr Timestamp kStepUs = 10'000;
  StreamEvaluator evaluator = make_scene_evaluator(scene, {0.01}, kStepUs);
  evaluate_scene(scene, scene_camera_model(name), config, kStepUs, evaluator);
  return evaluator.accuracy().summed_prf(0).f;
}

TEST(NoiseFilters, KeepTheAccuracyOfACleanSceneAndRecoverMostOfANoisyOnes) {
  const double clean = scene_f_at_1_percent("boxes-6dof", 1'000'000, false);
  const double clean_filtered = scene_f_at_1_percent("boxes-6dof", 1'000'000, true);
  EXPECT_GT(clean, 0.7);
  EXPECT_GE(clean_filtered, clean - 0.01);
  // The same motion seen by a sensor with 2 Hz background activity, 40 hot pixels and a wider
  // threshold spread (docs/accuracy.md, noise filters: 0.65 without filters, 0.81 with them over the
  // whole 5 s when the filters were tuned).
  const double noisy = scene_f_at_1_percent("noisy-boxes", 1'000'000, false);
  const double noisy_filtered = scene_f_at_1_percent("noisy-boxes", 1'000'000, true);
  EXPECT_LT(noisy, clean - 0.1);
  EXPECT_GT(noisy_filtered, noisy + 0.1);
}

TEST(WholeLineSupport, CountsTheLengthNearASegmentAndTheWeakLines) {
  WholeLineSupport support;                                       // 2 px, weak below 60%
  const Segment left{{0, 0}, {40, 0}}, right{{60, 1}, {100, 1}};  // two collinear edges, a 20 px gap
  // A whole line on the left edge alone, and one bridging the gap to the right edge.
  const std::vector<Segment> whole{{{0, 0}, {40, 0}}, {{0, 0.5f}, {100, 0.5f}}};
  support.add_step(whole, std::vector<Segment>{left, right});
  SupportSummary s = support.summary();
  EXPECT_EQ(s.steps, 1u);
  EXPECT_EQ(s.lines, 2u);
  EXPECT_NEAR(s.length_px, 140, 1e-3);
  // The bridge: 84 of its 100 px lie within 2 px of an edge (80 along them, about 2 px into the gap at each end).
  EXPECT_NEAR(s.supported_share, (40 + 84) / 140.0, 0.02);
  EXPECT_EQ(s.weak_lines, 0u);

  // A line that cuts across, far from both edges, is unsupported and weak; the figures accumulate.
  const std::vector<Segment> diagonal{{{0, 30}, {100, 60}}};
  support.add_step(diagonal, std::vector<Segment>{left, right});
  s = support.summary();
  EXPECT_EQ(s.steps, 2u);
  EXPECT_EQ(s.weak_lines, 1u);
  EXPECT_NEAR(s.weak_share, 1.0 / 3.0, 1e-9);
  EXPECT_LT(s.supported_share, (40 + 84) / 140.0);

  EXPECT_TRUE(std::isnan(WholeLineSupport().summary().supported_share));  // no lines: no share
  EXPECT_THROW(WholeLineSupport(-1.0f), std::invalid_argument);
  EXPECT_THROW(WholeLineSupport(2.0f, 1.5f), std::invalid_argument);
}

// Recall per true edge (--edge-recall): a line moving down 2 px a step, found at every step, and a
// still one 30-20 px below it, never found.
TEST(EdgeRecall, CountsEachEdgesPixelsAndMatchesWithItsSpeedAndParallelGap) {
  GroundTruthSteps truth = moving_truth();
  truth.segments_at = [](std::size_t index, std::vector<Segment>& segments, std::vector<std::uint64_t>& ids) {
    segments = {moving_line(index), row_segment(40, 10, 30)};
    ids = {3, 7};
  };
  StreamEvaluator evaluator(kSensor, {0.01}, truth, std::llround(StreamEvaluator::kHoldPeriods * kGtPeriod));
  evaluator.keep_edge_recall(/*picture_at_us=*/15);
  for (int k = 0; k < kGtSteps; ++k) predict(evaluator, k * kGtPeriod, 1, {moving_line(static_cast<std::size_t>(k))});
  evaluator.finish();
  ASSERT_TRUE(evaluator.edge_recall());
  const std::vector<EdgeStep>& steps = evaluator.edge_recall()->steps();
  ASSERT_EQ(steps.size(), 2u * kGtSteps);
  for (int k = 0; k < kGtSteps; ++k) {
    const EdgeStep& moving = steps[2 * static_cast<std::size_t>(k)];
    const EdgeStep& still = steps[2 * static_cast<std::size_t>(k) + 1];
    EXPECT_EQ(moving.id, 3u);
    EXPECT_EQ(moving.pixels, 41u);
    EXPECT_EQ(moving.matched, 41u);
    EXPECT_EQ(still.id, 7u);
    EXPECT_EQ(still.pixels, 21u);
    EXPECT_EQ(still.matched, 0u);
    EXPECT_FLOAT_EQ(moving.parallel_gap_px, static_cast<float>(30 - 2 * k));
    EXPECT_FLOAT_EQ(still.parallel_gap_px, static_cast<float>(30 - 2 * k));
    if (k == 0) {
      EXPECT_TRUE(std::isnan(moving.normal_speed_px_s));  // no step before
      EXPECT_TRUE(std::isnan(still.normal_speed_px_s));
    } else {
      EXPECT_NEAR(moving.normal_speed_px_s, 2.0f / (kGtPeriod * 1e-6f), 1.0f);  // 2 px in 10 us
      EXPECT_EQ(still.normal_speed_px_s, 0.0f);
    }
  }
  const double edges[] = {0, 1, std::numeric_limits<double>::infinity()};
  const auto bins = bin_edge_recall(steps, EdgeMeasure::NormalSpeed, edges);
  ASSERT_EQ(bins.size(), 2u);
  EXPECT_EQ(bins[0].pixels, 21u * (kGtSteps - 1));  // the first step has no speed, so no bin
  EXPECT_EQ(bins[0].matched, 0u);
  EXPECT_EQ(bins[1].pixels, 41u * (kGtSteps - 1));
  EXPECT_EQ(bins[1].matched, 41u * (kGtSteps - 1));
  const std::string csv = edge_recall_csv_rows("run", steps);
  EXPECT_NE(csv.find("run,0,3,40.000,,30.000,41,41\n"), std::string::npos) << csv;
  EXPECT_NE(edge_recall_tables(steps).find("speed across itself"), std::string::npos);

  // The picture is of the first step at or after 15 us: both edges, the prediction, the matches.
  const auto& picture = evaluator.edge_recall()->picture();
  ASSERT_TRUE(picture);
  EXPECT_EQ(picture->t_us, 2 * kGtPeriod);
  EXPECT_EQ(picture->truth.size(), 2u);
  ASSERT_EQ(picture->predicted.size(), 1u);
  EXPECT_EQ(picture->predicted[0].q0, moving_line(2).q0);
  const auto matched_at = [&](int x, int y) {
    return picture->matched_map[static_cast<std::size_t>(y) * kWidth + static_cast<std::size_t>(x)];
  };
  EXPECT_EQ(matched_at(20, 14), 1);  // on the found line (y = 10 + 2 * 2)
  EXPECT_EQ(matched_at(20, 40), 0);  // on the missed one
  const auto path = std::filesystem::temp_directory_path() / "evldt_edge_recall_test.png";
  write_edge_recall_png(path, *evaluator.edge_recall(), "test", 2);
  const cv::Mat image = cv::imread(path.string());
  std::filesystem::remove(path);
  ASSERT_FALSE(image.empty());
  EXPECT_EQ(image.cols, 2 * kSensor.width);
  const cv::Vec3b missed = image.at<cv::Vec3b>(image.rows - 2 * kSensor.height + 2 * 40, 2 * 20);
  EXPECT_GT(missed[2], 200);  // red (BGR)
  EXPECT_LT(missed[1], 100);

  StreamEvaluator without_picture(kSensor, {0.01}, truth, 15);
  without_picture.keep_edge_recall();
  without_picture.finish();
  EXPECT_THROW(write_edge_recall_png(path, *without_picture.edge_recall(), "none"), std::runtime_error);
}

}  // namespace
}  // namespace evldt
