#include "evldt/transport/sequence_tracker.hpp"

namespace evldt {

bool SequenceTracker::observe(std::int64_t epoch, std::int64_t seq) {
  if (started_ && (epoch < epoch_ || (epoch == epoch_ && seq < expected_))) {
    ++counts_.late;
    return false;
  }
  if (started_ && epoch == epoch_) {
    // Unsigned difference: a forged sequence number cannot overflow the count.
    counts_.lost += static_cast<std::uint64_t>(seq) - static_cast<std::uint64_t>(expected_);
  } else if (started_) {
    ++counts_.restarts;
  }
  started_ = true;
  epoch_ = epoch;
  expected_ = seq + (seq < INT64_MAX ? 1 : 0);
  ++counts_.received;
  return true;
}

}  // namespace evldt
