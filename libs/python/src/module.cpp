// _evldt: the Python face of the core (package evldt wraps it). Wiring only: every figure comes from
// the same libraries the tools use, and options go through the tools' own option parsers, so a
// parameter means, and is checked, as on the command line.

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <exception>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "evldt/app/pipeline_options.hpp"
#include "evldt/app/simulator_options.hpp"
#include "evldt/client/line_subscriber.hpp"
#include "evldt/eval/evaluation_report.hpp"
#include "evldt/eval/scene_evaluation.hpp"
#include "evldt/events/event_validator.hpp"
#include "evldt/frames/frame_reader.hpp"
#include "evldt/pipeline/deterministic_pipeline.hpp"
#include "evldt/sources/event_source.hpp"

namespace py = pybind11;

namespace evldt::python {

// Packed records: numpy's own dtype for a list of fields has no padding, so arrays built in Python
// (and np.concatenate's results) have the same dtype as the module's.
#pragma pack(push, 1)
/// One event as numpy holds it (the dtype evldt.EVENT_DTYPE).
struct EventRecord {
  std::int64_t t;
  std::uint16_t x;
  std::uint16_t y;
  std::int8_t p;
};

/// One segment at one output step (evldt.SEGMENT_DTYPE): the columns of evldt-offline's CSV, and
/// the line's first-seen and last-good times.
struct SegmentRecord {
  std::int64_t t;
  std::uint64_t id;
  float x0, y0, x1, y1;
  float score;
  std::uint8_t status;  ///< 0 detected, 1 good, 2 bad (evldt.STATUS_NAMES)
  std::int64_t first_seen;
  std::int64_t last_good;
  float normal_velocity;  ///< px/s across the line (TrackedLine's); NaN where not known
  float normal_velocity_std;
};

/// One ground-truth edge piece at one step (evldt.GROUND_TRUTH_DTYPE), as evldt-sim's CSV has it.
struct GroundTruthRecord {
  std::int64_t t;
  std::int64_t gt_id;
  double x0, y0, x1, y1;
};
#pragma pack(pop)

namespace {

/// Parses `args` (command-line flags) with an app set up by `add`; a usage error raises ValueError
/// with CLI11's message, as the tools print it.
template <typename Add>
void parse_flags(const std::string& what, const std::vector<std::string>& args, Add add) {
  CLI::App app{what};
  add(app);
  std::vector<std::string> reversed(args.rbegin(), args.rend());  // CLI11 takes them last first
  try {
    app.parse(reversed);
  } catch (const CLI::ParseError& error) {
    throw py::value_error(std::string(error.what()));
  }
}

template <typename Record>
py::array_t<Record> to_numpy(const std::vector<Record>& records) {
  py::array_t<Record> out(static_cast<py::ssize_t>(records.size()));
  if (!records.empty()) std::memcpy(out.mutable_data(), records.data(), records.size() * sizeof(Record));
  return out;
}

py::array_t<EventRecord> events_to_numpy(const EventBatch& batch) {
  py::array_t<EventRecord> out(static_cast<py::ssize_t>(batch.size()));
  auto view = out.mutable_unchecked<1>();
  for (std::size_t i = 0; i < batch.size(); ++i) {
    view(static_cast<py::ssize_t>(i)) = {batch.t[i], batch.x[i], batch.y[i], batch.p[i]};
  }
  return out;
}

/// A step's lines, by id as in evldt-offline's CSV.
void append_lines(Timestamp t, std::span<const TrackedLine> lines, std::vector<SegmentRecord>& out) {
  const std::size_t first = out.size();
  for (const TrackedLine& line : lines) {
    out.push_back({t, line.id, line.segment.q0.x(), line.segment.q0.y(), line.segment.q1.x(), line.segment.q1.y(),
                   line.score, static_cast<std::uint8_t>(line.status), line.first_seen_us, line.last_good_us,
                   line.normal_velocity, line.normal_velocity_std});
  }
  std::sort(out.begin() + static_cast<std::ptrdiff_t>(first), out.end(),
            [](const SegmentRecord& a, const SegmentRecord& b) { return a.id < b.id; });
}

/// A recording read in chunks (evldt.read_chunks; evldt.read joins them).
class Reader {
 public:
  Reader(const std::string& path, const std::string& format, const std::string& channel, Timestamp time_slack_us) {
    std::optional<EventFormat> parsed;
    if (!format.empty()) {
      parsed = parse_event_format(format);
      if (!parsed) throw py::value_error("unknown format '" + format + "': ecd, evt2, evt3, evt21, dat");
    }
    source_ = open_recording(path, parsed, channel, time_slack_us);
  }

