// The service nodes wired together in one process over LCM's in-memory transport (memq://): the
// same code paths as the real processes, without sockets.

#include <gtest/gtest.h>

#include <sched.h>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <lcm/lcm-cpp.hpp>
#include <map>
#include <mutex>
#include <opencv2/core.hpp>
#include <set>
#include <thread>

#include "evldt/camera_info_t.hpp"
#include "evldt/events/event_writer.hpp"
#include "evldt/nodes/camera_node.hpp"
#include "evldt/nodes/lines_node.hpp"
#include "evldt/nodes/viz_node.hpp"
#include "evldt/sim/scenes.hpp"
#include "evldt/transport/channels.hpp"
#include "evldt/transport/messages.hpp"
#include "support/temp_dir.hpp"

namespace evldt {
namespace {

using namespace std::chrono_literals;

// Records every segment list published on a channel.
class ListCollector {
 public:
  ListCollector(lcm::LCM& lcm, const std::string& channel) { lcm.subscribe(channel, &ListCollector::on_list, this); }
  void on_list(const lcm::ReceiveBuffer* buffer, const std::string&) {
    segment_list_t msg;
    const std::span<const std::uint8_t> bytes(static_cast<const std::uint8_t*>(buffer->data), buffer->data_size);
    std::lock_guard lock(mutex_);
    if (decode_message(bytes, msg) == WireError::None) {
      lists_.push_back(msg);
    } else {
      ++invalid_;
    }
  }
  std::vector<segment_list_t> lists() const {
    std::lock_guard lock(mutex_);
    return lists_;
  }
  int invalid() const {
    std::lock_guard lock(mutex_);
    return invalid_;
  }

 private:
  mutable std::mutex mutex_;
  std::vector<segment_list_t> lists_;
  int invalid_ = 0;
};

// Waits for a condition: a loaded machine or a sanitizer build is slow, not wrong, so the limit is generous.
template <typename Condition>
bool wait_for(Condition condition, std::chrono::milliseconds limit = 120000ms) {
  const auto deadline = std::chrono::steady_clock::now() + limit;
  while (!condition()) {
    if (std::chrono::steady_clock::now() > deadline) return false;
    std::this_thread::sleep_for(5ms);
  }
  return true;
}

CameraNode::SourceFactory scene_source(const std::string& name, Timestamp duration_us) {
  return [=] {
    Scene scene = make_scene(name);
    scene.duration_us = duration_us;
    return open_scene(std::move(scene), SimulatorConfig{}, name);
  };
}

CameraNodeOptions fast_camera() {
  CameraNodeOptions options;
  options.speed = 0;  // as fast as possible: memq queues everything
  options.progress_period_s = 0;
  return options;
}

LinesNodeOptions quiet_lines() {
  LinesNodeOptions options;
  options.publish_hz = 500;
  options.whole_lines_hz = 500;  // a whole-line list with every segment list
  options.log_period_s = 0;
  options.max_latency_ms = 0;  // these tests count every event: a slow (sanitizer) build must not shed
  return options;
}

// Runs a lines node on its own thread for the lifetime of the object.
class RunningLines {
 public:
  RunningLines(lcm::LCM& lcm, std::int64_t epoch, const LinesNodeOptions& options = quiet_lines())
      : node(lcm, options, epoch), thread_([this] { node.run(stop_); }) {}
  ~RunningLines() { stop(); }
  void stop() {
    stop_ = true;
    if (thread_.joinable()) thread_.join();
  }
  LinesNode node;

