#pragma once
// Loss accounting for a stream of numbered messages (docs/design.md, section 8): a gap in the sequence is lost
// messages; a newer publisher epoch (a restarted camera) starts the count afresh. A long run of
// messages all behind the newest (epoch, sequence) means that newest was forged or stale: the
// tracker then follows the stream that keeps arriving, so one bad message cannot silence a camera.

#include <cstdint>

namespace evldt {

struct SequenceCounts {
  std::uint64_t received = 0;
  std::uint64_t lost = 0;      ///< sequence numbers skipped
  std::uint64_t late = 0;      ///< duplicates, out of order, or from an older epoch (not used)
  std::uint64_t restarts = 0;  ///< publisher epochs seen after the first, resyncs included
  std::uint64_t resyncs = 0;   ///< runs of late messages after which their stream was followed
};

/// Consecutive late messages after which the tracker follows their stream: 0.1 s of 1 kHz batches.
inline constexpr std::uint64_t kSequenceResyncRun = 100;

class SequenceTracker {
 public:
  /// Accounts one message; returns false if it is late (a duplicate, reordered, or of an older
  /// epoch) and should be ignored.
  bool observe(std::int64_t epoch, std::int64_t seq);
  [[nodiscard]] const SequenceCounts& counts() const { return counts_; }

 private:
  bool started_ = false;
  std::int64_t epoch_ = 0;
  std::int64_t last_ = 0;  ///< newest sequence number accepted in this epoch
  std::uint64_t late_run_ = 0;
  SequenceCounts counts_;
};

}  // namespace evldt
