#pragma once
// Command-line selection of where events come from (shared by evldt-offline and evldt-camera):
// a recording file, a live stream of one (standard input "-", tcp://HOST:PORT, --follow FILE being
// written), a built-in --scene, or a --from-video file / webcam.

#include <CLI/CLI.hpp>
#include <atomic>
#include <filesystem>
#include <memory>
#include <string>

#include "evldt/app/simulator_options.hpp"
#include "evldt/sources/event_source.hpp"

namespace evldt {

class SourceOptions {
 public:
  void add_to(CLI::App& app);
  /// Opens the one selected source; throws std::invalid_argument unless exactly one was given.
  /// `backwards_slack_us` checks the time order of an lcm-log's batches; a live source stops waiting
  /// for bytes once `stop` is set.
  [[nodiscard]] std::unique_ptr<EventSource> open(Timestamp backwards_slack_us, const std::atomic<bool>& stop) const;

 private:
  std::string recording_;
  std::filesystem::path followed_;
  double follow_idle_s_ = 10;
  bool reconnect_ = false;
  std::string format_;
  std::string lcm_channel_;
  std::string video_;
  double video_fps_ = 0;
  SimulatorOptions simulator_;
};

}  // namespace evldt
