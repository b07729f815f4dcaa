#pragma once
// The end-of-run summary of an offline run: what came in, what was dropped, what the pipeline made.

#include <cstdio>
#include <filesystem>
#include <string>

#include "evldt/events/event_decoder.hpp"
#include "evldt/events/event_validator.hpp"
#include "evldt/pipeline/deterministic_pipeline.hpp"

namespace evldt {

struct RunSummary {
  std::string input;
  std::string input_error;  ///< set when the input ended in a format error
  std::uint64_t events_read = 0;
  DecodeCounts decoded;  ///< words the recording's decoder skipped, trigger events it counted
  DropCounts drops;
  std::string filters;  ///< the chain, "none" for no filter
  FilterCounts filtered;
  std::string calibration = "none";  ///< the calibration file, "none" for none
  double event_seconds = 0;
  double wall_seconds = 0;
  PipelineCounters counters;
  std::uint64_t lines_created = 0;       ///< distinct ids
  std::uint64_t lines_reassociated = 0;  ///< detections that took over a released line's id
  std::uint64_t lines_alive = 0;
  std::uint64_t released[kReleaseReasonCount] = {};
  LifetimeStats lifetimes;  ///< released and live lines
  std::uint64_t csv_rows = 0;
  std::uint64_t whole_lines_created = 0;  ///< with a whole-line CSV: distinct whole-line ids
  std::uint64_t whole_line_rows = 0;
  std::string whole_lines_path;  ///< empty: no whole lines written
  int frames = 0;

  /// Takes the filter chain, its counts, the round counters, line counts and lifetimes (released
  /// plus still alive) from the pipeline.
  void add_pipeline(const DeterministicPipeline& pipeline);
  void print(std::FILE* out, const std::string& csv_path) const;
  void write_json(const std::filesystem::path& path) const;
};

}  // namespace evldt
