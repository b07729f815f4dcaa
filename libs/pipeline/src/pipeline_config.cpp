#include "evldt/pipeline/pipeline_config.hpp"

#include <array>
#include <cstdlib>

namespace evldt {

PipelineConfig default_config_for(SensorSize sensor) {
  struct Row {
    int width;
    int block_size;
    float perturbation_px;
  };
  // docs/configuration.md; dq scales with width from the closest row.
  constexpr std::array<Row, 4> rows{{{240, 8, 0.8f}, {346, 8, 1.1f}, {640, 14, 2.5f}, {1280, 14, 2.5f}}};
  const Row* best = &rows[0];
  for (const Row& row : rows) {
    if (std::abs(row.width - sensor.width) < std::abs(best->width - sensor.width)) best = &row;
  }
  PipelineConfig config;
  config.lattice.sensor = sensor;
  config.lattice.block_size = best->block_size;
  // 1280x720 keeps 640x480's dq in the table: scaling applies only between the listed sizes.
  const float scale = best->width == 1280 ? 1.0f : static_cast<float>(sensor.width) / static_cast<float>(best->width);
  config.track.perturbation_px = best->perturbation_px * scale;
  return config;
}

}  // namespace evldt
