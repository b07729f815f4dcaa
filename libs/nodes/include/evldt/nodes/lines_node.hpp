#pragma once
// The evldt-lines service without its command line: subscribes to one camera's event batches and
// composes its parts on their threads: the ingest (lines_ingest.hpp: receiving, the latency budget,
// storage in the real-time engine, restarts) on the storing thread, the segment-list publisher and
// the statistics on the publishing thread, the whole-line publisher on its own
// (line_publishers.hpp, lines_statistics.hpp).

#include <sys/types.h>
#include <atomic>
#include <cstdint>
#include <lcm/lcm-cpp.hpp>
#include <optional>
#include <string>
#include <vector>

#include "evldt/nodes/line_publishers.hpp"
#include "evldt/nodes/lines_ingest.hpp"
#include "evldt/nodes/lines_options.hpp"
#include "evldt/nodes/lines_statistics.hpp"

namespace evldt {

class LinesNode {
 public:
  /// Subscribes at once. `epoch_us` (the process start) is sent in every message and is the first
  /// line id, so a restarted process never repeats an id.
  LinesNode(lcm::LCM& lcm, LinesNodeOptions options, std::int64_t epoch_us);
  ~LinesNode();
  LinesNode(const LinesNode&) = delete;
  LinesNode& operator=(const LinesNode&) = delete;

  /// Receives, stores and publishes until `stop` is set (checked every 100 ms), then stops the engine.
  void run(const std::atomic<bool>& stop);
  [[nodiscard]] LinesNodeTotals totals() const;

 private:
  /// Makes real-time the threads started since `threads_before` was taken (LCM's socket reader).
  static void make_socket_readers_realtime(const std::vector<pid_t>& threads_before);
  void on_events(const lcm::ReceiveBuffer* buffer, const std::string& channel);
  /// The publishing thread: segment lists, statistics and the log's status line.
  void publish_loop(const std::atomic<bool>& stop);

  lcm::LCM& lcm_;
  LinesNodeOptions options_;
  LinesIngest ingest_;
  std::optional<WholeLinePublisher> whole_lines_;  ///< with options.whole_lines
  SegmentListPublisher segments_;
  LinesStatistics statistics_;
  CameraInfoPublisher camera_info_;
  lcm::Subscription* subscription_ = nullptr;
  const std::atomic<bool>* stop_ = nullptr;  ///< run()'s, which the handler waits on when the queue is full
};

}  // namespace evldt
