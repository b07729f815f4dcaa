#include "evldt/sources/event_source.hpp"

#include <algorithm>
#include <bit>
#include <charconv>
#include <chrono>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>  // its constants; the calls go through evldt::media
#include <stdexcept>
#include <thread>

#include <spdlog/spdlog.h>
#include "evldt/containers/aedat4.hpp"
#include "evldt/containers/hdf5_events.hpp"
#include "evldt/containers/packet_source.hpp"
#include "evldt/events/event_stream_reader.hpp"
#include "evldt/frames/frame_reader.hpp"
#include "evldt/media/media.hpp"
#include "evldt/transport/lcm_log.hpp"

namespace evldt {
namespace {

class RecordingSource final : public EventSource {
 public:
  RecordingSource(std::unique_ptr<EventStreamReader> reader, bool live) : reader_(std::move(reader)), live_(live) {
    name_ = reader_->name() + " (" + std::string(format_name(reader_->format())) + (live ? ", live" : "") + ")";
  }
  bool read(EventBatch& batch) override { return reader_->read(batch); }
  [[nodiscard]] std::optional<SensorSize> geometry() const override { return reader_->geometry(); }
  [[nodiscard]] DecodeCounts decode_counts() const override { return reader_->counts(); }
  [[nodiscard]] double progress() const override {
    if (live_) return 0.0;
    return static_cast<double>(reader_->bytes_read()) /
           static_cast<double>(std::max<std::uint64_t>(1, reader_->total_bytes()));
  }
  [[nodiscard]] bool live() const override { return live_; }

 private:
  std::unique_ptr<EventStreamReader> reader_;
  bool live_;
};

class ReconnectingSource final : public EventSource {
 public:
  ReconnectingSource(std::function<std::unique_ptr<EventSource>()> open, const std::atomic<bool>& stop)
      : open_(std::move(open)), stop_(stop) {
    if (!connect_once()) throw std::runtime_error("stopped before a connection was made");
    geometry_ = current_->geometry();
    name_ = current_->name() + " (reconnecting)";
  }
  bool read(EventBatch& batch) override {
    for (;;) {
      if (!current_) {
        if (!connect_once()) return false;  // stopped
        ++reconnects_;
        spdlog::info("{}: connected again ({} reconnects)", name_, reconnects_);
      }
      try {
        if (current_->read(batch)) return true;
        spdlog::warn("{}: the stream ended; connecting again", name_);
      } catch (const FormatError& error) {  // cut inside a word or packet: the events before it were read
        spdlog::warn("{}: {}; connecting again", name_, error.what());
      }
      retire_current();
      if (stop_.load()) return false;
    }
  }
  [[nodiscard]] std::optional<SensorSize> geometry() const override { return geometry_; }
  [[nodiscard]] DecodeCounts decode_counts() const override {
    DecodeCounts counts = retired_counts_;
    if (current_) counts += current_->decode_counts();
    return counts;
  }
  [[nodiscard]] double progress() const override { return 0.0; }
  [[nodiscard]] bool live() const override { return true; }
  [[nodiscard]] std::uint64_t reconnects() const override { return reconnects_; }

 private:
  /// Connects and reads the header, retrying with back-off; false if stopped first.
  bool connect_once() {
    constexpr auto kFirstWait = std::chrono::milliseconds(100);
    constexpr auto kLongestWait = std::chrono::seconds(2);
    std::chrono::milliseconds wait = kFirstWait;
    for (std::uint64_t attempt = 1; !stop_.load(); ++attempt) {
      try {
        current_ = open_();
        return true;
      } catch (const std::runtime_error& error) {  // no server yet, or a stream that broke in its header
        if (std::has_single_bit(attempt)) spdlog::warn("{} (attempt {}; trying again)", error.what(), attempt);
      }
      for (auto waited = std::chrono::milliseconds(0); waited < wait && !stop_.load();
           waited += std::chrono::milliseconds(50)) {
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
      }
      wait = std::min<std::chrono::milliseconds>(wait * 2, kLongestWait);
    }
    return false;
  }
  void retire_current() {
    retired_counts_ += current_->decode_counts();
    current_.reset();
  }