  /// The next `max_events` events (fewer only at the end); None at the end. A corrupt recording
  /// raises FormatError once every event before the fault has been returned.
  std::optional<py::array_t<EventRecord>> read(std::size_t max_events) {
    if (failure_) std::rethrow_exception(std::exchange(failure_, nullptr));
    {
      py::gil_scoped_release unlocked;
      chunk_.clear();
      while (chunk_.size() < max_events) {
        if (taken_ == pending_.size()) {
          taken_ = 0;
          try {
            if (!source_->read(pending_)) break;
          } catch (const FormatError&) {
            if (chunk_.empty()) throw;
            failure_ = std::current_exception();  // after the events gathered so far
            pending_.clear();
            break;
          }
        }
        const std::size_t n = std::min(max_events - chunk_.size(), pending_.size() - taken_);
        chunk_.append(pending_, taken_, taken_ + n);
        taken_ += n;
      }
    }
    if (chunk_.empty()) return std::nullopt;
    return events_to_numpy(chunk_);
  }

  [[nodiscard]] std::optional<std::pair<int, int>> sensor() const {
    const auto size = source_->geometry();
    if (!size) return std::nullopt;
    return std::pair(size->width, size->height);
  }
  [[nodiscard]] std::string name() const { return source_->name(); }
  [[nodiscard]] double progress() const { return source_->progress(); }

 private:
  std::unique_ptr<EventSource> source_;
  EventBatch pending_;     // the source's last batch
  std::size_t taken_ = 0;  // of pending_, already returned
  EventBatch chunk_;
  std::exception_ptr failure_;  // raised by the next read()
};

/// The deterministic pipeline behind evldt-offline: validation, noise filters, storage, detection
/// and tracking, with an output step every output_period_us of event time; with whole_lines, each
/// step's whole lines too (evldt-offline's --whole-lines).
class Pipeline {
 public:
  Pipeline(int width, int height, const std::vector<std::string>& flags, Timestamp output_period_us, bool whole_lines) {
    PipelineOptions options;
    parse_flags("evldt.Pipeline", flags, [&](CLI::App& app) { options.add_to(app); });
    const SensorSize sensor{width, height};
    if (width < 1 || height < 1 || width > kMaxSensorSide || height > kMaxSensorSide) {
      throw py::value_error("sensor size must be 1.." + std::to_string(kMaxSensorSide) + " on each side");
    }
    const PipelineConfig config = options.resolve(sensor);  // std::invalid_argument -> ValueError
    validator_.emplace(sensor, options.time_slack_us());
    pipeline_.emplace(config);
    pipeline_->set_output(
        output_period_us,
        [this](const OutputStep& step) {
          append_lines(step.t, step.segments.lines(), steps_);
          append_lines(step.t, step.whole_lines, whole_steps_);
        },
        whole_lines);
    staging_.reserve(kStagingEvents);
  }