 private:
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

void publish_raw(lcm::LCM& lcm, const std::string& channel, const std::vector<std::uint8_t>& bytes) {
  ASSERT_EQ(lcm.publish(channel, bytes.data(), static_cast<unsigned>(bytes.size())), 0);
}

template <typename Message>
std::vector<std::uint8_t> encode(const Message& msg) {
  std::vector<std::uint8_t> bytes(static_cast<std::size_t>(msg.getEncodedSize()));
  msg.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  return bytes;
}

TEST(Nodes, CameraToLinesDeliversEveryBatchAndValidSegments) {
  lcm::LCM lcm("memq://");
  ASSERT_TRUE(lcm.good());
  ListCollector collector(lcm, "LINES_CAM0");
  ListCollector whole_collector(lcm, "WHOLE_LINES_CAM0");
  constexpr std::int64_t kEpoch = 5'000'000;
  const int kBlock = default_config_for(SensorSize{240, 180}).lattice.block_size;
  LinesNodeOptions options = quiet_lines();
  constexpr double kWholeLinesHz = 250;
  options.whole_lines_hz = kWholeLinesHz;
  RunningLines lines(lcm, kEpoch, options);
  // In real time, so that the whole lines below are published many times over a busy host too (at
  // full speed the stream could be stored in a few gulps).
  CameraNodeOptions real_time = fast_camera();
  real_time.speed = 1;
  CameraNode camera(lcm, real_time, 77);
  const std::atomic<bool> never{false};
  const CameraSummary sent = camera.run(scene_source("boxes-6dof", 400'000), never);
  ASSERT_GT(sent.batches, 300u);
  ASSERT_EQ(sent.events_published, sent.events_read);
  EXPECT_NEAR(static_cast<double>(sent.bytes) / static_cast<double>(sent.events_published), 9.0, 1.0);

  // Eventually a list includes the last batch: every event reached the lattice and was tracked on.
  const auto last_seq = static_cast<std::int64_t>(sent.batches - 1);
  ASSERT_TRUE(wait_for([&] {
    const auto lists = collector.lists();
    return !lists.empty() && lists.back().newest_batch_seq == last_seq;
  }));
  lines.stop();
  const LinesNodeTotals totals = lines.node.totals();
  EXPECT_EQ(totals.receiver.sequence.received, sent.batches);
  EXPECT_EQ(totals.receiver.sequence.lost, 0u);
  EXPECT_EQ(totals.receiver.invalid_messages, 0u);
  EXPECT_EQ(totals.events_received, sent.events_published);
  EXPECT_EQ(totals.filtered.events_in, sent.events_published);
  EXPECT_EQ(totals.events_stored, totals.filtered.passed);
  EXPECT_GT(totals.track_rounds, 0u);
  EXPECT_EQ(collector.invalid(), 0);
  // One host, one clock: LCM's receipt stamps and the camera's publish stamps agree, so latency is
  // measured from the publish.
  ASSERT_TRUE(totals.publish_clock_offset_us.has_value());
  EXPECT_LT(std::abs(*totals.publish_clock_offset_us), LatencyTracker::kClocksApartUs);
  EXPECT_EQ(totals.latency_from_receipt, 0u);

  const auto lists = collector.lists();
  std::size_t most_segments = 0;
  std::int64_t previous_seq = -1;
  for (const auto& list : lists) {
    EXPECT_EQ(list.seq, previous_seq + 1);
    previous_seq = list.seq;
    EXPECT_EQ(list.source, "cam0");
    EXPECT_EQ(list.width, 240);
    EXPECT_EQ(list.height, 180);
    EXPECT_EQ(list.epoch, kEpoch);
    most_segments = std::max(most_segments, list.segments.size());
    std::vector<TrackedLine> decoded;
    ASSERT_TRUE(read_segment_list(list, decoded));
    for (const auto& line : decoded) {
      EXPECT_GE(line.id, static_cast<std::uint64_t>(kEpoch));  // ids start at the process epoch
      for (const Point2& q : {line.segment.q0, line.segment.q1}) {
        EXPECT_TRUE(q.x() >= 0 && q.x() <= 240 && q.y() >= 0 && q.y() <= 180) << q.transpose();
      }
      // f = r_o * r_e with r_o <= 1 and r_e <= (blocks the line crosses), as r_e is normalised by
      // one block's capacity (EffectiveRatioNorm::Block); a segment of length L crosses at most
      // sqrt(2) L / b + 2 blocks.
      const float max_blocks = std::sqrt(2.0f) * line.segment.length() / static_cast<float>(kBlock) + 2.0f;
      EXPECT_GE(line.score, 0.0f);
      EXPECT_LE(line.score, max_blocks) << line.segment.length();
    }
  }
  EXPECT_GE(most_segments, 10u);  // boxes-6dof shows some 20 edges

  // Whole lines: at most 250 lists a second (segment lists come at up to 500), each sent with a
  // segment list (same publish time, lattice time and batch fields); each joins segments of that
  // list (its score counts them; lines too short to publish hold the rest), and a line keeps its
  // id while it lasts. (LCM may hand over the last one of either kind after the snapshots above.)
  const auto whole = whole_collector.lists();
  ASSERT_GE(whole.size(), 5u);
  ASSERT_LE(whole.size(), lists.size());
  const double span_s = static_cast<double>(whole.back().utime - whole.front().utime) * 1e-6;
  EXPECT_LE(static_cast<double>(whole.size() - 1), span_s * kWholeLinesHz * 2 + 1);  // a publish period early at most
  EXPECT_EQ(whole_collector.invalid(), 0);
  std::size_t fewer = 0, continued = 0, both = 0;
  double joined_segments = 0, all_segments = 0;
  std::set<std::uint64_t> previous_ids;
  std::size_t next_list = 0;
  for (std::size_t k = 0; k < whole.size(); ++k) {
    while (next_list < lists.size() && lists[next_list].utime < whole[k].utime) ++next_list;
    if (next_list == lists.size()) break;  // its segment list came after the snapshot
    const segment_list_t& list = lists[next_list];
    ++both;
    EXPECT_EQ(whole[k].seq, static_cast<std::int64_t>(k));
    EXPECT_EQ(whole[k].utime, list.utime);
    EXPECT_EQ(whole[k].t_us, list.t_us);
    EXPECT_EQ(whole[k].newest_batch_seq, list.newest_batch_seq);
    std::vector<TrackedLine> joined;
    ASSERT_TRUE(read_segment_list(whole[k], joined));
    double segments = 0;
    std::set<std::uint64_t> ids;
    for (const auto& line : joined) {
      EXPECT_GE(line.id, static_cast<std::uint64_t>(kEpoch));
      segments += line.score;
      ids.insert(line.id);
      continued += previous_ids.count(line.id);
    }
    EXPECT_LE(segments, static_cast<double>(list.segments.size()));
    joined_segments += segments;
    all_segments += static_cast<double>(list.segments.size());
    fewer += joined.size() < list.segments.size() ? 1 : 0;
    previous_ids = ids;
  }
  EXPECT_GT(fewer, both / 2);                      // segments along one edge are joined
  EXPECT_GT(continued, both);                      // ids carry over from list to list
  EXPECT_GT(joined_segments, 0.6 * all_segments);  // most segments lie along published lines
}

// Every statistics message a service publishes.
class StatsCollector {
 public:
  explicit StatsCollector(lcm::LCM& lcm) { lcm.subscribe(std::string(kStatsChannel), &StatsCollector::on_stats, this); }
  void on_stats(const lcm::ReceiveBuffer* buffer, const std::string&) {
    stats_t msg;
    const std::span<const std::uint8_t> bytes(static_cast<const std::uint8_t*>(buffer->data), buffer->data_size);
    if (decode_message(bytes, msg) == WireError::None) messages_.push_back(msg);
  }
  std::vector<stats_t> messages_;
};

TEST(Nodes, CameraStatisticsCountTheWordsItsDecoderSkipped) {
  // An EVT 3.0 recording padded with 0x9999 words, as some IMX636 cameras write it.
  test_support::TempDir dir;
  const auto path = dir.file("padded.raw");
  EventBatch events;
  for (int i = 0; i < 5000; ++i)
    events.push_back(1000 + 20 * i, static_cast<std::uint16_t>(i % 640), static_cast<std::uint16_t>(i % 480), 1);
  std::vector<std::uint8_t> words;
  detail::make_evt3_encoder({640, 480})->encode(events, words);
  std::string file = "% format EVT3;height=480;width=640\n% end\n";
  int padding = 0;
  for (std::size_t at = 0; at < words.size(); at += 2) {
    if (at % 200 == 0) {
      file += "\x99\x99";
      ++padding;
    }
    file.append(reinterpret_cast<const char*>(words.data() + at), 2);
  }
  std::ofstream(path, std::ios::binary) << file;

  lcm::LCM lcm("memq://");
  StatsCollector stats(lcm);
  CameraNode camera(lcm, fast_camera(), 77);
  const std::atomic<bool> never{false};
  const CameraSummary sent = camera.run([&] { return open_recording(path, std::nullopt, "", 1000); }, never);
  EXPECT_EQ(sent.events_published, events.size());
  EXPECT_EQ(sent.decoded.skipped_words, static_cast<std::uint64_t>(padding));
  while (lcm.handleTimeout(0) > 0) {
  }
  ASSERT_FALSE(stats.messages_.empty());
  const stats_t& last = stats.messages_.back();  // the one at the end of the run
  EXPECT_EQ(last.service, "evldt-camera");
  EXPECT_EQ(last.source, "cam0");
  EXPECT_EQ(last.words_skipped, padding);
  EXPECT_EQ(last.trigger_events, 0);
  EXPECT_EQ(last.events_in, static_cast<std::int64_t>(events.size()));
  EXPECT_EQ(last.batches_received, static_cast<std::int64_t>(sent.batches));
}

TEST(Nodes, GarbageAndForeignMessagesAreCountedNotFatal) {
  lcm::LCM lcm("memq://");
  RunningLines lines(lcm, 1);
  publish_raw(lcm, "EVENTS_CAM0", {'h', 'e', 'l', 'l', 'o'});
  publish_raw(lcm, "EVENTS_CAM0", encode(segment_list_t{}));  // a real LCM type, but not ours to receive here
  publish_raw(lcm, "EVENTS_CAM0", {});
  EventBatch events;
  events.push_back(10, 5, 5, 1);
  events.push_back(20, 500, 5, 1);  // off the 240x180 sensor
  event_batch_t batch;
  batch.width = 6;  // first, a sensor too small for any lattice: refused, not adopted (nor a crash)
  batch.height = 6;
  batch.source = "test";
  std::vector<std::uint8_t> bytes;
  encode_event_batch(batch, EventBatch{}, bytes);
  publish_raw(lcm, "EVENTS_CAM0", bytes);
  batch.width = 240;
  batch.height = 180;
  encode_event_batch(batch, events, bytes);
  publish_raw(lcm, "EVENTS_CAM0", bytes);
  batch.width = 320;  // a second sensor size on the same channel
  batch.seq = 1;
  encode_event_batch(batch, events, bytes);
  publish_raw(lcm, "EVENTS_CAM0", bytes);
  ASSERT_TRUE(wait_for([&] { return lines.node.totals().receiver.invalid_messages == 5; }));
  lines.stop();
  const LinesNodeTotals totals = lines.node.totals();
  EXPECT_EQ(totals.events_received, 1u);
  EXPECT_EQ(totals.receiver.drops.off_sensor, 1u);
  EXPECT_EQ(totals.receiver.sequence.received, 1u);
}

// A configured sensor size: the engine is built at start (no batch queues behind it) and serves
// the first batch; nothing is published before a batch has come, and it is not counted as a restart.
/// The scheduling policy of each of this process's threads, by thread name.
std::multimap<std::string, int> thread_policies() {
  std::multimap<std::string, int> policies;
  for (const auto& task : std::filesystem::directory_iterator("/proc/self/task")) {
    std::string name;
    std::getline(std::ifstream(task.path() / "comm"), name);
    policies.emplace(name, sched_getscheduler(std::stoi(task.path().filename().string())));
  }
  return policies;
}

TEST(Nodes, ConfiguredSensorEngineServesTheFirstBatch) {
  lcm::LCM lcm("memq://");
  ListCollector collector(lcm, "LINES_CAM0");
  LinesNodeOptions options = quiet_lines();
  options.sensor = SensorSize{240, 180};
  constexpr std::int64_t kEpoch = 3'000'000;
  RunningLines lines(lcm, kEpoch, options);
  std::this_thread::sleep_for(1200ms);  // longer than the heartbeat (1 s) of a service that has lines
  EXPECT_TRUE(collector.lists().empty());
  // The rounds were started with the engine and wait; they and the publishers (of segment lists,
  // and of whole lines on a thread of its own) are batch work, which never preempts storage when it wakes.
  const auto policies = thread_policies();
  for (const char* name : {"evldt-detect", "evldt-track", "evldt-publish", "evldt-whole"}) {
    ASSERT_EQ(policies.count(name), 1u) << name;
    EXPECT_EQ(policies.find(name)->second, SCHED_BATCH) << name;
  }
  // Storage has a thread of its own, which does preempt them.
  ASSERT_EQ(policies.count("evldt-store"), 1u);
  EXPECT_EQ(policies.find("evldt-store")->second, SCHED_OTHER);
  const std::atomic<bool> never{false};
  const CameraSummary sent = CameraNode(lcm, fast_camera(), 1).run(scene_source("boxes-6dof", 200'000), never);
  ASSERT_TRUE(wait_for([&] {
    const auto lists = collector.lists();
    return !lists.empty() && lists.back().newest_batch_seq == static_cast<std::int64_t>(sent.batches - 1);
  }));
  lines.stop();
  const LinesNodeTotals totals = lines.node.totals();
  EXPECT_EQ(totals.engine_restarts, 0u);
  EXPECT_EQ(totals.receiver.sequence.lost, 0u);
  EXPECT_EQ(totals.events_received, sent.events_published);
  EXPECT_EQ(totals.events_stored, totals.filtered.passed);
  EXPECT_GT(totals.lines_created, 0u);
  std::size_t segments = 0;
  for (const auto& list : collector.lists()) {
    EXPECT_EQ(list.width, 240);
    for (const auto& entry : list.segments)
      EXPECT_GE(static_cast<std::uint64_t>(entry.id), static_cast<std::uint64_t>(kEpoch));
    segments += list.segments.size();
  }
  EXPECT_GT(segments, 0u);
}

// Records every CAMERA_INFO message of a camera.
class CameraInfoCollector {
 public:
  explicit CameraInfoCollector(lcm::LCM& lcm) {
    lcm.subscribe("CAMERA_INFO_CAM0", &CameraInfoCollector::on_info, this);
  }
  void on_info(const lcm::ReceiveBuffer* buffer, const std::string&) {
    camera_info_t msg;
    const std::span<const std::uint8_t> bytes(static_cast<const std::uint8_t*>(buffer->data), buffer->data_size);
    std::lock_guard lock(mutex_);
    if (decode_message(bytes, msg) == WireError::None) infos_.push_back(msg);
  }
  std::vector<camera_info_t> infos() const {
    std::lock_guard lock(mutex_);
    return infos_;
  }

 private:
  mutable std::mutex mutex_;
  std::vector<camera_info_t> infos_;
};

TEST(Nodes, WithACalibrationTheLinesComeWithTheirCamera) {
  lcm::LCM lcm("memq://");
  ListCollector collector(lcm, "LINES_CAM0");
  CameraInfoCollector cameras(lcm);
  LinesNodeOptions options = quiet_lines();
  // A calibration whose table keeps every pixel (libs/calibration makes real ones; tested there).
  options.configure = [](SensorSize sensor) {
    PipelineConfig config = default_config_for(sensor);
    std::vector<std::int32_t> sources(static_cast<std::size_t>(sensor.width) * static_cast<std::size_t>(sensor.height));
    for (std::size_t i = 0; i < sources.size(); ++i) sources[i] = static_cast<std::int32_t>(i);
    auto table = std::make_shared<RectificationTable>(RectificationTable::from_sources(sensor, sources));
    table->lens = {199.1, 198.8, 132.2, 110.7, "radtan", {-0.37, 0.15, -0.0003, -0.0008}, "davis240c.yaml"};
    config.calibration = "davis240c.yaml";
    config.rectification = table;
    return config;
  };
  RunningLines lines(lcm, 4'000'000, options);
  const std::atomic<bool> never{false};
  const CameraSummary sent = CameraNode(lcm, fast_camera(), 1).run(scene_source("boxes-6dof", 200'000), never);
  // Until a list holds the last batch (every event stored), and the camera came twice.
  ASSERT_TRUE(wait_for([&] {
    const auto lists = collector.lists();
    return cameras.infos().size() >= 2 && !lists.empty() &&
           lists.back().newest_batch_seq == static_cast<std::int64_t>(sent.batches - 1);
  }));
  lines.stop();
  const camera_info_t info = cameras.infos().back();
  EXPECT_EQ(info.source, "cam0");
  EXPECT_EQ(info.epoch, 4'000'000);
  EXPECT_EQ(info.width, 240);
  EXPECT_EQ(info.height, 180);
  EXPECT_DOUBLE_EQ(info.fx, 199.1);
  EXPECT_DOUBLE_EQ(info.cy, 110.7);
  EXPECT_EQ(info.sensor_distortion, "radtan");
  EXPECT_EQ(info.calibration, "davis240c.yaml");
  EXPECT_EQ(info.coefficients, (std::vector<double>{-0.37, 0.15, -0.0003, -0.0008}));
  EXPECT_EQ(lines.node.totals().events_received, sent.events_published);
}

TEST(Nodes, ASensorTheConfigurationRefusesIsCountedNotFatal) {
  // A calibration of a 240x180 camera, and a 346x260 camera on the channel: its batches are refused
  // and counted, and the service goes on.
  lcm::LCM lcm("memq://");
  LinesNodeOptions options = quiet_lines();
  options.configure = [](SensorSize sensor) {
    if (!(sensor == SensorSize{240, 180})) throw std::invalid_argument("the calibration is of a 240x180 camera");
    return default_config_for(sensor);
  };
  RunningLines lines(lcm, 6'000'000, options);
  const std::atomic<bool> never{false};
  const CameraSummary sent = CameraNode(lcm, fast_camera(), 1).run(scene_source("multi-speed", 100'000), never);
  ASSERT_TRUE(wait_for([&] { return lines.node.totals().receiver.invalid_messages == sent.batches; }));
  lines.stop();
  EXPECT_EQ(lines.node.totals().events_received, 0u);
}

TEST(Nodes, CameraRestartBeginsAfreshWithoutRepeatingIds) {
  lcm::LCM lcm("memq://");
  ListCollector collector(lcm, "LINES_CAM0");
  ListCollector whole_collector(lcm, "WHOLE_LINES_CAM0");
  RunningLines lines(lcm, 1000);
  const std::atomic<bool> never{false};
  const auto source = scene_source("boxes-6dof", 200'000);
  const CameraSummary first = CameraNode(lcm, fast_camera(), 1).run(source, never);
  ASSERT_TRUE(wait_for([&] {
    const auto lists = collector.lists();
    return !lists.empty() && lists.back().newest_batch_seq == static_cast<std::int64_t>(first.batches - 1);
  }));
  const std::size_t lists_before = collector.lists().size();
  // The camera process restarts: a newer epoch, sequence and event time from zero again. It runs in
  // real time, so that the new engine's state is published many times on the way (at full speed
  // it could end before the next publish), and the wait is for every event to have arrived: the
  // old engine's last list also names the last batch (same scene, same sequence numbers).
  CameraNodeOptions real_time = fast_camera();
  real_time.speed = 1;
  const CameraSummary second = CameraNode(lcm, real_time, 2).run(source, never);
  ASSERT_TRUE(wait_for([&] {
    const auto lists = collector.lists();
    return lines.node.totals().events_received == first.events_published + second.events_published &&
           lists.size() > lists_before &&
           lists.back().newest_batch_seq == static_cast<std::int64_t>(second.batches - 1) &&
           lists.back().t_us < 200'000 + 1000;
  }));
  lines.stop();
  const LinesNodeTotals totals = lines.node.totals();
  EXPECT_EQ(totals.engine_restarts, 1u);
  EXPECT_EQ(totals.receiver.sequence.restarts, 1u);
  EXPECT_EQ(totals.receiver.sequence.lost, 0u);
  EXPECT_EQ(totals.receiver.drops.total(), 0u);  // the restarted clock is not "time backwards"
  EXPECT_EQ(totals.events_received, first.events_published + second.events_published);
  EXPECT_EQ(totals.events_stored, totals.filtered.passed);

  // Ids of the first camera run and of the second never overlap: the largest id of the lists
  // before the restart (the first list whose event time went back), and the smallest of the new
  // engine's lists.
  const auto expect_ids_apart = [](const std::vector<segment_list_t>& lists) {
    std::size_t restart = 1;
    while (restart < lists.size() && lists[restart].t_us >= lists[restart - 1].t_us) ++restart;
    ASSERT_LT(restart, lists.size()) << "no list of the restarted engine";
    std::uint64_t max_before = 0, min_after = UINT64_MAX;
    for (std::size_t i = 0; i < lists.size(); ++i) {
      for (const auto& entry : lists[i].segments) {
        const auto id = static_cast<std::uint64_t>(entry.id);
        if (i < restart) max_before = std::max(max_before, id);
        if (i >= restart && lists[i].t_us < lists[restart - 1].t_us) min_after = std::min(min_after, id);
      }
    }
    ASSERT_GT(max_before, 0u);
    ASSERT_LT(min_after, UINT64_MAX);
    EXPECT_GT(min_after, max_before);
  };
  const auto lists = collector.lists();
  ASSERT_GT(lists.size(), lists_before);
  expect_ids_apart(lists);
  expect_ids_apart(whole_collector.lists());  // so do the whole lines'
}

// What the viz tests draw from: a vertical run of events at x = 50 from time t0 on, and a good track
// at x = 150.5 in a list of event time list_t.
void publish_column_and_line(lcm::LCM& lcm, Timestamp t0, Timestamp list_t) {
  EventBatch events;
  for (std::uint16_t y = 20; y < 120; ++y) events.push_back(t0 + y, 50, y, 1);
  event_batch_t batch;
  batch.width = 240;
  batch.height = 180;
  std::vector<std::uint8_t> bytes;
  encode_event_batch(batch, events, bytes);
  publish_raw(lcm, "EVENTS_CAM0", bytes);
  TrackedLine line;
  line.id = 9;
  line.segment = {Point2(150.5f, 20.5f), Point2(150.5f, 160.5f)};
  line.score = 0.9f;
  line.status = LineStatus::GoodTrack;
  segment_list_t list;
  fill_segment_list(std::span<const TrackedLine>(&line, 1), list);
  list.width = 240;
  list.height = 180;
  list.t_us = list_t;
  publish_raw(lcm, "LINES_CAM0", encode(list));
}

VizNodeOptions twice_scale_viz_options() {
  VizNodeOptions options;
  options.render_hz = 200;
  options.render.scale = 2;
  return options;
}

// Runs the viz until it has rendered `frames` frames; the last of them.
cv::Mat render_frames(VizNode& viz, std::uint64_t frames) {
  cv::Mat last;
  const std::atomic<bool> never{false};
  viz.run(never, [&](const cv::Mat& frame) {
    frame.copyTo(last);
    return viz.totals().frames < frames;
  });
  return last;
}

TEST(Nodes, VizTakesACameraClockInUnixTime) {
  // A live camera's events stamped in Unix microseconds: drawn, and the time shown from the first.
  lcm::LCM lcm("memq://");
  VizNode viz(lcm, twice_scale_viz_options());
  constexpr Timestamp kEpochCameraUs = 1'700'000'000'000'000;
  publish_column_and_line(lcm, kEpochCameraUs, kEpochCameraUs + 250'000);
  const cv::Mat last = render_frames(viz, 2);
  EXPECT_EQ(viz.totals().segment_lists, 1u);
  EXPECT_EQ(viz.totals().events.invalid_messages, 0u);
  EXPECT_GT(last.at<cv::Vec3b>(2 * 70, 2 * 50)[0], 40);  // the events' column, at twice the scale
  ASSERT_FALSE(viz.status().empty());
  EXPECT_EQ(viz.status()[0][1], "t=0.250 s");
}

TEST(Nodes, VizDrawsEventsSegmentsAndStatus) {
  lcm::LCM lcm("memq://");
  VizNode viz(lcm, twice_scale_viz_options());

  publish_column_and_line(lcm, 1000, 0);
  publish_raw(lcm, "LINES_CAM0", {1, 2, 3});  // refused, counted
  stats_t stats{};  // evldt-lines masks the hot pixel (200, 40); evldt-camera's statistics are not drawn
  stats.service = "evldt-lines";
  stats.source = "cam0";
  stats.masked_pixels = {40 * 240 + 200};
  stats.num_masked_pixels = 1;
  publish_raw(lcm, std::string(kStatsChannel), encode(stats));
  stats.service = "evldt-camera";
  stats.masked_pixels.clear();
  stats.num_masked_pixels = 0;
  publish_raw(lcm, std::string(kStatsChannel), encode(stats));

  const cv::Mat last = render_frames(viz, 3);
  EXPECT_EQ(viz.totals().frames, 3u);
  EXPECT_EQ(viz.totals().segment_lists, 1u);
  EXPECT_EQ(viz.totals().invalid_segment_lists, 1u);
  ASSERT_EQ(last.cols, 480);
  ASSERT_EQ(last.rows, 360);
  // The event column is drawn grey and the good track green, at twice the scale.
  const cv::Vec3b event_pixel = last.at<cv::Vec3b>(2 * 70, 2 * 50);
  EXPECT_GT(event_pixel[0], 40);
  int green = 0, red = 0;  // anti-aliased: look across the line's width
  for (int x = 2 * 150 - 2; x <= 2 * 150 + 4; ++x) {
    green = std::max<int>(green, last.at<cv::Vec3b>(2 * 90, x)[1]);
    red = std::max<int>(red, last.at<cv::Vec3b>(2 * 90, x)[2]);
  }
  EXPECT_GT(green, 100);
  EXPECT_LT(red, 60);
  // The masked pixel is ringed in magenta (radius 6 at scale 2, centred on the pixel).
  const cv::Vec3b ring = last.at<cv::Vec3b>(2 * 40 + 1, 2 * 200 + 1 + 6);
  EXPECT_GT(ring[0], 100);
  EXPECT_GT(ring[2], 100);
  EXPECT_LT(ring[1], 60);
}

// A frame that takes longer than its period (a slow machine, a big sensor at a high --fps) must not
// starve the messages: everything that arrived before a frame is in it.
TEST(Nodes, VizThatDrawsSlowlyStillHandlesEveryMessageBeforeEachFrame) {
  lcm::LCM lcm("memq://");
  VizNodeOptions options;
  options.render_hz = 200;  // a 5 ms period; each frame below takes 30 ms, so the next is always due
  VizNode viz(lcm, options);
  event_batch_t batch;
  batch.width = 240;
  batch.height = 180;
  std::vector<std::uint8_t> bytes;
  auto publish_batch = [&](int seq) {
    EventBatch events;
    events.push_back(1000 * seq, static_cast<std::uint16_t>(10 + seq), 50, 1);
    batch.seq = seq;
    encode_event_batch(batch, events, bytes);
    publish_raw(lcm, "EVENTS_CAM0", bytes);
  };
  publish_batch(0);
  constexpr int kBatches = 40;
  std::vector<VizTotals> at_frame;
  const std::atomic<bool> never{false};
  viz.run(never, [&](const cv::Mat&) {
    at_frame.push_back(viz.totals());
    if (at_frame.size() == 1) {
      // Messages arrive while the first frame is being drawn.
      for (int seq = 1; seq < kBatches; ++seq) publish_batch(seq);
      segment_list_t list;
      fill_segment_list(std::span<const TrackedLine>(), list);
      list.width = 240;
      list.height = 180;
      publish_raw(lcm, "LINES_CAM0", encode(list));
    }
    std::this_thread::sleep_for(30ms);
    return at_frame.size() < 2;
  });
  ASSERT_EQ(at_frame.size(), 2u);
  EXPECT_EQ(at_frame[0].events.sequence.received, 1u);
  EXPECT_EQ(at_frame[1].events.sequence.received, static_cast<std::uint64_t>(kBatches));
  EXPECT_EQ(at_frame[1].segment_lists, 1u);
  EXPECT_EQ(at_frame[1].events.sequence.lost, 0u);
}

}  // namespace
}  // namespace evldt
