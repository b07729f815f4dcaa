#include "evldt/transport/sequence_tracker.hpp"

namespace evldt {

bool SequenceTracker::observe(std::int64_t epoch, std::int64_t seq) {
  const bool late = started_ && (epoch < epoch_ || (epoch == epoch_ && seq <= last_));
  if (late) {
    if (++late_run_ < kSequenceResyncRun) {
      ++counts_.late;
      return false;
    }
    ++counts_.resyncs;
  }
  late_run_ = 0;
  if (started_ && epoch == epoch_ && !late) {
    // Unsigned difference: a forged sequence number cannot overflow the count.
    counts_.lost += static_cast<std::uint64_t>(seq) - static_cast<std::uint64_t>(last_) - 1;
  } else if (started_) {
    ++counts_.restarts;
  }
  started_ = true;
  epoch_ = epoch;
  last_ = seq;
  ++counts_.received;
  return true;
}

}  // namespace evldt
