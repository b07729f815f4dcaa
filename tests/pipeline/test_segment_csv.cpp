#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "evldt/pipeline/segment_csv.hpp"

namespace evldt {
namespace {

TEST(SegmentCsv, RoundTripSortedByIdAndMalformedRowsNamed) {
  const auto dir = std::filesystem::temp_directory_path() / ("evldt_csv_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  std::vector<TrackedLine> lines(2);
  lines[0].id = 9;
  lines[0].segment = {Point2(1.25f, 2.5f), Point2(3.0f, 4.125f)};
  lines[0].score = 0.5f;
  lines[0].status = LineStatus::BadTrack;
  lines[0].normal_velocity = -12.25f;
  lines[0].normal_velocity_std = 3.5f;
  lines[1].id = 4;
  lines[1].segment = {Point2(10, 20), Point2(30, 40)};
  lines[1].status = LineStatus::GoodTrack;
  SegmentCsvWriter writer(dir / "s.csv");
  writer.write_step(1000, lines);
  writer.close();
  EXPECT_EQ(writer.rows(), 2u);
  EXPECT_THROW(writer.write_step(2000, lines), std::logic_error);
  const auto rows = read_segment_csv(dir / "s.csv");
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0].id, 4u);  // sorted by id within the step
  EXPECT_EQ(rows[0].status, LineStatus::GoodTrack);
  EXPECT_EQ(rows[1].id, 9u);
  EXPECT_EQ(rows[1].t_us, 1000);
  EXPECT_EQ(rows[1].segment.q1, Point2(3.0f, 4.125f));
  EXPECT_FLOAT_EQ(rows[1].score, 0.5f);
  EXPECT_EQ(rows[1].status, LineStatus::BadTrack);
  EXPECT_FLOAT_EQ(rows[1].normal_velocity, -12.2f);  // to 0.1 px/s, rounded to even
  EXPECT_FLOAT_EQ(rows[1].normal_velocity_std, 3.5f);

  // A file written before the velocity columns: read, its velocities unknown.
  std::ofstream(dir / "old.csv") << kSegmentCsvHeaderWithoutVelocity << "\n1,2,3,4,5,6,0.5,good\n";
  const auto old_rows = read_segment_csv(dir / "old.csv");
  ASSERT_EQ(old_rows.size(), 1u);
  EXPECT_EQ(old_rows[0].status, LineStatus::GoodTrack);
  EXPECT_TRUE(std::isnan(old_rows[0].normal_velocity));
  // ... but a row of the old form under the new header is malformed, as are trailing fields.
  std::ofstream(dir / "short.csv") << kSegmentCsvHeader << "\n1,2,3,4,5,6,0.5,good\n";
  EXPECT_THROW(read_segment_csv(dir / "short.csv"), std::runtime_error);
  std::ofstream(dir / "long.csv") << kSegmentCsvHeader << "\n1,2,3,4,5,6,0.5,good,1,2,3\n";
  EXPECT_THROW(read_segment_csv(dir / "long.csv"), std::runtime_error);

  std::ofstream(dir / "bad.csv") << kSegmentCsvHeader << "\n1,2,3,4,5,6,0.5,good,1.0,2.0\n7,8,9\n";
  try {
    read_segment_csv(dir / "bad.csv");
    FAIL() << "malformed row accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("bad.csv:3:"), std::string::npos) << e.what();
  }
  std::ofstream(dir / "status.csv") << kSegmentCsvHeader << "\n1,2,3,4,5,6,0.5,great,0,0\n";
  EXPECT_THROW(read_segment_csv(dir / "status.csv"), std::runtime_error);
  std::ofstream(dir / "header.csv") << "t,id\n";
  EXPECT_THROW(read_segment_csv(dir / "header.csv"), std::runtime_error);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace evldt
