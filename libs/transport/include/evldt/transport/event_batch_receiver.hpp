#pragma once
// The receiving end of an event channel, shared by every subscriber (lines, viz, lcm-log reader):
// every payload is decoded with checks, its sensor size compared, its sequence number accounted and
// its events validated. Whatever is refused is counted and logged, never fatal.

#include <cstdint>
#include <functional>
#include <optional>
#include <span>

#include "evldt/events/event_validator.hpp"
#include "evldt/transport/latency_budget.hpp"
#include "evldt/transport/messages.hpp"
#include "evldt/transport/sequence_tracker.hpp"

namespace evldt {

struct ReceiverCounts {
  std::uint64_t invalid_messages = 0;  ///< undecodable (time base out of range included), foreign type, bad sensor size
  SequenceCounts sequence;
  DropCounts drops;                   ///< events refused by the validator (before a restart included)
  std::uint64_t batches_shed = 0;     ///< valid, current batches that came later than the latency budget
  std::uint64_t batches_thinned = 0;  ///< valid, current batches that queued, of which only a share was decoded
  std::uint64_t events_shed = 0;      ///< events of both not decoded nor validated (shed or thinned out)
};

class EventBatchReceiver {
 public:
  /// Whether the subscriber can work with a sensor of that size (e.g. its lattice fits).
  using SensorCheck = std::function<bool(SensorSize)>;

  /// `sensor`: the size batches must have; unset: the first valid batch's size is adopted, if
  /// `usable` (when given) accepts it. Sizes outside 1..kMaxSensorSide are always refused.
  EventBatchReceiver(std::optional<SensorSize> sensor, Timestamp backwards_slack_us, SensorCheck usable = {});

  /// Decodes `payload`; if it is a valid, current batch, fills `out` (cleared) with its valid
  /// events and returns true (`out` may then be empty). A batch of a newer publisher epoch
  /// restarts the time-order check (restarted() tells).
  bool receive(std::span<const std::uint8_t> payload, EventBatch& out);
  /// As receive(), with the events of a valid, current batch that queued (as `budget` judges it at
  /// `now_utime`) thinned: only every stride-th is decoded (thinned() tells); one that queued past
  /// the budget is shed: accounted (sequence, sensor, counts) without decoding its events, `out` is
  /// left empty and shed() tells. Both cost only what is kept, so a subscriber behind catches up.
  bool receive(std::span<const std::uint8_t> payload, EventBatch& out, LatencyBudget& budget, std::int64_t now_utime);

  /// Header of the last accepted batch (its arrays are empty: the events went to `out`).
  [[nodiscard]] const event_batch_t& message() const { return message_; }
  [[nodiscard]] std::optional<SensorSize> sensor() const { return sensor_; }
  /// True if the last accepted batch started a new publisher epoch (not for the first batch), or its
  /// events made the validator follow a clock that went back.
  [[nodiscard]] bool restarted() const { return restarted_; }
  /// True if the last accepted batch was shed; shed_until_us() is then the time of its last event.
  [[nodiscard]] bool shed() const { return shed_; }
  [[nodiscard]] Timestamp shed_until_us() const { return shed_until_us_; }
  /// True if only a share of the last accepted batch's events was decoded (it had queued).
  [[nodiscard]] bool thinned() const { return stride_ > 1; }
  /// Of the last accepted batch, every stride()-th event was decoded (1: all of them).
  [[nodiscard]] int stride() const { return stride_; }
  [[nodiscard]] ReceiverCounts counts() const;

 private:
  void refuse(const char* why);
  bool receive_every(std::span<const std::uint8_t> payload, EventBatch& out, std::size_t stride);
  /// The checks of a decoded header (sensor size, sequence); restarts the validator with the stream.
  bool admit();

  std::optional<SensorSize> sensor_;
  Timestamp slack_;
  SensorCheck usable_;
  std::optional<EventValidator> validator_;
  DropCounts drops_before_restart_;
  SequenceTracker sequence_;
  std::uint64_t invalid_ = 0;
  event_batch_t message_;
  bool restarted_ = false;
  bool shed_ = false;
  int stride_ = 1;
  Timestamp shed_until_us_ = 0;
  std::uint64_t batches_shed_ = 0, batches_thinned_ = 0, events_shed_ = 0;
};

}  // namespace evldt
