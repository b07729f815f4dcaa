#pragma once
// Reading what lcm-logger recorded (LcmLogReader, which counts and says every damaged stretch): the
// event batches of one camera as an event stream (so a recorded run can be processed offline) and
// its segment lists as rows (so a recorded run can be evaluated). Malformed messages are counted and
// skipped.

#include <cstdint>
#include <filesystem>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "evldt/pipeline/segment_csv.hpp"
#include "evldt/transport/event_batch_receiver.hpp"
#include "evldt/transport/lcm_log_reader.hpp"

namespace evldt {

/// True if the file starts like an LCM log (the event sync word 0xEDA1DA01).
bool is_lcm_log(const std::filesystem::path& path);

class LcmLogEventReader {
 public:
  /// `channel` empty: the first EVENTS_* channel in the log. Events off the sensor or back in time
  /// (beyond `backwards_slack_us`) are dropped and counted. Throws std::runtime_error if the file
  /// cannot be opened or holds no valid event batch on that channel.
  LcmLogEventReader(const std::filesystem::path& path, std::string channel, Timestamp backwards_slack_us);
  ~LcmLogEventReader();

  /// Clears `out` and fills it with the events of the next batch; false at the end of the log.
  bool read(EventBatch& out);

  [[nodiscard]] SensorSize sensor() const { return *receiver_.sensor(); }
  [[nodiscard]] const std::string& channel() const { return channel_; }
  /// Refused messages, lost batches and dropped events on the channel.
  [[nodiscard]] ReceiverCounts counts() const { return receiver_.counts(); }
  /// Fraction of the file read.
  [[nodiscard]] double progress() const;
  /// What was skipped as damaged so far (said in a warning once the log is read).
  [[nodiscard]] const LogDamage& damage() const { return log_.damage(); }

 private:
  bool next_batch(EventBatch& out);

  std::string channel_;
  LcmLogReader log_;
  LcmLogReader::Record record_;
  EventBatchReceiver receiver_;
  EventBatch first_;  // read while finding the sensor size, handed out by the first read()
  bool first_pending_ = false;
};

/// The segment lists on `channel` (empty: the first LINES_* channel) as rows, one step per lattice
/// time (the last list of that time), rows of a step sorted by id. Lists going back in time are
/// skipped and counted; damaged stretches of the log are said in a warning. Throws std::runtime_error
/// if the file cannot be opened or has no valid list.
std::vector<SegmentRow> read_segment_log(const std::filesystem::path& path, std::string channel = {});

}  // namespace evldt
