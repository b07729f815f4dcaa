#pragma once
// What a batch goes through before storage, in both pipelines and in evldt-bench: the noise
// filters, which work on sensor pixels, then, with a calibration, the move into the rectified image
// (where the lattice and the lines live). Storing stays with each pipeline, since where a batch is
// cut into runs depends on its round schedule.

#include <cstdint>
#include <optional>
#include <span>

#include "evldt/calibration/rectifier.hpp"
#include "evldt/events/event.hpp"
#include "evldt/filters/filter_chain.hpp"
#include "evldt/pipeline/pipeline_config.hpp"

namespace evldt {

class EventIntake {
 public:
  /// The filters and calibration of `config`; buffers for batches of up to `prepared_batch` events
  /// are reserved, so those pass without growing one.
  explicit EventIntake(const PipelineConfig& config, std::size_t prepared_batch = 0);

  /// The events of `batch` (on-sensor, in time order) to store: `batch` itself where there is
  /// nothing to do, else a buffer of this intake's, valid until its next call.
  const EventBatch& prepare(const EventBatch& batch) { return rectify(pass_filters(batch)); }

  /// prepare() in two steps, the first of which may run on another thread into the caller's buffer
  /// (it touches only the filters' state): called in the same order, they store what prepare() does.
  void filter(const EventBatch& batch, EventBatch& filtered);
  const EventBatch& rectify(const EventBatch& filtered);

  [[nodiscard]] const FilterChain& filters() const { return filters_; }
  [[nodiscard]] FilterCounts filter_counts() const { return filters_.counts(); }
  [[nodiscard]] std::span<const std::uint32_t> masked_pixels() const { return filters_.masked_pixels(); }
  /// With a calibration: events left out so far, their pixel feeds no rectified pixel.
  [[nodiscard]] std::uint64_t off_rectified() const { return rectifier_ ? rectifier_->dropped() : 0; }

 private:
  const EventBatch& pass_filters(const EventBatch& batch);

  FilterChain filters_;
  EventBatch filtered_;  // what passed the filters, reused
  std::optional<Rectifier> rectifier_;
  EventBatch rectified_;  // what passed, in the rectified image, reused
};

}  // namespace evldt
