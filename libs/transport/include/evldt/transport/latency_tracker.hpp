#pragma once
// End-to-end latency of the lines service: from an event batch's publish (camera wall clock) to the
// publish of the first segment list whose lattice state holds all its events. Where the publish
// stamps are far from this host's clock (a log replayed by lcm-logplayer keeps the recording's; a
// camera host's clock may be set apart), the latency is measured from the batch's receipt instead:
// from the stamps it would read as lag that is not there. Fixed memory: a ring
// of batches waiting to be included and a bounded sample store per reporting period. The run's
// figures are kept twice: from the stream's start, and once it has settled (batches published a
// second or more after its first), since a stream's first tens of milliseconds meet cold caches and
// a lattice filling at once (measured: rounds of 5-19 ms instead of 1-2 ms at 1280x720).

#include <cstdint>
#include <optional>
#include <vector>

#include "evldt/events/event.hpp"

namespace evldt {

struct LatencySummary {
  std::uint32_t samples = 0;
  double median_ms = 0;
  double p99_ms = 0;
};

/// Latencies in ms: a store of the current period's (bounded) and a histogram of the whole run.
class LatencyStatistics {
 public:
  explicit LatencyStatistics(std::size_t sample_capacity = 65536);
  void add(double latency_ms);
  /// Median and p99 of the latencies added since the previous call.
  LatencySummary take_summary();
  /// Median and p99 since construction, to 0.1 ms (a histogram; latencies above 1 s count as 1 s).
  [[nodiscard]] LatencySummary run_summary() const;

 private:
  std::vector<double> samples_ms_;
  std::size_t sample_capacity_;
  static constexpr double kBinMs = 0.1;
  std::vector<std::uint64_t> run_histogram_;  ///< bins of kBinMs up to 1 s
  std::uint64_t run_samples_ = 0;
};

class LatencyTracker {
 public:
  /// `pending_capacity`: batches that may wait for a list (the oldest is forgotten beyond it);
  /// `sample_capacity`: latencies kept per period (later ones in the period are not kept).
  explicit LatencyTracker(std::size_t pending_capacity = 16384, std::size_t sample_capacity = 65536);

  /// A batch was stored: its sequence number, publish wall clock (the sender's), receipt wall clock
  /// (ours) and newest event time.
  void batch_stored(std::int64_t seq, std::int64_t publish_utime, std::int64_t received_utime,
                    Timestamp newest_event_us);

  struct Included {
    std::int64_t seq = -1;   ///< newest batch included so far (-1: none yet)
    std::int64_t utime = 0;  ///< its publish wall clock
  };
  /// A segment list of lattice time `lattice_us` is published at `now_utime`: records the latency
  /// of every waiting batch it includes and returns the newest batch included so far.
  Included list_published(Timestamp lattice_us, std::int64_t now_utime);

  /// Median and p99 of the latencies recorded since the previous call.
  LatencySummary take_summary() { return statistics_.take_summary(); }
  /// Median and p99 since construction, to 0.1 ms (a histogram; latencies above 1 s count as 1 s).
  [[nodiscard]] LatencySummary run_summary() const { return statistics_.run_summary(); }
  /// As run_summary(), of the batches published kSettleUs or more after the first one stored.
  [[nodiscard]] LatencySummary settled_summary() const { return settled_.run_summary(); }
  static constexpr std::int64_t kSettleUs = 1'000'000;

  /// The publish clock's offset: the least (receipt - publish) over the last one to two windows,
  /// transit plus how far the sender's clock is behind ours; none before the first batch.
  [[nodiscard]] std::optional<std::int64_t> publish_clock_offset_us() const;
  /// Batches whose latency was measured from their receipt, since the offset was beyond
  /// kClocksApartUs either way.
  [[nodiscard]] std::uint64_t measured_from_receipt() const { return from_receipt_; }
  /// Transit on a network, and a camera's clock kept by NTP, are far below this.
  static constexpr std::int64_t kClocksApartUs = 50'000;
  static constexpr std::int64_t kOffsetWindowUs = 2'000'000;

 private:
  struct Pending {
    std::int64_t seq;
    std::int64_t utime;
    std::int64_t received_utime;
    bool from_receipt;
    Timestamp newest_event_us;
  };
  std::vector<Pending> ring_;
  std::size_t head_ = 0, count_ = 0;
  LatencyStatistics statistics_;
  LatencyStatistics settled_{0};             // a run histogram only: its per-period samples are never taken
  std::optional<std::int64_t> first_utime_;  // publish wall clock of the first batch stored
  Included newest_;
  // The least delay of the current window (by receipt time) and of the one before it.
  std::int64_t window_start_ = 0;
  std::optional<std::int64_t> current_least_, previous_least_;
  std::uint64_t from_receipt_ = 0;
};

}  // namespace evldt
