#pragma once
// An lcm-logger recording of one camera as an MCAP file in Foxglove's schemas (foxglove_json.hpp):
// the events as pictures of the SCARF surface at a chosen rate of recording time, the segments and
// the whole lines as image annotations, the lines service's statistics as JSON. Topics
// /<camera>/events, /<camera>/segments, /<camera>/whole_lines, /<camera>/stats; messages at the
// time lcm-logger received them.

#include <cstdint>
#include <filesystem>
#include <string>

#include "evldt/transport/lcm_log_reader.hpp"

namespace evldt {

struct LogExportOptions {
  std::string camera;    ///< empty: the camera of the log's first event batch
  double image_hz = 10;  ///< pictures of the events per second of recording time
  int scale = 1;         ///< of the pictures (and so of the annotations' coordinates)
  int jpeg_quality = 85;
};

struct LogExportCounts {
  std::string camera;
  std::uint64_t images = 0, segment_lists = 0, whole_line_lists = 0, stats = 0;
  std::uint64_t camera_infos = 0;    ///< CAMERA_INFO messages (a run with a calibration)
  std::uint64_t invalid = 0;         ///< messages of the camera's channels that could not be decoded (skipped)
  std::uint64_t other_messages = 0;  ///< of other channels or cameras (not exported)
  LogDamage damage;                  ///< what of the log could not be read (also said in a warning)
};

/// Writes `mcap` from `log`; damaged stretches of the log are skipped, counted and said in a warning
/// (LcmLogReader). Throws std::runtime_error naming the file for a log that cannot be
/// opened or holds no event batch of the camera, std::invalid_argument for bad options.
LogExportCounts export_log_to_mcap(const std::filesystem::path& log, const std::filesystem::path& mcap,
                                   const LogExportOptions& options);

}  // namespace evldt
