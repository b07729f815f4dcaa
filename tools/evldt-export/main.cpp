// evldt-export: an lcm-logger recording as an MCAP file that Foxglove opens (libs/export).

#include <spdlog/spdlog.h>
#include <CLI/CLI.hpp>
#include <cstdio>

#include "evldt/app/pipeline_options.hpp"
#include "evldt/export/log_export.hpp"

int main(int argc, char** argv) {
  using namespace evldt;
  CLI::App app{
      "evldt-export: writes an lcm-logger recording (LOG.lcmlog) of one camera as an MCAP file in Foxglove's\n"
      "schemas, JSON encoding: /<camera>/events (foxglove.CompressedImage: the SCARF surface of the events at\n"
      "--image-hz of recording time), /<camera>/segments and /<camera>/whole_lines (foxglove.ImageAnnotations, whole\n"
      "lines with their ids), /<camera>/stats (evldt.Stats: evldt-lines' statistics) and, from a run with a "
      "calibration,\n"
      "/<camera>/camera_info (foxglove.CameraCalibration). Open it in Foxglove: an Image panel on /<camera>/events "
      "with\n"
      "both annotation topics."};
  std::filesystem::path log, mcap;
  LogExportOptions options;
  app.add_option("LOG", log, "lcm-logger recording")->required()->check(CLI::ExistingFile);
  app.add_option("MCAP", mcap, "MCAP file to write")->required();
  app.add_option("--camera", options.camera, "Camera to export (default: that of the first event batch)");
  app.add_option("--image-hz", options.image_hz, "Pictures of the events per second of recording time")
      ->capture_default_str()
      ->check(CLI::Range(0.1, 1000.0));
  app.add_option("--scale", options.scale, "Zoom of the pictures")->capture_default_str()->check(CLI::Range(1, 8));
  app.add_option("--jpeg-quality", options.jpeg_quality, "JPEG quality of the pictures")
      ->capture_default_str()
      ->check(CLI::Range(1, 100));
  return run_main(app, argc, argv, [&] {
    const LogExportCounts counts = export_log_to_mcap(log, mcap, options);
    if (counts.invalid > 0) spdlog::warn("{} undecodable messages of camera {} skipped", counts.invalid, counts.camera);
    std::printf(
        "evldt-export summary\n"
        "  camera    %s\n"
        "  written   %llu pictures, %llu segment lists, %llu whole-line lists, %llu statistics, %llu camera "
        "calibrations -> %s\n"
        "  skipped   %llu undecodable, %llu of other channels or cameras\n"
        "  damage    %llu bytes in %llu place(s)%s\n",
        counts.camera.c_str(), static_cast<unsigned long long>(counts.images),
        static_cast<unsigned long long>(counts.segment_lists), static_cast<unsigned long long>(counts.whole_line_lists),
        static_cast<unsigned long long>(counts.stats), static_cast<unsigned long long>(counts.camera_infos),
        mcap.string().c_str(), static_cast<unsigned long long>(counts.invalid),
        static_cast<unsigned long long>(counts.other_messages),
        static_cast<unsigned long long>(counts.damage.skipped_bytes),
        static_cast<unsigned long long>(counts.damage.regions), counts.damage.cut ? ", the last record cut short" : "");
    return 0;
  });
}
