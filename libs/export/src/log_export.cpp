#include "evldt/export/log_export.hpp"

#include <cctype>
#include <opencv2/imgcodecs.hpp>  // its constants; the calls go through evldt::media
#include <optional>
#include <stdexcept>

#include "evldt/containers/mcap_writer.hpp"
#include "evldt/export/foxglove_json.hpp"
#include "evldt/media/media.hpp"
#include "evldt/pipeline/pipeline_config.hpp"
#include "evldt/render/scene_renderer.hpp"
#include "evldt/scarf/scarf_lattice.hpp"
#include "evldt/transport/channels.hpp"
#include "evldt/transport/event_batch_receiver.hpp"
#include "evldt/transport/lcm_log.hpp"
#include "evldt/transport/messages.hpp"

namespace evldt {
namespace {

bool same_camera(const std::string& a, const std::string& b) {
  return a.size() == b.size() &&
         std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) { return std::toupper(x) == std::toupper(y); });
}

/// The camera of the first EVENTS_* channel, or empty.
std::string first_camera(const std::filesystem::path& path) {
  LcmLogReader log(path);
  LcmLogReader::Record record;
  while (log.next(record)) {
    if (record.channel.starts_with("EVENTS_")) return record.channel.substr(7);
  }
  return {};
}

}  // namespace

LogExportCounts export_log_to_mcap(const std::filesystem::path& log_path, const std::filesystem::path& mcap_path,
                                   const LogExportOptions& options) {
  if (!(options.image_hz > 0 && options.image_hz <= 1000))
    throw std::invalid_argument("picture rate must be in (0, 1000] Hz");
  if (options.scale < 1 || options.scale > 8) throw std::invalid_argument("scale must be in 1..8");
  if (options.jpeg_quality < 1 || options.jpeg_quality > 100)
    throw std::invalid_argument("JPEG quality must be in 1..100");
  LcmLogReader log(log_path);
  LcmLogReader::Record record;
  LogExportCounts counts;
  counts.camera = options.camera.empty() ? first_camera(log_path) : options.camera;
  if (counts.camera.empty())
    throw std::runtime_error("no event batches (EVENTS_* channel) in LCM log " + log_path.string());
  for (char& c : counts.camera) c = static_cast<char>(std::tolower(c));
  const std::string events = events_channel(counts.camera), lines = lines_channel(counts.camera),
                    whole_lines = whole_lines_channel(counts.camera);

  McapWriter mcap(mcap_path);
  const std::uint16_t image_schema =
      mcap.add_schema("foxglove.CompressedImage", "jsonschema", compressed_image_schema());
  const std::uint16_t annotations_schema =
      mcap.add_schema("foxglove.ImageAnnotations", "jsonschema", image_annotations_schema());
  const std::uint16_t stats_schema_id = mcap.add_schema("evldt.Stats", "jsonschema", stats_schema());
  const std::string prefix = "/" + counts.camera + "/";
  const std::uint16_t image_channel = mcap.add_channel(image_schema, prefix + "events", "json");
  const std::uint16_t segment_channel = mcap.add_channel(annotations_schema, prefix + "segments", "json");
  const std::uint16_t whole_line_channel = mcap.add_channel(annotations_schema, prefix + "whole_lines", "json");
  const std::uint16_t stats_channel = mcap.add_channel(stats_schema_id, prefix + "stats", "json");
  std::optional<std::uint16_t> camera_info_channel_id;  // added with the first CAMERA_INFO message
  const std::string camera_info = camera_info_channel(counts.camera);

  EventBatchReceiver receiver(std::nullopt, /*backwards_slack_us=*/1000);
  EventBatch batch;
  std::optional<ScarfLattice> lattice;
  const auto period_us = static_cast<std::int64_t>(1e6 / options.image_hz);
  std::int64_t next_image_us = 0;
  RenderOptions render{.scale = options.scale};
  cv::Mat canvas;
  std::vector<std::uint8_t> jpeg;
  segment_list_t list;
  std::vector<TrackedLine> tracked;
  stats_t stats;
  camera_info_t info;
  const AnnotationStyle segment_style{.thickness = 1, .by_status = true};
  const AnnotationStyle whole_line_style{.thickness = 2, .by_status = false, .ids = true, .motion = true};
  bool any_batch = false;
  while (log.next(record)) {
    const LcmLogReader::Record* event = &record;
    const auto time_ns = static_cast<std::uint64_t>(std::max<std::int64_t>(event->t_us, 0)) * 1000u;
    if (event->channel == events) {
      if (!receiver.receive(event->data, batch)) {
        ++counts.invalid;
        continue;
      }
      any_batch = true;
      if (!lattice || receiver.restarted()) {
        const LatticeParams params = default_config_for(*receiver.sensor()).lattice;
        lattice.emplace(params.sensor, params.block_size, params.alpha, /*keep_surface=*/true);
      }
      for (std::size_t i = 0; i < batch.size(); ++i) lattice->insert(batch.x[i], batch.y[i]);
      if (event->t_us < next_image_us) continue;
      // A picture a period after the last; after a pause in the recording, a period after this one.
      next_image_us += period_us;
      if (next_image_us <= event->t_us) next_image_us = event->t_us + period_us;
      render_scene(*receiver.sensor(), lattice->surface(), {}, render, canvas);
      media::encode_image(".jpg", canvas, jpeg, {cv::IMWRITE_JPEG_QUALITY, options.jpeg_quality});
      mcap.write(image_channel, time_ns, compressed_image_json(time_ns, counts.camera, jpeg));
      ++counts.images;
    } else if (event->channel == lines || event->channel == whole_lines) {
      if (decode_message(event->data, list) != WireError::None || !read_segment_list(list, tracked)) {
        ++counts.invalid;
        continue;
      }
      const bool whole = event->channel == whole_lines;
      mcap.write(whole ? whole_line_channel : segment_channel, time_ns,
                 image_annotations_json(time_ns, tracked, whole ? whole_line_style : segment_style, options.scale));
      ++(whole ? counts.whole_line_lists : counts.segment_lists);
    } else if (event->channel == kStatsChannel) {
      if (decode_message(event->data, stats) != WireError::None) {
        ++counts.invalid;
        continue;
      }
      if (stats.service != "evldt-lines" || !same_camera(stats.source, counts.camera)) {
        ++counts.other_messages;
        continue;
      }
      mcap.write(stats_channel, time_ns, stats_json(time_ns, stats));
      ++counts.stats;
    } else if (event->channel == camera_info) {
      if (decode_message(event->data, info) != WireError::None) {
        ++counts.invalid;
        continue;
      }
      if (!camera_info_channel_id) {
        const std::uint16_t schema =
            mcap.add_schema("foxglove.CameraCalibration", "jsonschema", camera_calibration_schema());
        camera_info_channel_id = mcap.add_channel(schema, prefix + "camera_info", "json");
      }
      mcap.write(*camera_info_channel_id, time_ns, camera_calibration_json(time_ns, info));
      ++counts.camera_infos;
    } else {
      ++counts.other_messages;
    }
  }
  log.report();
  counts.damage = log.damage();
  if (!any_batch) throw std::runtime_error("no valid event batch on " + events + " in LCM log " + log_path.string());
  mcap.close();
  return counts;
}

}  // namespace evldt
