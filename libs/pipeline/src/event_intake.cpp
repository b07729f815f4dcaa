#include "evldt/pipeline/event_intake.hpp"

namespace evldt {

EventIntake::EventIntake(const PipelineConfig& config, std::size_t prepared_batch)
    : filters_(config.filters, config.lattice.sensor) {
  if (!filters_.empty()) filtered_.reserve_touched(prepared_batch);
  if (config.rectification) {
    rectifier_.emplace(*config.rectification);
    rectified_.reserve_touched(prepared_batch);
  }
}

const EventBatch& EventIntake::pass_filters(const EventBatch& batch) {
  if (filters_.empty()) return batch;  // no copy
  filters_.filter(batch, filtered_);
  return filtered_;
}

void EventIntake::filter(const EventBatch& batch, EventBatch& filtered) {
  if (filters_.empty()) {
    filtered = batch;
  } else {
    filters_.filter(batch, filtered);
  }
}

const EventBatch& EventIntake::rectify(const EventBatch& filtered) {
  if (!rectifier_) return filtered;
  rectifier_->apply(filtered, rectified_);
  return rectified_;
}

}  // namespace evldt
