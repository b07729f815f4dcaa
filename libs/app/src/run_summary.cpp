#include "evldt/app/run_summary.hpp"

#include <cinttypes>
#include <fstream>
#include <stdexcept>

#include "evldt/json/json_writer.hpp"

namespace evldt {

void RunSummary::add_pipeline(const DeterministicPipeline& pipeline) {
  filters = format_filter_chain(pipeline.config().filters.chain);
  calibration = pipeline.config().calibration;
  filtered = pipeline.filter_counts();
  counters = pipeline.counters();
  const LineMap& lines = pipeline.lines();
  lines_created = lines.created();
  lines_reassociated = lines.reassociated();
  lines_alive = lines.lines().size();
  for (int r = 0; r < kReleaseReasonCount; ++r) released[r] = lines.released(static_cast<ReleaseReason>(r));
  lifetimes = lines.released_lifetimes();
  for (const TrackedLine& line : lines.lines()) lifetimes.add(line.last_good_us - line.first_seen_us);
}

void RunSummary::print(std::FILE* out, const std::string& csv_path) const {
  const double mev = static_cast<double>(counters.events) * 1e-6;
  std::fprintf(out, "evldt summary: %s\n", input.c_str());
  if (!input_error.empty()) std::fprintf(out, "  input error      %s\n", input_error.c_str());
  std::fprintf(out,
               "  events           %" PRIu64 " read, %" PRIu64 " stored, %" PRIu64 " dropped as invalid (%" PRIu64
               " off-sensor, %" PRIu64 " time-backwards), %" PRIu64 " clock resets\n",
               events_read, counters.events, drops.total(), drops.off_sensor, drops.time_backwards, drops.clock_resets);
  if (filters == "none") {
    std::fprintf(out, "  filters          none\n");
  } else {
    std::fprintf(out,
                 "  filters          %s: %" PRIu64 " in, %" PRIu64 " passed; dropped %" PRIu64 " hot-pixel, %" PRIu64
                 " background-activity, %" PRIu64 " refractory, %" PRIu64 " anti-flicker\n",
                 filters.c_str(), filtered.events_in, filtered.passed, filtered.hot_pixel, filtered.background_activity,
                 filtered.refractory, filtered.anti_flicker);
  }
  if (calibration != "none") {
    std::fprintf(out,
                 "  calibration      %s: %" PRIu64 " events left out, their pixel sees beyond the rectified image\n",
                 calibration.c_str(), counters.off_rectified);
  }
  if (decoded.skipped_words > 0 || decoded.trigger_events > 0) {
    std::fprintf(
        out, "  decoding         %" PRIu64 " words of reserved or unknown types skipped, %" PRIu64 " trigger events\n",
        decoded.skipped_words, decoded.trigger_events);
  }
  std::fprintf(out, "  event time       %.3f s (%.2f Mev/s)\n", event_seconds,
               event_seconds > 0 ? mev / event_seconds : 0.0);
  std::fprintf(out, "  wall time        %.3f s (%.2f Mev/s processed)\n", wall_seconds,
               wall_seconds > 0 ? mev / wall_seconds : 0.0);
  std::fprintf(out,
               "  rounds           %" PRIu64 " tracking, %" PRIu64 " detection, %" PRIu64 " skipped over gaps, %" PRIu64
               " schedule restarts (clock went back)\n",
               counters.track_rounds, counters.detect_rounds, counters.skipped_rounds, counters.clock_restarts);
  std::fprintf(out,
               "  lines            %" PRIu64 " created, %" PRIu64 " detections took over a released line's id, %" PRIu64
               " alive at the end\n",
               lines_created, lines_reassociated, lines_alive);
  std::fprintf(out, "  released         ");
  for (int r = 0; r < kReleaseReasonCount; ++r) {
    std::fprintf(out, "%s%s %" PRIu64, r ? ", " : "", reason_name(static_cast<ReleaseReason>(r)).data(), released[r]);
  }
  std::fprintf(out, "\n  lifetime         mean %.1f ms, max %.1f ms (%" PRIu64 " lines)\n", lifetimes.mean_us() * 1e-3,
               static_cast<double>(lifetimes.max_us) * 1e-3, lifetimes.count);
  std::fprintf(out, "  output           %" PRIu64 " CSV rows -> %s", csv_rows, csv_path.c_str());
  if (frames > 0) std::fprintf(out, ", %d frames rendered", frames);
  std::fprintf(out, "\n");
  if (!whole_lines_path.empty()) {
    std::fprintf(out, "  whole lines      %" PRIu64 " ids, %" PRIu64 " CSV rows -> %s\n", whole_lines_created,
                 whole_line_rows, whole_lines_path.c_str());
  }
}

void RunSummary::write_json(const std::filesystem::path& path) const {
  std::ofstream out(path);
  if (!out) throw std::runtime_error("cannot create " + path.string());
  out << "{\n  \"input\": " << json_quoted(input) << ",\n";
  out << "  \"input_error\": " << json_quoted(input_error) << ",\n";
  out << "  \"events_read\": " << events_read << ",\n  \"events_stored\": " << counters.events << ",\n";
  out << "  \"dropped_off_sensor\": " << drops.off_sensor << ",\n  \"dropped_time_backwards\": " << drops.time_backwards
      << ",\n";
  out << "  \"clock_resets\": " << drops.clock_resets << ",\n";
  out << "  \"filters\": \"" << filters << "\",\n  \"filtered\": {\"events_in\": " << filtered.events_in
      << ", \"passed\": " << filtered.passed << ", \"hot_pixel\": " << filtered.hot_pixel
      << ", \"background_activity\": " << filtered.background_activity << ", \"refractory\": " << filtered.refractory
      << ", \"anti_flicker\": " << filtered.anti_flicker << "},\n";
  out << "  \"skipped_words\": " << decoded.skipped_words << ",\n  \"trigger_events\": " << decoded.trigger_events
      << ",\n";
  out << "  \"event_seconds\": " << event_seconds << ",\n  \"wall_seconds\": " << wall_seconds << ",\n";
  out << "  \"track_rounds\": " << counters.track_rounds << ",\n  \"detect_rounds\": " << counters.detect_rounds
      << ",\n";
  out << "  \"skipped_rounds\": " << counters.skipped_rounds << ",\n";
  out << "  \"clock_restarts\": " << counters.clock_restarts << ",\n";
  out << "  \"events_off_rectified\": " << counters.off_rectified << ",\n";
  out << "  \"lines_created\": " << lines_created << ",\n  \"lines_reassociated\": " << lines_reassociated
      << ",\n  \"lines_alive\": " << lines_alive << ",\n  \"released\": {";
  for (int r = 0; r < kReleaseReasonCount; ++r) {
    out << (r ? ", " : "") << '"' << reason_name(static_cast<ReleaseReason>(r)) << "\": " << released[r];
  }
  out << "},\n  \"lifetime_mean_ms\": " << lifetimes.mean_us() * 1e-3 << ",\n";
  out << "  \"lifetime_max_ms\": " << static_cast<double>(lifetimes.max_us) * 1e-3 << ",\n";
  out << "  \"csv_rows\": " << csv_rows << ",\n  \"whole_lines_created\": " << whole_lines_created
      << ",\n  \"whole_line_rows\": " << whole_line_rows << ",\n  \"frames\": " << frames << "\n}\n";
  if (!out) throw std::runtime_error("error writing " + path.string());
}

}  // namespace evldt
