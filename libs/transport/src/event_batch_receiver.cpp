#include "evldt/transport/event_batch_receiver.hpp"

#include <spdlog/spdlog.h>
#include <bit>
#include <utility>

namespace evldt {

EventBatchReceiver::EventBatchReceiver(std::optional<SensorSize> sensor, Timestamp backwards_slack_us,
                                       SensorCheck usable)
    : sensor_(sensor), slack_(backwards_slack_us), usable_(std::move(usable)) {
  if (sensor_) validator_.emplace(*sensor_, slack_);
}

void EventBatchReceiver::refuse(const char* why) {
  if (std::has_single_bit(++invalid_)) spdlog::warn("refused {} event message(s) (latest: {})", invalid_, why);
}

bool EventBatchReceiver::receive(std::span<const std::uint8_t> payload, EventBatch& out) {
  return receive_every(payload, out, 1);
}

bool EventBatchReceiver::receive_every(std::span<const std::uint8_t> payload, EventBatch& out, std::size_t stride) {
  shed_ = false;
  stride_ = 1;
  if (const WireError error = decode_event_batch(payload, message_, out, stride); error != WireError::None) {
    out.clear();
    refuse(error == WireError::WrongType ? "not an evldt event_batch_t" : "malformed event_batch_t");
    return false;
  }
  if (!admit()) {
    out.clear();
    return false;
  }
  const std::uint64_t clock_resets_before = validator_->drops().clock_resets;
  if (stride > 1) {
    stride_ = static_cast<int>(stride);
    ++batches_thinned_;
    events_shed_ += static_cast<std::uint64_t>(message_.num_events) - out.size();
  }
  validator_->filter(out);
  // A clock that went back is a restart for the subscriber as well: its state belongs to the old clock.
  if (validator_->drops().clock_resets != clock_resets_before) restarted_ = true;
  return true;
}

bool EventBatchReceiver::receive(std::span<const std::uint8_t> payload, EventBatch& out, LatencyBudget& budget,
                                 std::int64_t now_utime) {
  Timestamp last_event_us = 0;
  if (decode_event_batch_header(payload, message_, last_event_us) != WireError::None) {
    return receive(payload, out);  // refused there, with its reason
  }
  if (const int stride = budget.stride(message_.utime, now_utime); stride > 0) {
    return receive_every(payload, out, static_cast<std::size_t>(stride));
  }
  out.clear();
  shed_ = false;
  stride_ = 1;
  if (!admit()) return false;
  shed_ = true;
  shed_until_us_ = last_event_us;
  ++batches_shed_;
  events_shed_ += static_cast<std::uint64_t>(message_.num_events);
  return true;
}

bool EventBatchReceiver::admit() {
  const SensorSize size{message_.width, message_.height};
  if (!size.valid()) {
    refuse("invalid sensor size");
    return false;
  }
  if (sensor_ && size != *sensor_) {
    refuse("sensor size differs from the stream's");
    return false;
  }
  if (!sensor_ && usable_ && !usable_(size)) {
    refuse("sensor size this subscriber cannot work with");
    return false;
  }
  const SequenceCounts before = sequence_.counts();
  if (!sequence_.observe(message_.epoch, message_.seq)) return false;
  restarted_ = sequence_.counts().restarts != before.restarts;
  if (const std::uint64_t lost = sequence_.counts().lost; std::bit_floor(lost) > before.lost) {
    // Batches the network or this host dropped before they were read (a socket buffer overflowing
    // while the host was busy, most often): the lattice missed their events.
    spdlog::warn(
        "lost {} event batch(es) in all (sequence gaps; latest before seq {}): is net.core.rmem_max at least "
        "8 MiB (deploy/README.md)?",
        lost, message_.seq);
  }
  if (!sensor_) sensor_ = size;
  if (!validator_ || restarted_) {
    // A restarted camera's clock may begin again: judge its time order afresh.
    if (validator_) {
      drops_before_restart_.off_sensor += validator_->drops().off_sensor;
      drops_before_restart_.time_backwards += validator_->drops().time_backwards;
      drops_before_restart_.clock_resets += validator_->drops().clock_resets;
    }
    validator_.emplace(*sensor_, slack_);
  }
  return true;
}

ReceiverCounts EventBatchReceiver::counts() const {
  ReceiverCounts counts;
  counts.invalid_messages = invalid_;
  counts.sequence = sequence_.counts();
  counts.drops = drops_before_restart_;
  counts.batches_shed = batches_shed_;
  counts.batches_thinned = batches_thinned_;
  counts.events_shed = events_shed_;
  if (validator_) {
    counts.drops.off_sensor += validator_->drops().off_sensor;
    counts.drops.time_backwards += validator_->drops().time_backwards;
    counts.drops.clock_resets += validator_->drops().clock_resets;
  }
  return counts;
}

}  // namespace evldt
