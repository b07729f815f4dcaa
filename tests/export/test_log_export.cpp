// evldt-export on a recording whose camera clock is Unix time (as DV and live cameras stamp their
// events): every message goes into the file, at its recording time.

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <lcm/lcm-cpp.hpp>

#include "evldt/export/log_export.hpp"
#include "evldt/segment_list_t.hpp"
#include "evldt/transport/messages.hpp"
#include "support/lcm_log_writing.hpp"

namespace evldt {
namespace {

constexpr Timestamp kEpochCameraUs = 1'700'000'000'000'000;  // November 2023, in microseconds

TEST(LogExport, ACameraClockInUnixTimeExportsEveryMessage) {
  const auto dir = std::filesystem::temp_directory_path() / ("evldt_epoch_export_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const auto log_path = dir / "epoch.lcmlog";
  {
    lcm::LogFile log(log_path.string(), "w");
    ASSERT_TRUE(log.good());
    event_batch_t header{};
    header.epoch = 1;
    header.source = "cam0";
    header.width = 240;
    header.height = 180;
    for (int batch = 0; batch < 30; ++batch) {  // 0.3 s of a vertical edge sweeping right
      EventBatch events;
      for (int k = 0; k < 100; ++k) {
        const Timestamp t = kEpochCameraUs + batch * 10'000 + k * 100;
        events.push_back(t, static_cast<std::uint16_t>(20 + batch * 5 + k % 3), static_cast<std::uint16_t>(30 + k), 1);
      }
      header.seq = batch;
      header.utime = 1'765'000'000'000'000 + batch * 10'000;
      std::vector<std::uint8_t> bytes;
      encode_event_batch(header, events, bytes);
      test_support::write_log_event(log, header.utime, "EVENTS_CAM0", bytes);
    }
    segment_list_t list{};
    list.utime = 1'765'000'000'300'000;
    list.epoch = 1;
    list.source = "cam0";
    list.width = 240;
    list.height = 180;
    list.t_us = kEpochCameraUs + 300'000;
    list.newest_batch_seq = 29;
    list.newest_batch_utime = 1'765'000'000'290'000;
    line_segment_t segment{};
    segment.id = 1;
    segment.x0 = segment.x1 = 170.5f;
    segment.y0 = 30;
    segment.y1 = 130;
    segment.score = 0.5f;
    segment.status = line_segment_t::STATUS_GOOD_TRACK;
    list.segments = {segment};
    list.num_segments = 1;
    std::vector<std::uint8_t> bytes(static_cast<std::size_t>(list.getEncodedSize()));
    list.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
    test_support::write_log_event(log, list.utime, "LINES_CAM0", bytes);
  }
  LogExportOptions options;
  options.image_hz = 20;
  const LogExportCounts counts = export_log_to_mcap(log_path, dir / "epoch.mcap", options);
  EXPECT_EQ(counts.camera, "cam0");
  EXPECT_EQ(counts.invalid, 0u);
  EXPECT_EQ(counts.segment_lists, 1u);
  EXPECT_GE(counts.images, 5u);  // 0.29 s of recording at 20 Hz
  EXPECT_GT(std::filesystem::file_size(dir / "epoch.mcap"), 1000u);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace evldt