  /// Runs the events (any length; strided numpy views are read in place) and returns the segments
  /// of every output step they completed.
  py::array_t<SegmentRecord> process(const py::array_t<std::int64_t>& t, const py::array_t<std::uint16_t>& x,
                                     const py::array_t<std::uint16_t>& y, const py::array_t<std::int8_t>& p) {
    if (t.ndim() != 1 || x.ndim() != 1 || y.ndim() != 1 || p.ndim() != 1) {
      throw py::value_error("t, x, y and p must be one-dimensional");
    }
    const py::ssize_t n = t.shape(0);
    if (x.shape(0) != n || y.shape(0) != n || p.shape(0) != n)
      throw py::value_error("t, x, y and p must have one length");
    const auto ts = t.unchecked<1>();
    const auto xs = x.unchecked<1>();
    const auto ys = y.unchecked<1>();
    const auto ps = p.unchecked<1>();
    std::vector<SegmentRecord> completed;
    {
      py::gil_scoped_release unlocked;  // the arrays stay alive: the caller holds them
      std::lock_guard lock(mutex_);
      steps_.clear();
      whole_steps_.clear();
      for (py::ssize_t begin = 0; begin < n; begin += static_cast<py::ssize_t>(kStagingEvents)) {
        const py::ssize_t end = std::min(n, begin + static_cast<py::ssize_t>(kStagingEvents));
        staging_.clear();
        for (py::ssize_t i = begin; i < end; ++i) staging_.push_back(ts(i), xs(i), ys(i), ps(i));
        validator_->filter(staging_);
        pipeline_->process(staging_);
      }
      completed.swap(steps_);
      completed_whole_.swap(whole_steps_);
    }
    return to_numpy(completed);
  }

  /// The whole lines of the output steps the last process() call completed (empty unless the
  /// pipeline was made with whole_lines).
  py::array_t<SegmentRecord> whole_lines() const {
    std::lock_guard lock(mutex_);
    return to_numpy(completed_whole_);
  }

  /// The live lines now, stamped with the newest event time seen.
  py::array_t<SegmentRecord> segments() const {
    std::vector<SegmentRecord> now;
    {
      std::lock_guard lock(mutex_);
      append_lines(validator_->newest_time(), pipeline_->lines().lines(), now);
    }
    return to_numpy(now);
  }

  py::dict counters() const {
    std::lock_guard lock(mutex_);
    py::dict out;
    const auto& c = pipeline_->counters();
    const auto& lines = pipeline_->lines();
    out["events_accepted"] = validator_->accepted();
    out["dropped_off_sensor"] = validator_->drops().off_sensor;
    out["dropped_back_in_time"] = validator_->drops().time_backwards;
    out["events_stored"] = c.events;
    out["track_rounds"] = c.track_rounds;
    out["detect_rounds"] = c.detect_rounds;
    out["skipped_rounds"] = c.skipped_rounds;
    out["lines_created"] = lines.created();
    out["lines_live"] = lines.lines().size();
    return out;
  }

