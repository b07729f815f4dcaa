#include "evldt/app/parameters.hpp"

#include <array>
#include <charconv>
#include <cmath>
#include <initializer_list>
#include <limits>
#include <stdexcept>

#include "evldt/filters/filter_chain.hpp"

namespace evldt {

namespace {

using Type = Parameter::Type;
constexpr std::string_view kPipeline = "Pipeline";
constexpr std::string_view kFilters = "Noise filters";
constexpr double kLongestUs = 10'000'000;
constexpr double kSensorSide = kMaxSensorSide;

// One entry per parameter, in --help's order. The field each sets is named once, in its accessor.
const std::vector<Parameter>& table() {
  static const std::vector<Parameter> parameters{
      {.flag = "width",
       .group = kPipeline,
       .type = Type::Integer,
       .min = 1,
       .max = kSensorSide,
       .unit = "px",
       .help = "Sensor width",
       .default_text = "from the recording's header"},
      {.flag = "height",
       .group = kPipeline,
       .type = Type::Integer,
       .min = 1,
       .max = kSensorSide,
       .unit = "px",
       .help = "Sensor height",
       .default_text = "from the recording's header"},
      {.flag = "block-size",
       .group = kPipeline,
       .type = Type::Integer,
       .min = 2,
       .max = 64,
       .unit = "px",
       .help = "SCARF block size b (even)",
       .field = +[](PipelineConfig& c) -> int& { return c.lattice.block_size; }},
      {.flag = "alpha",
       .group = kPipeline,
       .type = Type::Real,
       .min = 0,
       .max = 1e9,
       .above_min = true,
       .help = "Ring capacity factor: N = floor(alpha * b * b / 2)",
       .field = +[](PipelineConfig& c) -> double& { return c.lattice.alpha; }},
      {.flag = "fit-threshold",
       .group = kPipeline,
       .type = Type::Real,
       .min = 0,
       .max = 1,
       .help = "Fitting-score threshold f_th",
       .field = +[](PipelineConfig& c) -> float& { return c.score.fit_threshold; }},
      {.flag = "inlier-ratio",
       .group = kPipeline,
       .type = Type::Real,
       .min = 0.01,
       .max = 1,
       .unit = "b",
       .help = "Inlier distance d_max",
       .field = +[](PipelineConfig& c) -> float& { return c.score.inlier_distance_ratio; }},
      {.flag = "fit-iterations",
       .group = kPipeline,
       .type = Type::Integer,
       .min = 0,
       .max = 20,
       .help = "Robust reweighting rounds of the line fit",
       .field = +[](PipelineConfig& c) -> int& { return c.score.fit_iterations; }},
      {.flag = "max-bend",
       .group = kPipeline,
       .type = Type::Real,
       .min = 0,
       .max = 2,
       .unit = "b",
       .help = "Detection: no line where the events beyond both of its ends bend off to one side by this much, at "
               "least 2 px "
               "(an arc; 0: off)",
       .field = +[](PipelineConfig& c) -> float& { return c.score.max_bend_ratio; }},
      {.flag = "detect-retry",
       .group = kPipeline,
       .type = Type::Real,
       .min = 0,
       .max = 1,
       .unit = "N",
       .help = "Detection: a block whose fit failed is fitted again once this share of N new active entries came in "
               "(0: at any change)",
       .field = +[](PipelineConfig& c) -> float& { return c.score.retry_share; }},
      {.flag = "perturbation",
       .group = kPipeline,
       .type = Type::Real,
       .min = 0.01,
       .max = 20,
       .unit = "px",
       .help = "Endpoint perturbation dq",
       .field = +[](PipelineConfig& c) -> float& { return c.track.perturbation_px; }},
      {.flag = "bad-track-patience-us",
       .group = kPipeline,
       .type = Type::Integer,
       .min = 1,
       .max = kLongestUs,
       .unit = "us",
       .help = "Event time a line may go without a good track before it is released",
       .field = +[](PipelineConfig& c) -> Timestamp& { return c.track.bad_track_patience_us; }},
      {.flag = "reassociation-window-us",
       .group = kPipeline,
       .type = Type::Integer,
       .min = 0,
       .max = kLongestUs,
       .unit = "us",
       .help = "A new line takes over the id of a line released nearby within this event time (0: never)",
       .field = +[](PipelineConfig& c) -> Timestamp& { return c.track.reassociation.window_us; }},
      {.flag = "reassociation-max-angle",
       .group = kPipeline,
       .type = Type::Real,
       .min = 0,
       .max = 90,
       .unit = "degrees",
       .help = "... if their directions differ by at most this",
       .field = +[](PipelineConfig& c) -> float& { return c.track.reassociation.max_angle_deg; }},
      {.flag = "reassociation-max-offset",
       .group = kPipeline,
       .type = Type::Real,
       .min = 0,
       .max = 4,
       .unit = "b",
       .help = "... and its centre lies within this of the released line",
       .field = +[](PipelineConfig& c) -> float& { return c.track.reassociation.max_offset_ratio; }},
      {.flag = "whole-line-max-angle",
       .group = kPipeline,
       .type = Type::Real,
       .min = 0,
       .max = 90,
       .unit = "degrees",
       .help = "Whole lines: a segment joins a line whose direction is within this",
       .field = +[](PipelineConfig& c) -> float& { return c.whole_lines.max_angle_deg; }},
      {.flag = "whole-line-max-offset",
       .group = kPipeline,
       .type = Type::Real,
       .min = 0,
       .max = 4,
       .unit = "b",
       .help = "... with both ends within this of it",
       .field = +[](PipelineConfig& c) -> float& { return c.whole_lines.max_offset_ratio; }},
      {.flag = "whole-line-max-gap",
       .group = kPipeline,
       .type = Type::Real,
       .min = 0,
       .max = 16,
       .unit = "b",
       .help = "... and at most this beyond its ends",
       .field = +[](PipelineConfig& c) -> float& { return c.whole_lines.max_gap_ratio; }},
      {.flag = "whole-line-keep-id-us",
       .group = kPipeline,
       .type = Type::Integer,
       .min = 0,
       .max = kLongestUs,
       .unit = "us",
       .help = "Whole lines: a line unseen this long gives up its id",
       .field = +[](PipelineConfig& c) -> Timestamp& { return c.whole_lines.keep_id_us; }},
      {.flag = "whole-line-end-memory-us",
       .group = kPipeline,
       .type = Type::Integer,
       .min = 0,
       .max = kLongestUs,
       .unit = "us",
       .help = "Whole lines: an end its segments no longer reach stays this long",
       .field = +[](PipelineConfig& c) -> Timestamp& { return c.whole_lines.end_memory_us; }},
      {.flag = "whole-line-min-length",
       .group = kPipeline,
       .type = Type::Real,
       .min = 0,
       .max = 1000,
       .unit = "b",
       .help = "Whole lines: a line is published once it is this long (then while it lasts)",
       .field = +[](PipelineConfig& c) -> float& { return c.whole_lines.min_length_ratio; }},
      {.flag = "whole-line-corner-reach",
       .group = kPipeline,
       .type = Type::Real,
       .min = 0,
       .max = 16,
       .unit = "b",
       .help = "Whole lines: two lines whose ends lie within this of where they cross meet there (0: off)",
       .field = +[](PipelineConfig& c) -> float& { return c.whole_lines.corner_reach_ratio; }},
      {.flag = "whole-line-corner-min-angle",
       .group = kPipeline,
       .type = Type::Real,
       .min = 0,
       .max = 90,
       .unit = "degrees",
       .help = "... if they differ in direction by this much",
       .field = +[](PipelineConfig& c) -> float& { return c.whole_lines.corner_min_angle_deg; }},
      {.flag = "whole-line-event-reach",
       .group = kPipeline,
       .type = Type::Real,
       .min = 0,
       .max = 16,
       .unit = "b",
       .help = "Whole lines: an end reaches along the events beyond its segments up to this far (0: off)",
       .field = +[](PipelineConfig& c) -> float& { return c.whole_lines.event_reach_ratio; }},
      {.flag = "multi-block-norm",
       .group = kPipeline,
       .type = Type::Text,
       .choices = {"block", "union"},
       .help = "r_e divisor for lines over k blocks: block (N) or union (k*N)",
       .field = Parameter::TextField{[](const PipelineConfig& c) -> std::string {
                                       return c.track.multi_block_norm == EffectiveRatioNorm::Union ? "union" : "block";
                                     },
                                     [](PipelineConfig& c, const std::string& text) {
                                       c.track.multi_block_norm =
                                           text == "union" ? EffectiveRatioNorm::Union : EffectiveRatioNorm::Block;
                                     }}},
      {.flag = "track-period-us",
       .group = kPipeline,
       .type = Type::Integer,
       .min = 1,
       .max = kLongestUs,
       .unit = "us",
       .help = "Deterministic mode: tracking period in event time",
       .field = +[](PipelineConfig& c) -> Timestamp& { return c.schedule.track_period_us; }},
      {.flag = "detect-period-us",
       .group = kPipeline,
       .type = Type::Integer,
       .min = 1,
       .max = kLongestUs,
       .unit = "us",
       .help = "Deterministic mode: detection period in event time",
       .field = +[](PipelineConfig& c) -> Timestamp& { return c.schedule.detect_period_us; }},
      {.flag = "threads",
       .group = kPipeline,
       .type = Type::Integer,
       .min = 1,
       .max = 64,
       .help = "Threads each tracking and detection round is split over; the output is the same for any count",
       .field = +[](PipelineConfig& c) -> int& { return c.threads; },
       .default_text = "the cores less one for the receiving thread, at least 1"},
      {.flag = "calibration",
       .group = kPipeline,
       .type = Type::Text,
       .help = "Camera calibration file (ROS camera_info or Kalibr camchain YAML, OpenCV FileStorage YAML/XML, the "
               "ECD's calib.txt): after the noise filters, events move into the rectified image, where the lattice and "
               "the lines live; none: the sensor's pixels as they are",
       .field = Parameter::TextField{
           [](const PipelineConfig& c) { return c.calibration; },
           [](PipelineConfig& c, const std::string& text) { c.calibration = text.empty() ? "none" : text; }}},
      {.flag = "filters",
       .group = kFilters,
       .type = Type::Text,
       .help = "Filters in order, comma-separated: hot-pixel, background-activity, refractory, anti-flicker; or none",
       .field = Parameter::TextField{
           [](const PipelineConfig& c) { return format_filter_chain(c.filters.chain); },
           [](PipelineConfig& c, const std::string& text) { c.filters.chain = parse_filter_chain(text); }}},
      {.flag = "filter-ba-window-us",
       .group = kFilters,
       .type = Type::Integer,
       .min = 1,
       .max = kLongestUs,
       .unit = "us",
       .help = "background-activity: a neighbour must have fired within this",
       .field = +[](PipelineConfig& c) -> Timestamp& { return c.filters.background_window_us; }},
      {.flag = "filter-ba-min-noise-hz",
       .group = kFilters,
       .type = Type::Real,
       .min = 0,
       .max = 1000,
       .unit = "Hz",
       .help =
           "background-activity: drop only while uncorrelated events come at this rate per pixel or more (0: always)",
       .field = +[](PipelineConfig& c) -> double& { return c.filters.background_min_noise_hz; }},
      {.flag = "filter-refractory-us",
       .group = kFilters,
       .type = Type::Integer,
       .min = 1,
       .max = kLongestUs,
       .unit = "us",
       .help = "refractory: a pixel's events closer than this to its previous passed one are dropped",
       .field = +[](PipelineConfig& c) -> Timestamp& { return c.filters.refractory_us; }},
      {.flag = "filter-hot-window-us",
       .group = kFilters,
       .type = Type::Integer,
       .min = 1000,
       .max = 60'000'000,
       .unit = "us",
       .help = "hot-pixel: rates are judged over windows of this event time",
       .field = +[](PipelineConfig& c) -> Timestamp& { return c.filters.hot_pixel.window_us; }},
      {.flag = "filter-hot-rate-hz",
       .group = kFilters,
       .type = Type::Real,
       .min = 0,
       .max = 1e9,
       .above_min = true,
       .unit = "Hz",
       .help = "hot-pixel: a pixel slower than this is never hot",
       .field = +[](PipelineConfig& c) -> double& { return c.filters.hot_pixel.min_rate_hz; }},
      {.flag = "filter-hot-ratio",
       .group = kFilters,
       .type = Type::Real,
       .min = 1,
       .max = 1e6,
       .help = "hot-pixel: hot above this many times its neighbours' mean rate",
       .field = +[](PipelineConfig& c) -> double& { return c.filters.hot_pixel.neighbour_ratio; }},
      {.flag = "filter-flicker-min-hz",
       .group = kFilters,
       .type = Type::Real,
       .min = 17,
       .max = 10000,
       .unit = "Hz",
       .help = "anti-flicker: lowest flicker frequency",
       .field = +[](PipelineConfig& c) -> double& { return c.filters.anti_flicker.min_hz; }},
      {.flag = "filter-flicker-max-hz",
       .group = kFilters,
       .type = Type::Real,
       .min = 17,
       .max = 10000,
       .unit = "Hz",
       .help = "anti-flicker: highest flicker frequency",
       .field = +[](PipelineConfig& c) -> double& { return c.filters.anti_flicker.max_hz; }},
      {.flag = "time-slack-us",
       .group = kPipeline,
       .type = Type::Integer,
       .min = 0,
       .max = 60'000'000,
       .unit = "us",
       .help = "Events older than the newest by more than this are dropped",
       .default_text = "1000"},
  };
  return parameters;
}

template <typename T>
std::string number_text(T value) {
  std::array<char, 64> text{};
  const auto end = std::to_chars(text.data(), text.data() + text.size(), value).ptr;
  return {text.data(), end};
}

template <typename T>
T parse_number(std::string_view flag, const std::string& text) {
  T value{};
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc{} || end != text.data() + text.size()) {
    throw std::invalid_argument("--" + std::string(flag) + ": '" + text + "' is not a number of its type");
  }
  return value;
}

void append(std::string& out, std::initializer_list<std::string_view> parts) {
  for (const std::string_view part : parts) out += part;
}

template <typename... F>
struct Overloaded : F... {
  using F::operator()...;
};
template <typename... F>
Overloaded(F...) -> Overloaded<F...>;  // clang before 17 deduces no aggregate's arguments

}  // namespace

