#pragma once
// The evldt-camera service without its command line: reads an event source, validates its events,
// cuts them into batches by time window and size, and publishes them paced at real time (or a
// speed factor), optionally looping the source with time continuing forward; its statistics go on
// EVLDT_STATS.

#include <atomic>
#include <functional>
#include <lcm/lcm-cpp.hpp>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "evldt/event_batch_t.hpp"
#include "evldt/events/event_validator.hpp"
#include "evldt/sources/event_source.hpp"
#include "evldt/transport/sensor_lag.hpp"

namespace evldt {

struct CameraNodeOptions {
  std::string camera = "cam0";
  std::optional<SensorSize> sensor;  ///< unset: the source's own
  Timestamp batch_us = 1000;
  std::size_t max_batch = 7000;  ///< about one 64 KiB datagram
  double speed = 1.0;            ///< 0: as fast as possible
  bool loop = false;
  Timestamp time_slack_us = 1000;
  double progress_period_s = 2;  ///< a progress line this often (0: none)
  double stats_hz = 1;           ///< statistics on EVLDT_STATS this often, and once at the end (0: none)
};

struct CameraSummary {
  std::string source;
  SensorSize sensor;
  std::uint64_t events_read = 0;
  std::uint64_t events_published = 0;
  DecodeCounts decoded;  ///< words the recording's decoder skipped, trigger events it counted
  DropCounts drops;
  std::uint64_t batches = 0;
  std::uint64_t publish_failures = 0;
  std::uint64_t bytes = 0;   ///< encoded message bytes published
  std::uint64_t loops = 0;   ///< times the source was restarted by --loop
  double event_seconds = 0;  ///< event time spanned by the published batches
  double wall_seconds = 0;
  double max_lag_s = 0;              ///< furthest behind the pace
  std::uint64_t skipped_gaps = 0;    ///< jumps of event time not waited through (Pacer)
  std::string input_error;           ///< set if the source ended in a format error
  bool live = false;                 ///< a camera read as it records: the lag below is measured
  LatencySummary sensor_lag;         ///< sensor clock -> publish, beyond the quickest batch (SensorLag)
  double sensor_clock_offset_s = 0;  ///< wall clock - sensor clock, as last estimated
  std::uint64_t reconnects = 0;      ///< a live stream's connection made again

  void print(std::FILE* out) const;
};

class CameraNode {
 public:
  using SourceFactory = std::function<std::unique_ptr<EventSource>()>;
  /// `epoch_us` (the process start) goes in every batch so subscribers see a restart.
  CameraNode(lcm::LCM& lcm, CameraNodeOptions options, std::int64_t epoch_us);

  /// Publishes the source (reopened by `open_source` for every loop) until it ends or `stop` is
  /// set. Throws std::runtime_error if the sensor size is unknown.
  CameraSummary run(const SourceFactory& open_source, const std::atomic<bool>& stop);

 private:
  class Run;  // the state of one run()

  void publish(const EventBatch& batch, CameraSummary& summary);
  /// The statistics so far; `rate_events` published since the last ones, over `period_s`.
  void publish_stats(const CameraSummary& summary, const DecodeCounts& decoded, const DropCounts& drops,
                     double period_s, std::uint64_t rate_events);

  lcm::LCM& lcm_;
  CameraNodeOptions options_;
  std::int64_t epoch_us_;
  std::string channel_;
  event_batch_t header_;            // header fields of the next batch (its arrays stay empty)
  std::vector<std::uint8_t> wire_;  // the encoded batch, reused
  std::optional<Timestamp> first_published_t_;
  SensorLag sensor_lag_;  // of the live source being published
};

}  // namespace evldt