  std::function<std::unique_ptr<EventSource>()> open_;
  const std::atomic<bool>& stop_;
  std::unique_ptr<EventSource> current_;
  std::optional<SensorSize> geometry_;
  DecodeCounts retired_counts_;
  std::uint64_t reconnects_ = 0;
};

class ContainerSource final : public EventSource {
 public:
  ContainerSource(std::unique_ptr<PacketSource> packets, const std::string& path, bool live = false)
      : path_(path), reader_(std::move(packets), path), live_(live) {
    name_ = path_ + " (" + reader_.source().description() + (live ? ", live" : "") + ")";
  }
  ~ContainerSource() override {
    if (const std::uint64_t skipped = reader_.source().skipped_packets()) {
      spdlog::info("{}: {} packets of other streams skipped", name_, skipped);
    }
  }
  bool read(EventBatch& batch) override { return reader_.read(batch); }
  [[nodiscard]] std::optional<SensorSize> geometry() const override { return geometry_; }
  [[nodiscard]] DecodeCounts decode_counts() const override { return reader_.counts(); }
  [[nodiscard]] double progress() const override { return reader_.source().progress(); }
  [[nodiscard]] bool live() const override { return live_; }
  /// Reads ahead to the first packet where the container has no size (or camera name) of its own.
  void learn_geometry() {
    geometry_ = reader_.geometry();
    const std::string camera = reader_.source().camera();
    if (!camera.empty()) name_ = path_ + " (" + reader_.source().description() + ", camera " + camera + ")";
  }

 private:
  std::string path_;
  PacketEventReader reader_;
  bool live_;
  std::optional<SensorSize> geometry_;
};

class Hdf5Source final : public EventSource {
 public:
  Hdf5Source(const std::filesystem::path& path, const std::string& table) : reader_(path, table) {
    name_ = path.string() + " (" + reader_.description() + ")";
  }
  bool read(EventBatch& batch) override { return reader_.read(batch); }
  [[nodiscard]] std::optional<SensorSize> geometry() const override { return reader_.geometry(); }
  [[nodiscard]] double progress() const override { return reader_.progress(); }

 private:
  Hdf5EventReader reader_;
};

class LcmLogSource final : public EventSource {
 public:
  LcmLogSource(const std::filesystem::path& path, const std::string& channel, Timestamp backwards_slack_us)
      : reader_(path, channel, backwards_slack_us) {
    name_ = path.string() + " (lcm-log, " + reader_.channel() + ")";
  }
  ~LcmLogSource() override {
    const ReceiverCounts counts = reader_.counts();
    if (counts.sequence.lost || counts.invalid_messages) {
      spdlog::warn("{}: {} batches missing by sequence number, {} invalid messages skipped", name_,
                   counts.sequence.lost, counts.invalid_messages);
    }
  }
  bool read(EventBatch& batch) override { return reader_.read(batch); }
  [[nodiscard]] std::optional<SensorSize> geometry() const override { return reader_.sensor(); }
  [[nodiscard]] double progress() const override { return reader_.progress(); }

 private:
  LcmLogEventReader reader_;
};

class SceneSource final : public EventSource {
 public:
  SceneSource(Scene scene, const SimulatorConfig& config, const std::string& label)
      : simulator_(std::move(scene), config) {
    name_ = "scene " + label;
  }
  bool read(EventBatch& batch) override {
    batch.clear();
    constexpr Timestamp kSliceUs = 10000;
    return simulator_.run_until(simulator_.now_us() + kSliceUs, batch);
  }
  [[nodiscard]] std::optional<SensorSize> geometry() const override { return simulator_.scene().sensor; }
  [[nodiscard]] double progress() const override {
    return static_cast<double>(simulator_.now_us()) / static_cast<double>(simulator_.scene().duration_us);
  }