std::string Parameter::value_in(const PipelineConfig& config) const {
  PipelineConfig copy = config;  // the accessors give references into a configuration they may change
  return std::visit(
      Overloaded{[](std::monostate) { return std::string{}; }, [&](const TextField& text) { return text.get(config); },
                 [&](auto of) { return number_text(of(copy)); }},
      field);
}

void Parameter::set(PipelineConfig& config, const std::string& text) const {
  std::visit(Overloaded{[](std::monostate) {}, [&](const TextField& text_field) { text_field.set(config, text); },
                        [&](auto of) {
                          auto& value = of(config);
                          value = parse_number<std::remove_reference_t<decltype(value)>>(flag, text);
                        }},
             field);
}

std::string Parameter::range_text() const {
  if (type == Type::Text) {
    std::string out;
    for (const std::string_view choice : choices) out += (out.empty() ? "" : ", ") + std::string(choice);
    return out;
  }
  const auto bound = [&](double value) {
    return type == Type::Integer ? number_text(static_cast<std::int64_t>(value)) : number_text(value);
  };
  std::string out(above_min ? "(" : "[");
  out += bound(min);
  out += ", ";
  out += bound(max);
  out += "]";
  return out;
}

std::span<const Parameter> pipeline_parameters() { return table(); }

std::string configuration_page() {
  constexpr std::array<SensorSize, 4> kSizes{{{240, 180}, {346, 260}, {640, 480}, {1280, 720}}};
  std::string page =
      "# Configuration\n\n"
      "<!-- Generated by `evldt-config --markdown` from libs/app/src/parameters.cpp; a test fails when they differ. "
      "-->\n\n"
      "Every tool and service that runs the line pipeline (`evldt-lines`, `evldt-offline`, `evldt-eval`,\n"
      "`evldt-bench`, Python's `evldt.Pipeline`) takes these parameters, as a command-line flag\n"
      "(`--block-size 14`) or as a key of the TOML file given by `--config` (`block-size = 14`); the command\n"
      "line wins, and an unknown key is an error. A parameter left unset takes the default for the sensor\n"
      "size below (the sizes of `config/`; another size takes the nearest listed width's). Units: `b` is a\n"
      "block side, `px` a pixel, `us` a microsecond of event time. `evldt-config --width W --height H`\n"
      "prints the whole configuration a size resolves to, as a TOML file `--config` takes back.\n";
  for (const std::string_view group : {kPipeline, kFilters}) {
    append(page, {"\n## ", group, "\n\n| parameter | range | unit |"});
    for (const SensorSize size : kSizes)
      append(page, {" ", std::to_string(size.width), "x", std::to_string(size.height), " |"});
    page += " what it does |\n|---|---|---|";
    for (std::size_t i = 0; i < kSizes.size(); ++i) page += "---|";
    page += "---|\n";
    for (const Parameter& parameter : table()) {
      if (parameter.group != group) continue;
      append(page, {"| `", parameter.flag, "` | ", parameter.range_text(), " | ", parameter.unit, " |"});
      for (const SensorSize size : kSizes) {
        const std::string value = parameter.default_text.empty() ? parameter.value_in(default_config_for(size))
                                                                 : std::string(parameter.default_text);
        append(page, {" ", value, " |"});
      }
      append(page, {" ", parameter.help, " |\n"});
    }
  }
  return page;
}

}  // namespace evldt
