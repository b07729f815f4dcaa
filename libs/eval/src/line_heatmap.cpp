#include "evldt/eval/line_heatmap.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <functional>
#include <limits>
#include <stdexcept>
#include <string>

namespace evldt {

namespace {

constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();

std::size_t pixel_count(SensorSize sensor) {
  return static_cast<std::size_t>(sensor.width) * static_cast<std::size_t>(sensor.height);
}

/// Liang-Barsky clipping of p0 + t * d, t in [t0, t1], to the sensor rectangle. Only segments that
/// reach off the sensor change, and they would lose those samples anyway; clipping first bounds the
/// number of samples by the sensor diagonal whatever the input.
bool clip_to_sensor(double p0x, double p0y, double dx, double dy, SensorSize sensor, double& t0, double& t1) {
  const double p[4] = {-dx, dx, -dy, dy};
  const double q[4] = {p0x, sensor.width - p0x, p0y, sensor.height - p0y};
  for (int i = 0; i < 4; ++i) {
    if (p[i] == 0) {
      if (q[i] < 0) return false;
      continue;
    }
    const double t = q[i] / p[i];
    if (p[i] < 0) {
      t0 = std::max(t0, t);
    } else {
      t1 = std::min(t1, t);
    }
  }
  return t0 <= t1;
}

void check_map_size(std::span<const std::uint8_t> map, SensorSize sensor, const char* which) {
  if (map.size() != pixel_count(sensor)) {
    throw std::invalid_argument(std::string(which) + " map has " + std::to_string(map.size()) + " pixels, sensor has " +
                                std::to_string(pixel_count(sensor)));
  }
}

/// Calls visit(x, y) for each non-zero pixel in row-major order. Line maps are mostly empty, so
/// eight bytes are tested at once.
template <typename Visit>
void for_each_line_pixel(std::span<const std::uint8_t> map, int width, Visit visit) {
  for (std::size_t start = 0; start < map.size(); start += 8) {
    const std::size_t end = std::min(start + 8, map.size());
    if (end - start == 8) {
      std::uint64_t word = 0;
      std::memcpy(&word, map.data() + start, sizeof word);
      if (word == 0) continue;
    }
    for (std::size_t i = start; i < end; ++i) {
      if (map[i] != 0) visit(static_cast<int>(i % width), static_cast<int>(i / width));
    }
  }
}

}  // namespace

std::optional<Segment> clipped_to_sensor(const Segment& s, SensorSize sensor) {
  if (!s.q0.allFinite() || !s.q1.allFinite()) return std::nullopt;
  const double x0 = s.q0.x(), y0 = s.q0.y();
  const double dx = static_cast<double>(s.q1.x()) - x0, dy = static_cast<double>(s.q1.y()) - y0;
  double t0 = 0, t1 = 1;
  if (!clip_to_sensor(x0, y0, dx, dy, sensor, t0, t1)) return std::nullopt;
  return Segment{Point2(static_cast<float>(x0 + t0 * dx), static_cast<float>(y0 + t0 * dy)),
                 Point2(static_cast<float>(x0 + t1 * dx), static_cast<float>(y0 + t1 * dy))};
}

void for_each_segment_sample(const Segment& s, SensorSize sensor, const std::function<void(int x, int y)>& visit) {
  if (!s.q0.allFinite() || !s.q1.allFinite()) return;
  const double x0 = s.q0.x(), y0 = s.q0.y();
  const double dx = static_cast<double>(s.q1.x()) - x0, dy = static_cast<double>(s.q1.y()) - y0;
  double t0 = 0, t1 = 1;
  if (!clip_to_sensor(x0, y0, dx, dy, sensor, t0, t1)) return;
  const double length = std::hypot(dx, dy) * (t1 - t0);
  const int steps = std::max(1, static_cast<int>(std::ceil(length / kRasterStepPx)));
  for (int i = 0; i <= steps; ++i) {
    const double t = t0 + (t1 - t0) * i / steps;
    const double x = std::floor(x0 + t * dx), y = std::floor(y0 + t * dy);
    // Compared as doubles first so that the int conversion below is always in range.
    if (x < 0 || y < 0 || x >= sensor.width || y >= sensor.height) continue;
    visit(static_cast<int>(x), static_cast<int>(y));
  }
}

void rasterise(std::span<const Segment> segments, SensorSize sensor, std::vector<std::uint8_t>& map) {
  map.assign(pixel_count(sensor), 0);
  const auto width = static_cast<std::size_t>(sensor.width);
  for (const Segment& s : segments) {
    for_each_segment_sample(
        s, sensor, [&](int x, int y) { map[static_cast<std::size_t>(y) * width + static_cast<std::size_t>(x)] = 1; });
  }
}

Prf prf(const MatchCounts& counts) {
  const auto ratio = [](std::uint64_t numerator, std::uint64_t denominator) {
    return denominator == 0 ? std::numeric_limits<double>::quiet_NaN()
                            : static_cast<double>(numerator) / static_cast<double>(denominator);
  };
  return {ratio(counts.matched, counts.predicted), ratio(counts.matched, counts.ground_truth),
          ratio(2 * counts.matched, counts.predicted + counts.ground_truth)};
}

double diagonal_tolerance_px(SensorSize sensor, double tolerance_fraction) {
  return tolerance_fraction * std::hypot(static_cast<double>(sensor.width), static_cast<double>(sensor.height));
}

HeatmapMatcher::HeatmapMatcher(SensorSize sensor, double tolerance_fraction) : sensor_(sensor) {
  if (!sensor.valid()) {
    throw std::invalid_argument("invalid sensor size " + std::to_string(sensor.width) + "x" +
                                std::to_string(sensor.height));
  }
  if (!std::isfinite(tolerance_fraction) || tolerance_fraction < 0) {
    throw std::invalid_argument("tolerance fraction must be finite and >= 0, got " +
                                std::to_string(tolerance_fraction));
  }
  tolerance_px_ = diagonal_tolerance_px(sensor, tolerance_fraction);
  // Pixel distances are square roots of integers: compare squares, exactly, as integers. No pixel
  // pair is further apart than the diagonal, which also keeps the casts in range.
  const double diagonal_squared =
      static_cast<double>(sensor.width) * sensor.width + static_cast<double>(sensor.height) * sensor.height;
  max_distance_squared_ =
      static_cast<std::int64_t>(std::min(std::floor(tolerance_px_ * tolerance_px_), diagonal_squared));
  // Cells no smaller than the radius (one cell is the whole sensor at most), but not so small that
  // a tiny radius makes a huge grid.
  cell_size_ = static_cast<int>(
      std::min(std::max(std::ceil(tolerance_px_), 4.0), static_cast<double>(std::max(sensor.width, sensor.height))));
  cell_columns_ = (sensor.width + cell_size_ - 1) / cell_size_;
  cell_rows_ = (sensor.height + cell_size_ - 1) / cell_size_;
  cell_start_.resize(static_cast<std::size_t>(cell_columns_) * cell_rows_ + 1);
}

MatchCounts HeatmapMatcher::match(std::span<const Segment> predicted, std::span<const Segment> ground_truth) {
  rasterise(predicted, sensor_, predicted_map_);
  rasterise(ground_truth, sensor_, ground_truth_map_);
  return match_maps(predicted_map_, ground_truth_map_);
}

void HeatmapMatcher::matched_ground_truth(std::vector<std::uint8_t>& map) const {
  map.assign(pixel_count(sensor_), 0);
  for (std::size_t i = 0; i < bucketed_.size(); ++i) {
    if (mate_of_ground_truth_[i] == kNone) continue;
    map[static_cast<std::size_t>(bucketed_[i].y) * static_cast<std::size_t>(sensor_.width) +
        static_cast<std::size_t>(bucketed_[i].x)] = 1;
  }
}

void HeatmapMatcher::matched_predicted(std::span<const std::uint8_t> predicted_map,
                                       std::vector<std::uint8_t>& map) const {
  check_map_size(predicted_map, sensor_, "predicted");
  map.assign(pixel_count(sensor_), 0);
  // The predicted pixels were numbered in the order for_each_line_pixel visits them.
  std::uint32_t u = 0;
  for_each_line_pixel(predicted_map, sensor_.width, [&](int x, int y) {
    if (u < mate_of_predicted_.size() && mate_of_predicted_[u] != kNone) {
      map[static_cast<std::size_t>(y) * static_cast<std::size_t>(sensor_.width) + static_cast<std::size_t>(x)] = 1;
    }
    ++u;
  });
}

MatchCounts HeatmapMatcher::match_maps(std::span<const std::uint8_t> predicted_map,
                                       std::span<const std::uint8_t> ground_truth_map) {
  check_map_size(predicted_map, sensor_, "predicted");
  check_map_size(ground_truth_map, sensor_, "ground-truth");
  bucket_ground_truth(ground_truth_map);
  build_graph_and_match_greedily(predicted_map);
  const std::size_t predicted = first_neighbour_.size() - 1;
  const std::size_t ground_truth = bucketed_.size();

  layer_.resize(predicted);
  next_edge_.resize(predicted);
  // Each phase augments along a maximal set of shortest augmenting paths; none left means maximum.
  while (layer_from_free_predictions()) {
    std::copy(first_neighbour_.begin(), first_neighbour_.end() - 1, next_edge_.begin());
    for (std::uint32_t u = 0; u < predicted; ++u) {
      if (mate_of_predicted_[u] == kNone && layer_[u] == 0) augment_from(u);
    }
  }
  return {predicted, ground_truth, matched_};
}

void HeatmapMatcher::bucket_ground_truth(std::span<const std::uint8_t> ground_truth_map) {
  ground_truth_.clear();
  for_each_line_pixel(ground_truth_map, sensor_.width, [this](int x, int y) {
    ground_truth_.push_back({x, y, cell_of(x, y)});
  });
  // Counting sort by cell, stable, so each cell keeps row-major order.
  std::fill(cell_start_.begin(), cell_start_.end(), 0u);
  for (const Pixel& p : ground_truth_) ++cell_start_[p.cell + 1];
  for (std::size_t c = 1; c < cell_start_.size(); ++c) cell_start_[c] += cell_start_[c - 1];
  bucketed_.resize(ground_truth_.size());
  // cell_start_[c] serves as the fill position of cell c, and ends up at the start of cell c + 1 ...
  for (const Pixel& p : ground_truth_) bucketed_[cell_start_[p.cell]++] = p;
  // ... so shifting it up by one cell restores the starts.
  std::copy_backward(cell_start_.begin(), cell_start_.end() - 1, cell_start_.end());
  cell_start_[0] = 0;
}

void HeatmapMatcher::build_graph_and_match_greedily(std::span<const std::uint8_t> predicted_map) {
  first_neighbour_.clear();
  neighbours_.clear();
  mate_of_predicted_.clear();
  mate_of_ground_truth_.assign(bucketed_.size(), kNone);
  matched_ = 0;
  for_each_line_pixel(predicted_map, sensor_.width, [this](int x, int y) {
    const auto u = static_cast<std::uint32_t>(first_neighbour_.size());
    first_neighbour_.push_back(static_cast<std::uint32_t>(neighbours_.size()));
    // The greedy start pairs each pixel, in row-major order, with its nearest free neighbour; it
    // leaves Hopcroft-Karp few phases.
    std::uint32_t nearest_free = kNone;
    std::int64_t nearest_distance_squared = std::numeric_limits<std::int64_t>::max();
    const int cx = x / cell_size_, cy = y / cell_size_;
    for (int ny = std::max(0, cy - 1); ny <= std::min(cell_rows_ - 1, cy + 1); ++ny) {
      for (int nx = std::max(0, cx - 1); nx <= std::min(cell_columns_ - 1, cx + 1); ++nx) {
        const std::size_t cell = static_cast<std::size_t>(ny) * cell_columns_ + nx;
        for (std::uint32_t g = cell_start_[cell]; g < cell_start_[cell + 1]; ++g) {
          const std::int64_t dx = bucketed_[g].x - x, dy = bucketed_[g].y - y;
          const std::int64_t distance_squared = dx * dx + dy * dy;
          if (distance_squared > max_distance_squared_) continue;
          neighbours_.push_back(g);
          if (distance_squared < nearest_distance_squared && mate_of_ground_truth_[g] == kNone) {
            nearest_free = g;
            nearest_distance_squared = distance_squared;
          }
        }
      }
    }
    mate_of_predicted_.push_back(nearest_free);
    if (nearest_free != kNone) {
      mate_of_ground_truth_[nearest_free] = u;
      ++matched_;
    }
  });
  first_neighbour_.push_back(static_cast<std::uint32_t>(neighbours_.size()));
}

bool HeatmapMatcher::layer_from_free_predictions() {
  // Breadth-first from all free predicted pixels along alternating paths; free_layer_ is the
  // length (in predicted pixels) of the shortest augmenting paths.
  queue_.clear();
  const std::size_t predicted = mate_of_predicted_.size();
  for (std::uint32_t u = 0; u < predicted; ++u) {
    if (mate_of_predicted_[u] == kNone) {
      layer_[u] = 0;
      queue_.push_back(u);
    } else {
      layer_[u] = kNone;
    }
  }
  free_layer_ = kNone;
  for (std::size_t head = 0; head < queue_.size(); ++head) {
    const std::uint32_t u = queue_[head];
    if (layer_[u] >= free_layer_) break;  // deeper layers cannot be on a shortest path
    for (std::uint32_t e = first_neighbour_[u]; e < first_neighbour_[u + 1]; ++e) {
      const std::uint32_t w = mate_of_ground_truth_[neighbours_[e]];
      if (w == kNone) {
        free_layer_ = std::min(free_layer_, layer_[u] + 1);
      } else if (layer_[w] == kNone) {
        layer_[w] = layer_[u] + 1;
        queue_.push_back(w);
      }
    }
  }
  return free_layer_ != kNone;
}

void HeatmapMatcher::augment_from(std::uint32_t root) {
  // Depth-first along the layers with an explicit stack (paths can be thousands of pixels long).
  // next_edge_ persists through the phase, so edges that led nowhere are not tried again in it.
  path_.clear();
  path_.push_back(root);
  while (!path_.empty()) {
    const std::uint32_t u = path_.back();
    if (next_edge_[u] == first_neighbour_[u + 1]) {
      layer_[u] = kNone;  // dead end for the rest of this phase
      path_.pop_back();
      if (!path_.empty()) ++next_edge_[path_.back()];
      continue;
    }
    const std::uint32_t w = mate_of_ground_truth_[neighbours_[next_edge_[u]]];
    if (w == kNone && layer_[u] + 1 == free_layer_) {
      // Flip the path: each predicted pixel on it takes the ground-truth pixel its edge points at.
      for (const std::uint32_t p : path_) {
        const std::uint32_t g = neighbours_[next_edge_[p]];
        mate_of_predicted_[p] = g;
        mate_of_ground_truth_[g] = p;
      }
      ++matched_;
      return;
    }
    if (w != kNone && layer_[w] == layer_[u] + 1) {
      path_.push_back(w);
    } else {
      ++next_edge_[u];
    }
  }
}

}  // namespace evldt
