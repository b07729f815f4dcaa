#include "evldt/app/pipeline_options.hpp"

#include <cmath>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>
#include <stdexcept>

#include "evldt/lines/worker_pool.hpp"

namespace evldt {

const CLI::Validator& finite_number() {
  static const CLI::Validator validator(
      [](std::string& text) -> std::string {
        double value = 0;
        if (!CLI::detail::lexical_cast(text, value) || !std::isfinite(value)) return "'" + text + "' is not a finite number";
        return {};
      },
      "FINITE");
  return validator;
}

void PipelineOptions::add_to(CLI::App& app) {
  app.allow_config_extras(CLI::config_extras_mode::error);
  app.set_config("--config", "", "TOML file of options (keys are the long flag names, e.g. block-size = 14)");
  auto* group = app.add_option_group("Pipeline", "Line detection and tracking; unset values follow the sensor size");
  group->add_option("--width", width_, "Sensor width in pixels (default: from the recording's header)")
      ->check(CLI::Range(1, kMaxSensorSide));
  group->add_option("--height", height_, "Sensor height in pixels (default: from the recording's header)")
      ->check(CLI::Range(1, kMaxSensorSide));
  group->add_option("--block-size", block_size_, "SCARF block size b in pixels (even)")->check(CLI::Range(2, 64));
  group->add_option("--alpha", alpha_, "Ring capacity factor: N = floor(alpha * b * b / 2)")
      ->check(finite_number() & CLI::PositiveNumber);
  group->add_option("--fit-threshold", fit_threshold_, "Fitting-score threshold f_th")
      ->check(finite_number() & CLI::Range(0.0, 1.0));
  group->add_option("--inlier-ratio", inlier_ratio_, "Inlier distance d_max as a fraction of b")
      ->check(finite_number() & CLI::Range(0.01, 1.0));
  group->add_option("--fit-iterations", fit_iterations_, "Robust reweighting rounds of the line fit")
      ->check(CLI::Range(0, 20));
  group->add_option("--max-bend", max_bend_,
                    "Detection: no line where the events beyond both of its ends bend off to one side by this fraction of b, at least 2 px (an arc; 0: off)")
      ->check(finite_number() & CLI::Range(0.0, 2.0));
  group->add_option("--perturbation", perturbation_, "Endpoint perturbation dq in pixels")
      ->check(finite_number() & CLI::Range(0.01, 20.0));
  group->add_option("--bad-track-patience-us", bad_track_patience_,
                    "Event time a line may go without a good track before it is released")
      ->check(CLI::Range(Timestamp{1}, Timestamp{10'000'000}));
  group->add_option("--reassociation-window-us", reassociation_window_,
                    "A new line takes over the id of a line released nearby within this event time (0: never)")
      ->check(CLI::Range(Timestamp{0}, Timestamp{10'000'000}));
  group->add_option("--reassociation-max-angle", reassociation_angle_, "... if their directions differ by at most this (degrees)")
      ->check(finite_number() & CLI::Range(0.0, 90.0));
  group->add_option("--reassociation-max-offset", reassociation_offset_,
                    "... and its centre lies within this fraction of b from the released line")
      ->check(finite_number() & CLI::Range(0.0, 4.0));
  group->add_option("--whole-line-max-angle", whole_angle_,
                    "Whole lines: a segment joins a line whose direction is within this (degrees)")
      ->check(finite_number() & CLI::Range(0.0, 90.0));
  group->add_option("--whole-line-max-offset", whole_offset_, "... with both ends within this fraction of b of it")
      ->check(finite_number() & CLI::Range(0.0, 4.0));
  group->add_option("--whole-line-max-gap", whole_gap_, "... and at most this fraction of b beyond its ends")
      ->check(finite_number() & CLI::Range(0.0, 16.0));
  group->add_option("--whole-line-keep-id-us", whole_keep_id_, "Whole lines: a line unseen this long gives up its id")
      ->check(CLI::Range(Timestamp{0}, Timestamp{10'000'000}));
  group->add_option("--whole-line-end-memory-us", whole_end_memory_,
                    "Whole lines: an end its segments no longer reach stays this long")
      ->check(CLI::Range(Timestamp{0}, Timestamp{10'000'000}));
  group->add_option("--whole-line-min-length", whole_min_length_,
                    "Whole lines: a line is published once it is this many b long (then while it lasts)")
      ->check(finite_number() & CLI::Range(0.0, 1000.0));
  group->add_option("--whole-line-corner-reach", whole_corner_reach_,
                    "Whole lines: two lines whose ends lie within this many b of where they cross meet there (0: off)")
      ->check(finite_number() & CLI::Range(0.0, 16.0));
  group->add_option("--whole-line-corner-min-angle", whole_corner_angle_, "... if they differ in direction by this much (degrees)")
      ->check(finite_number() & CLI::Range(0.0, 90.0));
  group->add_option("--whole-line-event-reach", whole_event_reach_,
                    "Whole lines: an end reaches along the events beyond its segments up to this many b (0: off)")
      ->check(finite_number() & CLI::Range(0.0, 16.0));
  group->add_option("--multi-block-norm", multi_block_norm_, "r_e divisor for lines over k blocks: block (N) or union (k*N)")
      ->check(CLI::IsMember({"block", "union"}));
  group->add_option("--track-period-us", track_period_, "Deterministic mode: tracking period in event time")
      ->check(CLI::Range(Timestamp{1}, Timestamp{10'000'000}));
  group->add_option("--detect-period-us", detect_period_, "Deterministic mode: detection period in event time")
      ->check(CLI::Range(Timestamp{1}, Timestamp{10'000'000}));
  group->add_option("--threads", threads_,
                    "Threads each tracking and detection round is split over; the output is the same for any count\n"
                    "(default: the machine's cores less one for the receiving thread, at least 1)")
      ->check(CLI::Range(1, 64));
  auto* filters = app.add_option_group("Noise filters", "Run before storage, in the order given");
  filters->add_option("--filters", filters_,
                      "Filters in order, comma-separated: hot-pixel, background-activity, refractory, anti-flicker; or none\n"
                      "(default: refractory,hot-pixel,anti-flicker,background-activity)");
  filters->add_option("--filter-ba-window-us", ba_window_, "background-activity: a neighbour must have fired within this")
      ->check(CLI::Range(Timestamp{1}, Timestamp{10'000'000}));
  filters->add_option("--filter-ba-min-noise-hz", ba_min_noise_hz_,
                      "background-activity: drop only while uncorrelated events come at this rate per pixel or more (0: always)")
      ->check(finite_number() & CLI::Range(0.0, 1000.0));
  filters->add_option("--filter-refractory-us", filter_refractory_, "refractory: a pixel's events closer than this to its previous passed one are dropped (default 300)")
      ->check(CLI::Range(Timestamp{1}, Timestamp{10'000'000}));
  filters->add_option("--filter-hot-window-us", hot_window_, "hot-pixel: rates are judged over windows of this event time")
      ->check(CLI::Range(Timestamp{1000}, Timestamp{60'000'000}));
  filters->add_option("--filter-hot-rate-hz", hot_rate_, "hot-pixel: a pixel slower than this is never hot")
      ->check(finite_number() & CLI::PositiveNumber);
  filters->add_option("--filter-hot-ratio", hot_ratio_, "hot-pixel: hot above this many times its neighbours' mean rate")
      ->check(finite_number() & CLI::Range(1.0, 1e6));
  filters->add_option("--filter-flicker-min-hz", flicker_min_hz_, "anti-flicker: lowest flicker frequency")
      ->check(finite_number() & CLI::Range(17.0, 10000.0));
  filters->add_option("--filter-flicker-max-hz", flicker_max_hz_, "anti-flicker: highest flicker frequency")
      ->check(finite_number() & CLI::Range(17.0, 10000.0));
  group->add_option("--time-slack-us", time_slack_us_, "Events older than the newest by more than this are dropped")
      ->capture_default_str()
      ->check(CLI::Range(Timestamp{0}, Timestamp{60'000'000}));
}

std::optional<SensorSize> PipelineOptions::sensor() const {
  if (width_.has_value() != height_.has_value()) throw std::invalid_argument("give both --width and --height, or neither");
  if (!width_) return std::nullopt;
  return SensorSize{*width_, *height_};
}

PipelineConfig PipelineOptions::resolve(SensorSize sensor) const {
  PipelineConfig config = default_config_for(sensor);
  if (block_size_) config.lattice.block_size = *block_size_;
  if (alpha_) config.lattice.alpha = *alpha_;
  if (fit_threshold_) config.score.fit_threshold = *fit_threshold_;
  if (inlier_ratio_) config.score.inlier_distance_ratio = *inlier_ratio_;
  if (fit_iterations_) config.score.fit_iterations = *fit_iterations_;
  if (max_bend_) config.score.max_bend_ratio = *max_bend_;
  if (perturbation_) config.track.perturbation_px = *perturbation_;
  if (bad_track_patience_) config.track.bad_track_patience_us = *bad_track_patience_;
  if (reassociation_window_) config.track.reassociation.window_us = *reassociation_window_;
  if (reassociation_angle_) config.track.reassociation.max_angle_deg = *reassociation_angle_;
  if (reassociation_offset_) config.track.reassociation.max_offset_ratio = *reassociation_offset_;
  if (whole_angle_) config.whole_lines.max_angle_deg = *whole_angle_;
  if (whole_offset_) config.whole_lines.max_offset_ratio = *whole_offset_;
  if (whole_gap_) config.whole_lines.max_gap_ratio = *whole_gap_;
  if (whole_keep_id_) config.whole_lines.keep_id_us = *whole_keep_id_;
  if (whole_end_memory_) config.whole_lines.end_memory_us = *whole_end_memory_;
  if (whole_min_length_) config.whole_lines.min_length_ratio = *whole_min_length_;
  if (whole_corner_reach_) config.whole_lines.corner_reach_ratio = *whole_corner_reach_;
  if (whole_corner_angle_) config.whole_lines.corner_min_angle_deg = *whole_corner_angle_;
  if (whole_event_reach_) config.whole_lines.event_reach_ratio = *whole_event_reach_;
  if (multi_block_norm_) {
    config.track.multi_block_norm = *multi_block_norm_ == "union" ? EffectiveRatioNorm::Union : EffectiveRatioNorm::Block;
  }
  if (track_period_) config.schedule.track_period_us = *track_period_;
  if (detect_period_) config.schedule.detect_period_us = *detect_period_;
  config.threads = threads_.value_or(default_worker_threads());
  if (filters_) config.filters.chain = parse_filter_chain(*filters_);
  if (ba_window_) config.filters.background_window_us = *ba_window_;
  if (ba_min_noise_hz_) config.filters.background_min_noise_hz = *ba_min_noise_hz_;
  if (filter_refractory_) config.filters.refractory_us = *filter_refractory_;
  if (hot_window_) config.filters.hot_pixel.window_us = *hot_window_;
  if (hot_rate_) config.filters.hot_pixel.min_rate_hz = *hot_rate_;
  if (hot_ratio_) config.filters.hot_pixel.neighbour_ratio = *hot_ratio_;
  if (flicker_min_hz_) config.filters.anti_flicker.min_hz = *flicker_min_hz_;
  if (flicker_max_hz_) config.filters.anti_flicker.max_hz = *flicker_max_hz_;
  check_filter_config(config.filters);
  return config;
}

int run_main(CLI::App& app, int argc, char** argv, const std::function<int()>& body) {
  std::string level = "info";
  app.add_option("--log-level", level, "Log level: trace, debug, info, warn, error, off")
      ->capture_default_str()
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error", "off"}));
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& error) {
    return app.exit(error) == 0 ? 0 : 1;  // --help is 0; every usage error is 1
  }
  // Logs and progress go to stderr, so stdout carries only a tool's results and summary.
  if (!spdlog::get("evldt")) spdlog::set_default_logger(spdlog::stderr_color_mt("evldt"));
  spdlog::set_level(spdlog::level::from_str(level));
  try {
    return body();
  } catch (const std::exception& error) {
    spdlog::error("{}", error.what());
    return 1;
  }
}

}  // namespace evldt