 private:
  // Events are staged in slices this long: the pipeline takes its batch type, and a slice keeps
  // the staging memory small whatever the input's length.
  static constexpr std::size_t kStagingEvents = 1 << 16;
  // Python threads may share a pipeline: process() runs without the GIL, so calls take turns here
  // (taken only where the GIL is not needed before it is let go, so the two never wait on each other).
  mutable std::mutex mutex_;
  std::optional<EventValidator> validator_;
  std::optional<DeterministicPipeline> pipeline_;
  EventBatch staging_;
  std::vector<SegmentRecord> steps_, whole_steps_;
  std::vector<SegmentRecord> completed_whole_;  // whole_steps_ of the last process()
};

/// evldt-eval's figures of predicted segments against ground truth.
py::object evaluate(const py::array_t<SegmentRecord>& segments, const py::array_t<GroundTruthRecord>& ground_truth,
                    int width, int height, const std::vector<double>& tolerances, Timestamp output_period_us,
                    std::optional<float> min_normal_speed) {
  if (min_normal_speed && !(*min_normal_speed >= 0)) throw py::value_error("min_normal_speed must not be negative");
  std::vector<SegmentRow> rows;
  const auto predicted = segments.unchecked<1>();
  rows.reserve(static_cast<std::size_t>(predicted.shape(0)));
  for (py::ssize_t i = 0; i < predicted.shape(0); ++i) {
    const SegmentRecord& r = predicted(i);
    rows.push_back({r.t, r.id, Segment{Point2(r.x0, r.y0), Point2(r.x1, r.y1)}, r.score,
                    static_cast<LineStatus>(r.status), r.normal_velocity, r.normal_velocity_std});
  }
  std::vector<GroundTruthRow> truth_rows;
  const auto truth = ground_truth.unchecked<1>();
  for (py::ssize_t i = 0; i < truth.shape(0); ++i) {
    const GroundTruthRecord& r = truth(i);
    if (r.gt_id < std::numeric_limits<int>::min() || r.gt_id > std::numeric_limits<int>::max()) {
      throw py::value_error("ground-truth id out of range at row " + std::to_string(i));
    }
    truth_rows.push_back({r.t, GtSegment{static_cast<int>(r.gt_id), Vec2d(r.x0, r.y0), Vec2d(r.x1, r.y1)}});
  }
  std::optional<StreamEvaluator> evaluator;
  {
    py::gil_scoped_release unlocked;
    GroundTruthSteps steps = csv_ground_truth_steps(truth_rows);
    evaluator.emplace(evaluate_segment_rows(
        std::move(rows), std::move(steps), SensorSize{width, height}, tolerances, output_period_us,
        min_normal_speed ? std::optional<VisibleOnly>(VisibleOnly::by_speed(*min_normal_speed)) : std::nullopt));
  }
  // evldt-eval's figures under its JSON keys (a run of its --json without the run's own fields).
  return py::module_::import("json").attr("loads")(evaluation_json(make_evaluation_report(*evaluator)));
}

/// A built-in scene through the event simulator: its events, its ground truth every gt_period_us
/// (as evldt-sim writes it), and its sensor size.
py::tuple simulate(const std::vector<std::string>& flags, Timestamp gt_period_us) {
  SimulatorOptions options;
  parse_flags("evldt.simulate", flags, [&](CLI::App& app) { options.add_to(app, /*scene_required=*/true); });
  const Scene scene = options.scene();
  EventBatch events;
  std::vector<GroundTruthRecord> truth;
  {
    py::gil_scoped_release unlocked;
    EventSimulator simulator(scene, options.config());
    while (simulator.run_until(simulator.now_us() + 10'000, events)) {
    }
    for (Timestamp t = 0; t <= scene.duration_us; t += gt_period_us) {
      for (const GtSegment& edge : scene.visible_edges(t)) {
        truth.push_back({t, edge.gt_id, edge.a.x(), edge.a.y(), edge.b.x(), edge.b.y()});
      }
    }
  }
  return py::make_tuple(events_to_numpy(events), to_numpy(truth), scene.sensor.width, scene.sensor.height);
}

// The frames of an ECD folder or a bag as (t_us, HxW uint8 array) pairs; FrameError names a bad frame.
py::list read_frames(const std::string& path, int width, int height, const std::string& topic) {
  const auto reader = open_frames(path, topic, SensorSize{width, height});
  py::list frames;
  while (auto frame = reader->next()) {
    py::array_t<std::uint8_t> image({frame->image.rows, frame->image.cols});
    for (int row = 0; row < frame->image.rows; ++row) {
      std::memcpy(image.mutable_data(row, 0), frame->image.ptr(row), static_cast<std::size_t>(frame->image.cols));
    }
    frames.append(py::make_tuple(frame->t_us, image));
  }
  return frames;
}

// A camera's segments and whole lines from a running evldt-lines (the C++ consumer SDK): no lcm
// Python module needed (Debian has none).
class Subscriber {
 public:
  Subscriber(const std::string& camera, const std::string& url)
      : bus_(url), subscriber_(bus_, camera, [this](const client::LineList& list) { pending_.push_back(list); }) {
    if (!bus_.good()) throw std::runtime_error("cannot open LCM at '" + url + "'");
  }
  /// The next list as (whole_lines, camera, t_us, SEGMENT_DTYPE array), or None after `timeout_ms`.
  py::object receive(int timeout_ms) {
    if (pending_.empty()) {
      py::gil_scoped_release released;
      if (bus_.handleTimeout(timeout_ms) < 0) throw std::runtime_error("LCM failed while waiting");
    }
    if (pending_.empty()) return py::none();
    const client::LineList list = std::move(pending_.front());
    pending_.erase(pending_.begin());
    py::array_t<SegmentRecord> lines(static_cast<py::ssize_t>(list.lines.size()));
    auto out = lines.mutable_unchecked<1>();
    for (std::size_t i = 0; i < list.lines.size(); ++i) {
      const client::Line& l = list.lines[i];
      out(static_cast<py::ssize_t>(i)) = {list.t_us,
                                          static_cast<std::uint64_t>(l.id),
                                          l.x0,
                                          l.y0,
                                          l.x1,
                                          l.y1,
                                          l.score,
                                          static_cast<std::uint8_t>(l.status),
                                          0,
                                          0,
                                          l.normal_velocity,
                                          l.normal_velocity_std};
    }
    return py::make_tuple(list.whole_lines, list.camera, list.t_us, lines);
  }
  [[nodiscard]] std::uint64_t undecodable() const { return subscriber_.undecodable(); }

 private:
  lcm::LCM bus_;
  std::vector<client::LineList> pending_;
  client::LineSubscriber subscriber_;
};

}  // namespace
}  // namespace evldt::python

PYBIND11_MODULE(_evldt, m) {
  using namespace evldt;
  using namespace evldt::python;
  m.doc() = "evldt core: recording readers, the deterministic line pipeline, the evaluator and the simulator";
  PYBIND11_NUMPY_DTYPE(EventRecord, t, x, y, p);
  PYBIND11_NUMPY_DTYPE(SegmentRecord, t, id, x0, y0, x1, y1, score, status, first_seen, last_good, normal_velocity,
                       normal_velocity_std);
  PYBIND11_NUMPY_DTYPE(GroundTruthRecord, t, gt_id, x0, y0, x1, y1);
  // A corrupt recording: what the tools print as the error, after the valid prefix was returned.
  py::register_exception<FormatError>(m, "FormatError", PyExc_ValueError);
  py::register_exception<FrameError>(m, "FrameError", PyExc_ValueError);

  m.attr("EVENT_DTYPE") = py::dtype::of<EventRecord>();
  m.attr("SEGMENT_DTYPE") = py::dtype::of<SegmentRecord>();
  m.attr("GROUND_TRUTH_DTYPE") = py::dtype::of<GroundTruthRecord>();

  py::class_<Reader>(m, "Reader")
      .def(py::init<const std::string&, const std::string&, const std::string&, Timestamp>(), py::arg("path"),
           py::arg("format") = "", py::arg("channel") = "", py::arg("time_slack_us") = 1000)
      .def("read", &Reader::read, py::arg("max_events"))
      .def_property_readonly("sensor", &Reader::sensor)
      .def_property_readonly("name", &Reader::name)
      .def_property_readonly("progress", &Reader::progress);

  py::class_<Pipeline>(m, "Pipeline")
      .def(py::init<int, int, const std::vector<std::string>&, Timestamp, bool>(), py::arg("width"), py::arg("height"),
           py::arg("flags"), py::arg("output_period_us"), py::arg("whole_lines") = false)
      .def("process", &Pipeline::process, py::arg("t"), py::arg("x"), py::arg("y"), py::arg("p"))
      .def("segments", &Pipeline::segments)
      .def("whole_lines", &Pipeline::whole_lines)
      .def("counters", &Pipeline::counters);

  py::class_<Subscriber>(m, "Subscriber")
      .def(py::init<const std::string&, const std::string&>(), py::arg("camera"), py::arg("url") = "")
      .def("receive", &Subscriber::receive, py::arg("timeout_ms"))
      .def_property_readonly("undecodable", &Subscriber::undecodable);

  m.def("evaluate", &evaluate, py::arg("segments"), py::arg("ground_truth"), py::arg("width"), py::arg("height"),
        py::arg("tolerances"), py::arg("output_period_us"), py::arg("min_normal_speed") = py::none());
  m.def("simulate", &simulate, py::arg("flags"), py::arg("gt_period_us"));
  m.def("read_frames", &read_frames, py::arg("path"), py::arg("width"), py::arg("height"), py::arg("topic") = "");
}