 private:
  EventSimulator simulator_;
};

class VideoSource final : public EventSource {
 public:
  explicit VideoSource(const VideoSourceOptions& options) {
    int index = -1;
    const auto& input = options.input;
    const auto [end, error] = std::from_chars(input.data(), input.data() + input.size(), index);
    live_ = error == std::errc() && end == input.data() + input.size();
    const bool opened = live_ ? capture_.open(index) : capture_.open(input, cv::CAP_ANY);
    if (!opened) throw std::runtime_error("cannot open video " + std::string(live_ ? "camera " : "file ") + input);
    if (!live_) frame_count_ = capture_.get(cv::CAP_PROP_FRAME_COUNT);
    const double file_fps = capture_.get(cv::CAP_PROP_FPS);
    fps_ = options.fps_override > 0 ? options.fps_override : (file_fps > 0 && file_fps < 10000 ? file_fps : 30.0);
    if (!capture_.read(frame_) || frame_.empty()) throw std::runtime_error("no frame in video " + input);
    sensor_ = {frame_.cols, frame_.rows};
    emulator_.emplace(sensor_, options.emulator);
    name_ = "video " + input + " (" + std::to_string(sensor_.width) + "x" + std::to_string(sensor_.height) +
            ", frame differencing)";
    started_ = std::chrono::steady_clock::now();
    add_frame(nullptr);  // the first frame only sets the reference
  }
  bool read(EventBatch& batch) override {
    batch.clear();
    while (batch.empty()) {  // a static scene gives frames without events
      if (!capture_.read(frame_) || frame_.empty()) return false;
      if (frame_.cols != sensor_.width || frame_.rows != sensor_.height) {
        throw std::runtime_error(name_ + ": frame size changed mid-stream");
      }
      add_frame(&batch);
    }
    return true;
  }
  [[nodiscard]] std::optional<SensorSize> geometry() const override { return sensor_; }
  [[nodiscard]] double progress() const override {
    return frame_count_ > 0 ? std::min(1.0, static_cast<double>(frames_) / frame_count_) : 0.0;
  }

 private:
  void add_frame(EventBatch* out) {
    if (frame_.channels() == 1) {
      frame_.copyTo(grey_);
    } else {
      cv::cvtColor(frame_, grey_, frame_.channels() == 4 ? cv::COLOR_BGRA2GRAY : cv::COLOR_BGR2GRAY);
    }
    if (grey_.depth() != CV_8U) grey_.convertTo(grey_, CV_8U);
    const Timestamp t =
        live_
            ? std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::steady_clock::now() - started_).count()
            : video_frame_time_us(frames_, fps_);
    // Frame times must increase; a webcam may deliver two frames within a microsecond.
    const Timestamp frame_t = std::max(t, last_t_ + 1);
    last_t_ = frame_t;
    ++frames_;
    EventBatch discard;
    emulator_->add_frame(std::span<const std::uint8_t>(grey_.ptr<std::uint8_t>(), grey_.total()), frame_t,
                         out ? *out : discard);
  }

  media::VideoCapture capture_;
  bool live_ = false;
  double fps_ = 30;
  double frame_count_ = 0;
  SensorSize sensor_;
  std::optional<FrameDifferenceEmulator> emulator_;
  cv::Mat frame_, grey_;
  std::uint64_t frames_ = 0;
  Timestamp last_t_ = -1;
  std::chrono::steady_clock::time_point started_;
};

}  // namespace

std::unique_ptr<EventSource> open_recording(const std::filesystem::path& path, std::optional<EventFormat> format,
                                            const std::string& channel, Timestamp backwards_slack_us) {
  if (!format && is_lcm_log(path)) return std::make_unique<LcmLogSource>(path, channel, backwards_slack_us);
  if (!format && is_hdf5(path)) return std::make_unique<Hdf5Source>(path, channel);
  if (!format) {
    if (auto packets = open_packet_container(path, channel)) {
      auto source = std::make_unique<ContainerSource>(std::move(packets), path);
      source->learn_geometry();
      return source;
    }
  }
  return std::make_unique<RecordingSource>(std::make_unique<EventStreamReader>(path, format), false);
}

std::unique_ptr<EventSource> open_stream(std::unique_ptr<ByteSource> bytes, std::optional<EventFormat> format,
                                         std::string_view extension) {
  return std::make_unique<RecordingSource>(std::make_unique<EventStreamReader>(std::move(bytes), format, extension),
                                           true);
}

std::unique_ptr<EventSource> open_dv_stream(std::unique_ptr<ByteSource> bytes) {
  const std::string name = bytes->name();
  auto source = std::make_unique<ContainerSource>(open_aedat4_stream(std::move(bytes)), name, true);
  source->learn_geometry();
  return source;
}

std::unique_ptr<EventSource> open_reconnecting(std::function<std::unique_ptr<EventSource>()> open,
                                               const std::atomic<bool>& stop) {
  return std::make_unique<ReconnectingSource>(std::move(open), stop);
}

std::unique_ptr<EventSource> open_scene(Scene scene, const SimulatorConfig& config, const std::string& label) {
  return std::make_unique<SceneSource>(std::move(scene), config, label);
}

std::unique_ptr<EventSource> open_video(const VideoSourceOptions& options) {
  return std::make_unique<VideoSource>(options);
}

}  // namespace evldt
