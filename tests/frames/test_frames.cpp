// Intensity frames: the ECD layout written and read back, sensor_msgs/Image in ROS 1
// bags written with rosbag_storage and in ROS 2 bags (CDR in SQLite) written from the message's
// description, MVSEC's HDF5 frames written with the HDF5 library, AEDAT 3.1 frame packets, jAER's
// AEDAT 2.0 DAVIS APS samples and AEDAT 4.0 frame streams written from the format descriptions, their
// bad inputs, and LSD ground truth from the simulator's frames against
// the scene's exact lines.

#include <gtest/gtest.h>
#include <hdf5.h>
#include <unistd.h>

#include <array>
#include <filesystem>
#include <fstream>
#include <string>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include <flatbuffers/flatbuffers.h>

#include "aedat4_header_generated.h"
#include "evldt/eval/frame_ground_truth.hpp"
#include "evldt/frames/frame_reader.hpp"
#include "evldt/frames/frame_writer.hpp"
#include "evldt/sim/event_simulator.hpp"
#include "evldt/sim/scenes.hpp"
#include "support/raw_ros_message.hpp"
#include "support/ros2_bag_writer.hpp"

namespace evldt {
namespace {

constexpr SensorSize kSensor{64, 48};

class FramesTest : public ::testing::Test {
 protected:
  void SetUp() override {
    folder_ =
        std::filesystem::temp_directory_path() / ("evldt_frames_" + std::to_string(getpid()) + "_" +
                                                  ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::remove_all(folder_);
  }
  void TearDown() override { std::filesystem::remove_all(folder_); }

  // A dark frame with a bright square whose left side is at x = left.
  static cv::Mat square(int left) {
    cv::Mat image(kSensor.height, kSensor.width, CV_8UC1, cv::Scalar(30));
    cv::rectangle(image, cv::Rect(left, 12, 24, 24), cv::Scalar(220), cv::FILLED);
    return image;
  }
  void write_list(const std::string& text) { std::ofstream(folder_ / "images.txt") << text; }
  /// The FrameError of reading every frame of `path` (open_frames), or empty.
  static std::string read_error(const std::filesystem::path& path, const std::string& stream = {}) {
    try {
      const auto reader = open_frames(path, stream, kSensor);
      while (reader->next()) {
      }
    } catch (const FrameError& e) {
      return e.what();
    }
    return "";
  }
  std::string error_of(const std::filesystem::path& path) {
    try {
      const auto reader = open_ecd_frames(path, kSensor);
      while (reader->next()) {
      }
    } catch (const FrameError& e) {
      return e.what();
    }
    return "";
  }

  std::filesystem::path folder_;
};

TEST_F(FramesTest, WrittenFramesReadBackInOrder) {
  EcdFrameWriter writer(folder_);
  for (int k = 0; k < 3; ++k) writer.write(10'000 * k + 5, square(8 + 4 * k));
  writer.close();
  const auto reader = open_ecd_frames(folder_, kSensor);
  for (int k = 0; k < 3; ++k) {
    const auto frame = reader->next();
    ASSERT_TRUE(frame);
    EXPECT_EQ(frame->t_us, 10'000 * k + 5);
    EXPECT_EQ(frame->image.cols, kSensor.width);
    EXPECT_EQ(frame->image.rows, kSensor.height);
    EXPECT_EQ(cv::norm(frame->image, square(8 + 4 * k), cv::NORM_INF), 0.0) << frame->name;  // PNG: lossless
  }
  EXPECT_FALSE(reader->next());
}

// Where a recording says its size only by its frames (evldt-eval --frames-gt without --width/--height).
TEST_F(FramesTest, AnUnsetSensorTakesTheFirstFramesSizeAndRefusesAnotherLater) {
  EcdFrameWriter writer(folder_);
  writer.write(0, square(8));
  writer.write(10'000, square(12));
  writer.close();
  EXPECT_EQ(frames_sensor_size(folder_, ""), kSensor);
  cv::imwrite((folder_ / "images" / "small.png").string(), cv::Mat(10, 10, CV_8UC1, cv::Scalar(0)));
  write_list("0.0 images/frame_00000000.png\n0.01 images/small.png\n");
  const auto reader = open_frames(folder_, "", SensorSize{0, 0});
  ASSERT_TRUE(reader->next());
  try {
    reader->next();
    ADD_FAILURE() << "a second frame of another size must be refused";
  } catch (const FrameError& e) {
    EXPECT_NE(std::string(e.what()).find("small.png is 10x10, the sensor 64x48"), std::string::npos) << e.what();
  }
  write_list("");
  EXPECT_THROW(frames_sensor_size(folder_, ""), FrameError);
}

TEST_F(FramesTest, BadInputsNameTheFrame) {
  EcdFrameWriter writer(folder_);
  writer.write(0, square(8));
  writer.close();
  cv::Mat small(10, 10, CV_8UC1, cv::Scalar(0));
  cv::imwrite((folder_ / "images" / "small.png").string(), small);

  EXPECT_NE(error_of(folder_ / "none").find("no frame list"), std::string::npos);
  write_list("0.0 images/frame_00000000.png\n0.01 images/missing.png\n");
  EXPECT_NE(error_of(folder_).find("images/missing.png is missing"), std::string::npos) << error_of(folder_);
  std::ofstream(folder_ / "images" / "text.png") << "not a PNG";
  write_list("0.0 images/text.png\n");
  EXPECT_NE(error_of(folder_).find("images/text.png is not an image"), std::string::npos) << error_of(folder_);
  write_list("0.0 images/small.png\n");
  EXPECT_NE(error_of(folder_).find("small.png is 10x10, the sensor 64x48"), std::string::npos) << error_of(folder_);
  write_list("0.02 images/frame_00000000.png\n0.01 images/frame_00000000.png\n");
  EXPECT_NE(error_of(folder_).find("is earlier than the one before"), std::string::npos) << error_of(folder_);
  write_list("images/frame_00000000.png\n");
  EXPECT_NE(error_of(folder_).find("images.txt:1: expected"), std::string::npos) << error_of(folder_);
  // Nothing is scored from a folder that throws, and an empty one has no ground truth.
  write_list("");
  const auto empty = open_ecd_frames(folder_, kSensor);
  EXPECT_THROW(frame_ground_truth_steps(*empty, LsdParams{}), FrameError);
}

void put32(std::vector<std::uint8_t>& out, std::uint32_t value) {
  for (int k = 0; k < 4; ++k) out.push_back(static_cast<std::uint8_t>(value >> (8 * k)));
}
void put_string(std::vector<std::uint8_t>& out, const std::string& text) {
  put32(out, static_cast<std::uint32_t>(text.size()));
  out.insert(out.end(), text.begin(), text.end());
}

/// A sensor_msgs/Image as ROS 1 serializes it: header (seq, stamp, frame_id), height, width,
/// encoding, is_bigendian, step, data; `image` (grey, or BGR for bgr8 and rgb8) in the given pixel
/// encoding, rows padded by `row_padding` bytes, the data `cut` bytes short.
RawRosMessage ros_image(Timestamp t_us, const cv::Mat& image, const std::string& encoding, bool big_endian = false,
                        int row_padding = 0, std::size_t cut = 0) {
  RawRosMessage message{"sensor_msgs/Image", {}, {}};
  std::vector<std::uint8_t>& out = message.bytes;
  put32(out, 1);  // seq
  put32(out, static_cast<std::uint32_t>(t_us / 1'000'000));
  put32(out, static_cast<std::uint32_t>(t_us % 1'000'000 * 1000));
  put_string(out, "davis");
  put32(out, static_cast<std::uint32_t>(image.rows));
  put32(out, static_cast<std::uint32_t>(image.cols));
  put_string(out, encoding);
  out.push_back(big_endian ? 1 : 0);
  const int pixel_bytes = encoding == "mono16" ? 2 : encoding == "bgr8" || encoding == "rgb8" ? 3 : 1;
  const int step = image.cols * pixel_bytes + row_padding;
  put32(out, static_cast<std::uint32_t>(step));
  std::vector<std::uint8_t> data;
  for (int y = 0; y < image.rows; ++y) {
    for (int x = 0; x < image.cols; ++x) {
      if (pixel_bytes == 3) {
        const cv::Vec3b bgr = image.at<cv::Vec3b>(y, x);
        for (const int c : encoding == "bgr8" ? std::array{0, 1, 2} : std::array{2, 1, 0}) data.push_back(bgr[c]);
        continue;
      }
      const std::uint8_t grey = image.at<std::uint8_t>(y, x);
      if (pixel_bytes == 2) {
        const auto wide =
            static_cast<std::uint16_t>(grey << 8 | 0xff);  // the low byte is dropped, not rounded into the high one
        data.push_back(static_cast<std::uint8_t>(big_endian ? wide >> 8 : wide & 0xff));
        data.push_back(static_cast<std::uint8_t>(big_endian ? wide & 0xff : wide >> 8));
      } else {
        data.push_back(grey);
      }
    }
    data.insert(data.end(), static_cast<std::size_t>(row_padding), 0xee);
  }
  data.resize(data.size() - cut);
  put32(out, static_cast<std::uint32_t>(data.size()));
  out.insert(out.end(), data.begin(), data.end());
  return message;
}

class BagFramesTest : public FramesTest {
 protected:
  /// A bag of frames on /dvs/image_raw beside a topic of another type.
  std::filesystem::path write_bag(const std::vector<RawRosMessage>& images) {
    std::filesystem::create_directories(folder_);
    const std::filesystem::path path = folder_ / "frames.bag";
    rosbag::Bag bag(path.string(), rosbag::bagmode::Write);
    for (std::size_t k = 0; k < images.size(); ++k) {
      const ros::Time stamp(1.0 + 0.01 * static_cast<double>(k));
      bag.write("/imu", stamp, RawRosMessage{"sensor_msgs/Imu", std::vector<std::uint8_t>(20, 1), {}});
      bag.write("/dvs/image_raw", stamp, images[k]);
    }
    bag.close();
    return path;
  }
};

// A red square on blue: bgr8 and rgb8 read in the wrong channel order would weigh them otherwise.
cv::Mat coloured_square(int left) {
  cv::Mat image(kSensor.height, kSensor.width, CV_8UC3, cv::Scalar(200, 40, 10));
  cv::rectangle(image, cv::Rect(left, 12, 24, 24), cv::Scalar(20, 30, 230), cv::FILLED);
  return image;
}

TEST_F(BagFramesTest, EveryPixelEncodingReadsAsTheGreyItHolds) {
  const std::vector<std::string> encodings = {"mono8", "mono16", "mono16", "bgr8", "rgb8"};
  std::vector<RawRosMessage> images;
  std::vector<cv::Mat> expected;
  for (std::size_t k = 0; k < encodings.size(); ++k) {
    const int left = 4 + 6 * static_cast<int>(k);
    const bool colour = encodings[k] != "mono8" && encodings[k] != "mono16";
    images.push_back(ros_image(1'700'000'000'000'000 + 10'000 * static_cast<Timestamp>(k),
                               colour ? coloured_square(left) : square(left), encodings[k], k == 2, k == 3 ? 5 : 0));
    expected.push_back(square(left));
    if (colour) cv::cvtColor(coloured_square(left), expected.back(), cv::COLOR_BGR2GRAY);
  }
  const std::filesystem::path bag = write_bag(images);
  for (const std::string topic : {"", "/dvs/image_raw"}) {
    const auto reader = open_frames(bag, topic, kSensor);
    for (std::size_t k = 0; k < encodings.size(); ++k) {
      const auto frame = reader->next();
      ASSERT_TRUE(frame) << encodings[k];
      EXPECT_EQ(frame->t_us, 1'700'000'000'000'000 + 10'000 * static_cast<Timestamp>(k));
      ASSERT_EQ(frame->image.type(), CV_8UC1);
      EXPECT_EQ(cv::norm(frame->image, expected[k], cv::NORM_INF), 0.0) << encodings[k] << ", " << frame->name;
    }
    EXPECT_FALSE(reader->next());
  }
}

TEST_F(BagFramesTest, BadInputsNameTheFrame) {
  const Timestamp t0 = 1'700'000'000'000'000;
  const auto nth = [](const std::string& error) {
    return error.find("message 1 of /dvs/image_raw") != std::string::npos;
  };
  std::string error =
      read_error(write_bag({ros_image(t0, square(8), "mono8"), ros_image(t0 + 1, square(8), "bayer_rggb8")}));
  EXPECT_TRUE(nth(error) && error.find("pixel encoding 'bayer_rggb8'") != std::string::npos) << error;
  error = read_error(write_bag(
      {ros_image(t0, square(8), "mono8"), ros_image(t0 + 1, cv::Mat(10, 10, CV_8UC1, cv::Scalar(0)), "mono8")}));
  EXPECT_TRUE(nth(error) && error.find("frame is 10x10, the sensor 64x48") != std::string::npos) << error;
  error = read_error(write_bag({ros_image(t0 + 10, square(8), "mono8"), ros_image(t0, square(8), "mono8")}));
  EXPECT_TRUE(nth(error) && error.find("earlier than the one before") != std::string::npos) << error;
  error =
      read_error(write_bag({ros_image(t0, square(8), "mono8"), ros_image(t0 + 1, square(8), "mono16", false, 0, 7)}));
  EXPECT_TRUE(nth(error) && error.find("holds only") != std::string::npos) << error;
  const std::filesystem::path good = write_bag({ros_image(t0, square(8), "mono8")});
  error = read_error(good, "/imu");
  EXPECT_NE(error.find("topic /imu is of type sensor_msgs/Imu, not sensor_msgs/Image"), std::string::npos) << error;
  error = read_error(good, "/none");
  EXPECT_NE(error.find("no topic /none (topics: "), std::string::npos) << error;
  std::ofstream(folder_ / "junk.bin") << "not frames";
  error = read_error(folder_ / "junk.bin");
  EXPECT_NE(error.find("not a source of frames"), std::string::npos) << error;
  // Nothing is scored from a bag whose frames throw.
  const auto reader =
      open_frames(write_bag({ros_image(t0, square(8), "mono8"), ros_image(t0 + 1, square(8), "yuv422")}), "", kSensor);
  EXPECT_THROW(frame_ground_truth_steps(*reader, LsdParams{}), FrameError);
}

/// A sensor_msgs/msg/Image in CDR of either byte order (a mono8 frame).
std::vector<std::uint8_t> ros2_image(Timestamp t_us, const cv::Mat& image, bool little_endian) {
  test_support::CdrWriter cdr(little_endian);
  cdr.put<std::int32_t>(static_cast<std::int32_t>(t_us / 1'000'000));
  cdr.put<std::uint32_t>(static_cast<std::uint32_t>(t_us % 1'000'000 * 1000));
  cdr.put_string("davis");
  cdr.put<std::uint32_t>(static_cast<std::uint32_t>(image.rows));
  cdr.put<std::uint32_t>(static_cast<std::uint32_t>(image.cols));
  cdr.put_string("mono8");
  cdr.put<std::uint8_t>(0);
  cdr.put<std::uint32_t>(static_cast<std::uint32_t>(image.cols));
  cdr.put_bytes(std::vector<std::uint8_t>(image.datastart, image.dataend));
  return cdr.bytes();
}

TEST_F(FramesTest, Ros2BagFramesInCdrOfEitherByteOrder) {
  std::filesystem::create_directories(folder_);
  const std::filesystem::path path = folder_ / "frames.db3";
  {
    test_support::BagWriter bag(path);
    bag.topic(1, "/events", "event_camera_msgs/msg/EventPacket");
    bag.topic(2, "/dvs/image_raw", "sensor_msgs/msg/Image");
    for (int k = 0; k < 4; ++k)
      bag.message(2, 1'000'000'000 + k, ros2_image(1'700'000'000'000'000 + 10'000 * k, square(4 + 6 * k), k % 2 == 0));
    bag.message(2, 1'000'000'100, {0, 1, 0, 0, 1});  // a message cut short
  }
  const auto reader = open_frames(path, "", kSensor);
  for (int k = 0; k < 4; ++k) {
    const auto frame = reader->next();
    ASSERT_TRUE(frame);
    EXPECT_EQ(frame->t_us, 1'700'000'000'000'000 + 10'000 * k);
    EXPECT_EQ(cv::norm(frame->image, square(4 + 6 * k), cv::NORM_INF), 0.0) << frame->name;
  }
  try {
    reader->next();
    ADD_FAILURE() << "a cut message must be an error";
  } catch (const FrameError& e) {
    EXPECT_NE(std::string(e.what()).find("message id 5 of /dvs/image_raw: CDR byte 4: message ends early"),
              std::string::npos)
        << e.what();
  }
  try {
    open_frames(path, "/events", kSensor);
    ADD_FAILURE() << "an event topic holds no frames";
  } catch (const FrameError& e) {
    EXPECT_NE(std::string(e.what()).find(
                  "topic /events is of type event_camera_msgs/msg/EventPacket, not sensor_msgs/msg/Image"),
              std::string::npos)
        << e.what();
  }
}

/// An HDF5 file in MVSEC's layout: `frames` (8-bit grey, all one size) as N x H x W at `dataset`,
/// their times in seconds at dataset + "_ts" (`times` may differ in count, to make a bad file).
void write_mvsec_frames(const std::filesystem::path& path, const std::vector<cv::Mat>& frames,
                        const std::vector<double>& times, const std::string& dataset = "/davis/left/image_raw",
                        hid_t pixel_type = H5T_NATIVE_UINT8) {
  const hid_t file = H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
  const hid_t links = H5Pcreate(H5P_LINK_CREATE);
  H5Pset_create_intermediate_group(links, 1);
  const hsize_t dims[3] = {frames.size(), static_cast<hsize_t>(frames.front().rows),
                           static_cast<hsize_t>(frames.front().cols)};
  const hid_t space = H5Screate_simple(3, dims, nullptr);
  const hid_t images = H5Dcreate2(file, dataset.c_str(), pixel_type, space, links, H5P_DEFAULT, H5P_DEFAULT);
  std::vector<std::uint8_t> pixels;
  for (const cv::Mat& frame : frames) pixels.insert(pixels.end(), frame.datastart, frame.dataend);
  if (pixel_type == H5T_NATIVE_UINT8) H5Dwrite(images, H5T_NATIVE_UINT8, H5S_ALL, H5S_ALL, H5P_DEFAULT, pixels.data());
  const hsize_t count = times.size();
  const hid_t time_space = H5Screate_simple(1, &count, nullptr);
  const hid_t stamps =
      H5Dcreate2(file, (dataset + "_ts").c_str(), H5T_NATIVE_DOUBLE, time_space, links, H5P_DEFAULT, H5P_DEFAULT);
  H5Dwrite(stamps, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, times.data());
  for (const hid_t id : {stamps, time_space, images, space, links}) H5Idec_ref(id);
  H5Fclose(file);
}

TEST_F(FramesTest, MvsecHdf5FramesOfEitherCameraReadWithTheirTimes) {
  std::filesystem::create_directories(folder_);
  const std::filesystem::path path = folder_ / "indoor_flying1_data.hdf5";
  write_mvsec_frames(path, {square(4), square(10), square(16)}, {1504645177.42, 1504645177.45, 1504645177.48});
  const auto reader = open_frames(path, "", kSensor);
  for (int k = 0; k < 3; ++k) {
    const auto frame = reader->next();
    ASSERT_TRUE(frame);
    EXPECT_EQ(frame->t_us, 1'504'645'177'420'000 + 30'000 * k);
    EXPECT_EQ(cv::norm(frame->image, square(4 + 6 * k), cv::NORM_INF), 0.0) << frame->name;
    EXPECT_NE(frame->name.find("/davis/left/image_raw[" + std::to_string(k) + "]"), std::string::npos) << frame->name;
  }
  EXPECT_FALSE(reader->next());
  const std::filesystem::path right_camera = folder_ / "right.hdf5";
  write_mvsec_frames(right_camera, {square(20)}, {2.5}, "/davis/right/image_raw");
  const auto right = open_frames(right_camera, "/davis/right/image_raw", kSensor)->next();
  ASSERT_TRUE(right);
  EXPECT_EQ(right->t_us, 2'500'000);
  EXPECT_EQ(cv::norm(right->image, square(20), cv::NORM_INF), 0.0);
}

TEST_F(FramesTest, MvsecHdf5BadInputsAreClearErrors) {
  std::filesystem::create_directories(folder_);
  const std::filesystem::path path = folder_ / "bad.hdf5";
  const auto error = [&](const std::string& stream = {}) { return read_error(path, stream); };
  write_mvsec_frames(path, {square(4), square(8)}, {1.0});
  EXPECT_NE(error().find("/davis/left/image_raw_ts holds 1 times for 2 frames"), std::string::npos) << error();
  write_mvsec_frames(path, {square(4)}, {1.0});
  EXPECT_NE(error("/davis/right/image_raw").find("no frames /davis/right/image_raw"), std::string::npos)
      << error("/davis/right/image_raw");
  write_mvsec_frames(path, {square(4), square(8)}, {1.0, 0.5});
  EXPECT_NE(error().find("image_raw[1]: frame at 500000 us is earlier than the one before"), std::string::npos)
      << error();
  write_mvsec_frames(path, {cv::Mat(10, 10, CV_8UC1, cv::Scalar(0))}, {1.0});
  EXPECT_NE(error().find("frame is 10x10, the sensor 64x48"), std::string::npos) << error();
  write_mvsec_frames(path, {square(4)}, {1.0}, "/davis/left/image_raw", H5T_NATIVE_UINT16);
  EXPECT_NE(error().find("is not N x H x W frames of 8-bit pixels"), std::string::npos) << error();
  write_mvsec_frames(path, {square(4)}, {std::nan("")});
  EXPECT_NE(error().find("image_raw[0]: its time"), std::string::npos) << error();
  write_mvsec_frames(path, {cv::Mat(1, 5000, CV_8UC1, cv::Scalar(0))}, {1.0});
  EXPECT_NE(error().find("holds frames of 5000x1, not a sensor's size"), std::string::npos) << error();
}

// ---- AEDAT 3.1 and 2.0, written from the format descriptions (aedat_images.hpp) ----------------

void put16(std::vector<std::uint8_t>& out, std::uint16_t value) {
  out.push_back(static_cast<std::uint8_t>(value & 0xFF));
  out.push_back(static_cast<std::uint8_t>(value >> 8));
}
void put_be32(std::vector<std::uint8_t>& out, std::uint32_t value) {
  for (int k = 3; k >= 0; --k) out.push_back(static_cast<std::uint8_t>(value >> (8 * k)));
}
void write_bytes(const std::filesystem::path& path, const std::string& header, const std::vector<std::uint8_t>& data) {
  std::ofstream file(path, std::ios::binary);
  file << header;
  file.write(reinterpret_cast<const char*>(data.data()), static_cast<std::streamsize>(data.size()));
}

/// An AEDAT 3.1 packet: the 28-byte header, then `capacity` events of `event_size` bytes.
void put_aedat31_packet(std::vector<std::uint8_t>& out, std::int16_t type, std::int32_t event_size,
                        std::int32_t overflow, std::int32_t capacity, const std::vector<std::uint8_t>& events) {
  put16(out, static_cast<std::uint16_t>(type));
  put16(out, 1);  // source
  for (const std::int32_t field : {event_size, 4, overflow, capacity, capacity, capacity})
    put32(out, static_cast<std::uint32_t>(field));
  out.insert(out.end(), events.begin(), events.end());
  out.resize(out.size() + static_cast<std::size_t>(event_size) * static_cast<std::size_t>(capacity) - events.size(), 0);
}

/// A frame event: info (valid, channels), times, size, position, then the grey image's pixels as
/// 16-bit values (the grey in the high byte, noise in the low one), padded to `event_size`.
void put_aedat31_frame(std::vector<std::uint8_t>& out, std::size_t event_size, const cv::Mat& grey, bool valid,
                       std::uint32_t channels, std::int32_t start_exposure, std::int32_t end_exposure,
                       std::int32_t claimed_width = 0) {
  const std::size_t start = out.size();
  put32(out, (valid ? 1u : 0u) | channels << 1);
  for (const std::int32_t t : {start_exposure - 100, end_exposure + 100, start_exposure, end_exposure})
    put32(out, static_cast<std::uint32_t>(t));
  for (const int field : {claimed_width > 0 ? claimed_width : grey.cols, grey.rows, 0, 0})
    put32(out, static_cast<std::uint32_t>(field));
  for (int y = 0; y < grey.rows; ++y) {
    for (int x = 0; x < grey.cols; ++x)
      put16(out, static_cast<std::uint16_t>(grey.at<std::uint8_t>(y, x) << 8 | ((x * 7 + y) & 0xFF)));
  }
  out.resize(start + event_size, 0);
}

const std::string kAedat31Header = "#!AER-DAT3.1\r\n#Format: RAW\r\n#Source 1: DAVIS346B\r\n#!END-HEADER\r\n";
constexpr std::size_t kFrameEventSize = 36 + 64 * 48 * 2 + 8;  // a frame's header, its pixels and slack

TEST_F(FramesTest, Aedat31FramePacketsReadAtTheMiddleOfTheirExposure) {
  std::filesystem::create_directories(folder_);
  std::vector<std::uint8_t> data, polarity, frames;
  for (std::uint32_t k = 0; k < 2; ++k) {
    put32(polarity, 1u | 1u << 17 | 2u << 2);
    put32(polarity, 500 + k);
  }
  put_aedat31_packet(data, 1, 8, 1, 2, polarity);  // events: passed over
  put_aedat31_frame(frames, kFrameEventSize, square(4), true, 1, 1000, 3000);
  put_aedat31_frame(frames, kFrameEventSize, square(30), false, 1, 4000, 5000);  // invalid: no frame
  put_aedat31_frame(frames, kFrameEventSize, square(10), true, 1, 40000, 40001);
  put_aedat31_packet(data, 2, static_cast<std::int32_t>(kFrameEventSize), 1, 3, frames);
  const auto path = folder_ / "davis.aedat";
  write_bytes(path, kAedat31Header, data);
  const auto reader = open_frames(path, "", kSensor);
  const Timestamp overflow = Timestamp{1} << 31;
  for (const auto& [t, left] : {std::pair{overflow + 2000, 4}, std::pair{overflow + 40000, 10}}) {
    const auto frame = reader->next();
    ASSERT_TRUE(frame);
    EXPECT_EQ(frame->t_us, t);
    EXPECT_EQ(cv::norm(frame->image, square(left), cv::NORM_INF), 0.0) << frame->name;
    EXPECT_NE(frame->name.find("davis.aedat: frame "), std::string::npos) << frame->name;
  }
  EXPECT_FALSE(reader->next());
}

TEST_F(FramesTest, Aedat31BadFramesNameTheFrame) {
  std::filesystem::create_directories(folder_);
  const auto path = folder_ / "bad.aedat";
  const auto error = [&](const std::vector<std::uint8_t>& data) {
    write_bytes(path, kAedat31Header, data);
    return read_error(path);
  };
  std::vector<std::uint8_t> data, frame;
  put_aedat31_frame(frame, kFrameEventSize, square(4), true, 3, 1000, 2000);
  put_aedat31_packet(data, 2, static_cast<std::int32_t>(kFrameEventSize), 0, 1, frame);
  EXPECT_NE(error(data).find("bad.aedat: frame 0 of the frame packet at byte 64: 3 colour channels"), std::string::npos)
      << error(data);
  data.clear();
  frame.clear();
  put_aedat31_frame(frame, kFrameEventSize, square(4), true, 1, 1000, 2000, 200);
  put_aedat31_packet(data, 2, static_cast<std::int32_t>(kFrameEventSize), 0, 1, frame);
  EXPECT_NE(error(data).find("a 200x48 frame does not fit its"), std::string::npos) << error(data);
  data.clear();
  frame.clear();
  put_aedat31_frame(frame, kFrameEventSize, square(4), true, 1, 1000, 2000);
  put_aedat31_packet(data, 2, static_cast<std::int32_t>(kFrameEventSize), 0, 1, frame);
  data.resize(data.size() - 100);
  EXPECT_NE(error(data).find("does not fit in the file (a recording cut short)"), std::string::npos) << error(data);
  data.clear();
  frame.clear();
  put_aedat31_frame(frame, kFrameEventSize, cv::Mat(24, 32, CV_8UC1, cv::Scalar(9)), true, 1, 1000, 2000);
  put_aedat31_packet(data, 2, static_cast<std::int32_t>(kFrameEventSize), 0, 1, frame);
  EXPECT_NE(error(data).find("frame is 32x24, the sensor 64x48"), std::string::npos) << error(data);
  write_bytes(path, "#!AER-DAT9.9\r\n", {});
  EXPECT_THROW(open_frames(path, "", kSensor), FrameError);
}

/// jAER's DAVIS APS samples of one pixel (image coordinates: jAER mirrors both axes).
void put_aps_sample(std::vector<std::uint8_t>& out, int x, int y, std::uint32_t read, std::uint32_t value,
                    std::uint32_t t, int side) {
  put_be32(out, 0x80000000u | static_cast<std::uint32_t>(side - 1 - y) << 22 |
                    static_cast<std::uint32_t>(side - 1 - x) << 12 | read << 10 | value);
  put_be32(out, t);
}

TEST_F(FramesTest, Aedat2DavisApsFramesAreResetMinusSignal) {
  std::filesystem::create_directories(folder_);
  constexpr int kSide = 128;  // a DAVIS128
  const SensorSize sensor{kSide, kSide};
  cv::Mat scene(kSide, kSide, CV_8UC1, cv::Scalar(40));
  cv::rectangle(scene, cv::Rect(30, 50, 40, 20), cv::Scalar(200), cv::FILLED);
  std::vector<std::uint8_t> data;
  put_be32(data, 5u << 12 | 7u << 22 | 0x800u);  // a polarity event
  put_be32(data, 10);
  // A frame the recording starts inside: signal reads only, then resets of a tenth of the pixels.
  for (int x = 0; x < 10; ++x) put_aps_sample(data, x, 0, 1, 100, 20, kSide);
  for (int p = 0; p < kSide * kSide / 10; ++p) put_aps_sample(data, p % kSide, p / kSide, 0, 1023, 30, kSide);
  std::uint32_t t = 1000;
  std::vector<Timestamp> expected_times;
  for (int frame = 0; frame < 2; ++frame) {
    const std::uint32_t last_reset = t + kSide * kSide / 1000, first_signal = t + 5000;
    for (int p = 0; p < kSide * kSide; ++p)
      put_aps_sample(data, p % kSide, p / kSide, 0, 1023, t + static_cast<std::uint32_t>(p / 1000), kSide);
    put_be32(data, 0x80000C00u);  // an IMU sample
    put_be32(data, t + 20);
    for (int p = 0; p < kSide * kSide; ++p) {
      const std::uint32_t light = 4u * scene.at<std::uint8_t>(p / kSide, (p % kSide + 3 * frame) % kSide);
      put_aps_sample(data, p % kSide, p / kSide, 1, 1023 - light, first_signal + static_cast<std::uint32_t>(p / 1000),
                     kSide);
    }
    expected_times.push_back(last_reset + (first_signal - last_reset) / 2);
    t += 40000;
  }
  const auto path = folder_ / "davis128.aedat";
  // No "#End Of ASCII Header" line (older jAER files): the header ends where the data begins.
  write_bytes(path, "#!AER-DAT2.0\r\n# AEChip: eu.seebetter.ini.chips.davis.DAVIS128\r\n", data);
  const auto reader = open_frames(path, "", sensor);
  for (int frame = 0; frame < 2; ++frame) {
    const auto read = reader->next();
    ASSERT_TRUE(read);
    EXPECT_EQ(read->t_us, expected_times[static_cast<std::size_t>(frame)]);
    cv::Mat shifted(kSide, kSide, CV_8UC1);
    for (int y = 0; y < kSide; ++y) {
      for (int x = 0; x < kSide; ++x)
        shifted.at<std::uint8_t>(y, x) = scene.at<std::uint8_t>(y, (x + 3 * frame) % kSide);
    }
    EXPECT_EQ(cv::norm(read->image, shifted, cv::NORM_INF), 0.0) << read->name;
    EXPECT_NE(read->name.find("davis128.aedat: APS frame " + std::to_string(frame)), std::string::npos) << read->name;
  }
  EXPECT_FALSE(reader->next());

  write_bytes(path, "#!AER-DAT2.0\r\n# AEChip: ch.unizh.ini.jaer.chip.retina.DVS128\r\n", {});
  try {
    open_frames(path, "", sensor);
    ADD_FAILURE() << "a DVS128 recording gave frames";
  } catch (const FrameError& e) {
    EXPECT_NE(std::string(e.what()).find("DVS128 recording (its chip has no APS frames)"), std::string::npos)
        << e.what();
  }
}

// ---- AEDAT 4.0 frame streams ----------------------------------------------------------------------

/// How the writer stores each FlatBuffer: size-prefixed as DV does, or finished plain with its size
/// then put in front, as the aedat library does (8-byte fields aligned from the buffer, not the prefix).
enum class Writer { Dv, AedatLibrary };

/// The finished builder's bytes as `writer` stores them.
std::vector<std::uint8_t> stored(const flatbuffers::FlatBufferBuilder& builder, Writer writer) {
  std::vector<std::uint8_t> bytes;
  if (writer == Writer::AedatLibrary) put32(bytes, static_cast<std::uint32_t>(builder.GetSize()));
  bytes.insert(bytes.end(), builder.GetBufferPointer(), builder.GetBufferPointer() + builder.GetSize());
  return bytes;
}

/// A frame as DV writes one per FRME packet: built by slot number (as DV's own accessors read them:
/// timestamp 4, start / end of exposure 10 / 12, format 14, sizeX 16, sizeY 18, pixels 24), not
/// through evldt's schema, so a slot evldt's schema put elsewhere would fail here.
std::vector<std::uint8_t> dv_frame(Timestamp t, Timestamp start_exposure, Timestamp end_exposure, std::int8_t format,
                                   const cv::Mat& image, std::size_t pixels_cut = 0, Writer writer = Writer::Dv) {
  flatbuffers::FlatBufferBuilder builder;
  const cv::Mat continuous = image.clone();
  const auto pixels = builder.CreateVector(continuous.data, continuous.total() * continuous.elemSize() - pixels_cut);
  const auto start = builder.StartTable();
  builder.AddElement<std::int64_t>(4, t, 0);
  builder.AddElement<std::int64_t>(10, start_exposure, 0);
  builder.AddElement<std::int64_t>(12, end_exposure, 0);
  builder.AddElement<std::int8_t>(14, format, 0);
  builder.AddElement<std::int16_t>(16, static_cast<std::int16_t>(image.cols), 0);
  builder.AddElement<std::int16_t>(18, static_cast<std::int16_t>(image.rows), 0);
  builder.AddOffset(24, pixels);
  const flatbuffers::Offset<void> frame(builder.EndTable(start));
  if (writer == Writer::Dv) {
    builder.FinishSizePrefixed(frame, "FRME");
  } else {
    builder.Finish(frame);
  }
  return stored(builder, writer);
}

/// An AEDAT 4.0 file (uncompressed) of an event stream (0) and, unless `frames_stream` is false, a
/// frame stream (2), each payload a packet of the stream given.
void write_aedat4(const std::filesystem::path& path,
                  const std::vector<std::pair<int, std::vector<std::uint8_t>>>& packets, bool frames_stream = true,
                  Writer writer = Writer::Dv) {
  const std::string info =
      std::string(R"(<dv version="2.0"><node name="outInfo" path="/mainloop/Recorder/outInfo/">)") +
      R"(<node name="0" path="/mainloop/Recorder/outInfo/0/"><attr key="typeIdentifier" type="string">EVTS</attr></node>)" +
      (frames_stream
           ? R"(<node name="2" path="/mainloop/Recorder/outInfo/2/"><attr key="typeIdentifier" type="string">FRME</attr></node>)"
           : "") +
      "</node></dv>";
  flatbuffers::FlatBufferBuilder header;
  const auto table = aedat4::CreateIOHeaderDirect(header, aedat4::CompressionType::NONE, -1, info.c_str());
  if (writer == Writer::Dv) {
    aedat4::FinishSizePrefixedIOHeaderBuffer(header, table);
  } else {
    header.Finish(table);
  }
  std::vector<std::uint8_t> data = stored(header, writer);
  for (const auto& [stream, payload] : packets) {
    put32(data, static_cast<std::uint32_t>(stream));
    put32(data, static_cast<std::uint32_t>(payload.size()));
    data.insert(data.end(), payload.begin(), payload.end());
  }
  write_bytes(path, "#!AER-DAT4.0\r\n", data);
}

TEST_F(FramesTest, Aedat4FrameStreamsReadGreyAndColourAtTheMiddleOfTheirExposure) {
  std::filesystem::create_directories(folder_);
  const auto path = folder_ / "dv.aedat4";
  cv::Mat colour_grey;
  cv::cvtColor(coloured_square(16), colour_grey, cv::COLOR_BGR2GRAY);
  write_aedat4(path, {{0, std::vector<std::uint8_t>(40, 3)},  // events: passed over
                      {2, dv_frame(1'000'000, 1'000'000, 1'004'000, 0, square(4))},
                      {0, std::vector<std::uint8_t>(40, 3)},
                      {2, dv_frame(1'040'000, 1'040'000, 1'041'000, 16, coloured_square(16))},
                      {2, dv_frame(1'080'000, 0, 0, 0, square(28))}});  // no exposure given: its time stamp
  const auto reader = open_frames(path, "", kSensor);
  for (const auto& [t, expected] :
       {std::pair{Timestamp{1'002'000}, square(4)}, std::pair{Timestamp{1'040'500}, colour_grey},
        std::pair{Timestamp{1'080'000}, square(28)}}) {
    const auto frame = reader->next();
    ASSERT_TRUE(frame);
    EXPECT_EQ(frame->t_us, t);
    EXPECT_EQ(cv::norm(frame->image, expected, cv::NORM_INF), 0.0) << frame->name;
    EXPECT_NE(frame->name.find("dv.aedat4: frame packet at byte "), std::string::npos) << frame->name;
  }
  EXPECT_FALSE(reader->next());
}

// The aedat library's frames (each FlatBuffer finished plain, its size put in front) read as DV's.
TEST_F(FramesTest, Aedat4FramesWithTheirSizePutInFrontReadAsDvs) {
  std::filesystem::create_directories(folder_);
  const auto frames = [](Writer writer) {
    return std::vector<std::pair<int, std::vector<std::uint8_t>>>{
        {2, dv_frame(1'000'000, 1'000'000, 1'004'000, 0, square(4), 0, writer)},
        {2, dv_frame(1'040'000, 1'040'000, 1'041'000, 16, coloured_square(16), 0, writer)}};
  };
  write_aedat4(folder_ / "dv.aedat4", frames(Writer::Dv));
  write_aedat4(folder_ / "aedat-library.aedat4", frames(Writer::AedatLibrary), true, Writer::AedatLibrary);
  const auto from_dv = open_frames(folder_ / "dv.aedat4", "", kSensor);
  const auto from_library = open_frames(folder_ / "aedat-library.aedat4", "", kSensor);
  for (int k = 0; k < 2; ++k) {
    const auto expected = from_dv->next();
    const auto frame = from_library->next();
    ASSERT_TRUE(expected);
    ASSERT_TRUE(frame) << k;
    EXPECT_EQ(frame->t_us, expected->t_us);
    EXPECT_EQ(cv::norm(frame->image, expected->image, cv::NORM_INF), 0.0) << k;
  }
  EXPECT_FALSE(from_library->next());
}

TEST_F(FramesTest, Aedat4BadFramesNameTheFrame) {
  std::filesystem::create_directories(folder_);
  const auto path = folder_ / "bad.aedat4";
  const auto error = [&] { return read_error(path); };
  cv::Mat bgra;
  cv::cvtColor(coloured_square(4), bgra, cv::COLOR_BGR2BGRA);
  write_aedat4(path, {{2, dv_frame(1000, 0, 0, 24, bgra)}});
  EXPECT_NE(error().find("pixel format 24 is not one evldt reads"), std::string::npos) << error();
  write_aedat4(path, {{2, dv_frame(1000, 0, 0, 0, square(4), 10)}});
  EXPECT_NE(error().find("3062 bytes of pixels for a 64x48 frame"), std::string::npos) << error();
  write_aedat4(path, {{2, std::vector<std::uint8_t>(64, 0xAB)}});
  EXPECT_NE(error().find("not a valid Frame FlatBuffer"), std::string::npos) << error();
  write_aedat4(path, {}, false);
  EXPECT_NE(error().find("bad.aedat4: no frame stream (FRME) in the header"), std::string::npos) << error();
}

// A real DVXplorer recording has events only: asked for frames, it is refused by name.
TEST_F(FramesTest, Aedat4RecordingWithoutFramesIsRefusedByName) {
  const std::filesystem::path recording = std::filesystem::path(EVLDT_SHARED_DIR) / "real" / "dvxplorer_person.aedat4";
  if (!std::filesystem::exists(recording))
    GTEST_SKIP() << "no real recordings at " << recording.parent_path() << " (../shared is absent)";
  try {
    open_frames(recording, "", {320, 240});
    ADD_FAILURE() << "a recording without frames gave a frame reader";
  } catch (const FrameError& e) {
    EXPECT_NE(std::string(e.what()).find("dvxplorer_person.aedat4: no frame stream (FRME) in the header"),
              std::string::npos)
        << e.what();
  }
}

// A video's frames on the clock --from-video emulates its events on (frame k at k / fps s).
TEST_F(FramesTest, VideoFramesOnTheClockOfTheEventsEmulatedFromThem) {
  std::filesystem::create_directories(folder_);
  const std::filesystem::path path = folder_ / "clip.avi";
  {
    cv::VideoWriter writer(path.string(), cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 25,
                           cv::Size(kSensor.width, kSensor.height), false);
    ASSERT_TRUE(writer.isOpened());
    for (int k = 0; k < 4; ++k) writer.write(square(4 + 6 * k));
  }
  const auto reader = open_frames(path, "", kSensor);
  for (int k = 0; k < 4; ++k) {
    const auto frame = reader->next();
    ASSERT_TRUE(frame);
    EXPECT_EQ(frame->t_us, 40'000 * k);
    EXPECT_EQ(frame->t_us, video_frame_time_us(static_cast<std::uint64_t>(k), 25));
    ASSERT_EQ(frame->image.type(), CV_8UC1);
    EXPECT_LT(cv::norm(frame->image, square(4 + 6 * k), cv::NORM_L1) / static_cast<double>(frame->image.total()), 3.0)
        << frame->name;  // JPEG
  }
  EXPECT_FALSE(reader->next());
  const auto small = open_frames(path, "", SensorSize{32, 24});
  EXPECT_THROW(small->next(), FrameError);
}

// What an events-only camera can see of LSD's lines: those along which events fell within the
// window around the frame's time, in half or more of their pixels; read batch by batch, once.
TEST(EventSupport, ALineIsSeenWhereEventsFellAlongItAroundTheFrame) {
  const Segment upper{Point2(10.5f, 10.5f), Point2(40.5f, 10.5f)}, lower{Point2(10.5f, 30.5f), Point2(40.5f, 30.5f)};
  GroundTruthSteps truth;
  truth.times = {100'000, 200'000};
  truth.segments_at = [&](std::size_t, std::vector<Segment>& segments, std::vector<std::uint64_t>& ids) {
    segments = {upper, lower};
    ids = {1, 2};
  };
  std::vector<EventBatch> batches(2);
  const auto along = [&](EventBatch& batch, Timestamp t, int y, int x_from, int x_to) {
    for (int x = x_from; x <= x_to; ++x)
      batch.push_back(t, static_cast<std::uint16_t>(x), static_cast<std::uint16_t>(y), 1);
  };
  along(batches[0], 95'000, 10, 10, 40);       // the upper line, 5 ms before the first frame
  along(batches[0], 150'000, 30, 10, 40);      // the lower line, 50 ms from either frame: too far
  batches[0].push_back(160'000, 1000, 10, 1);  // off the sensor: passed over
  along(batches[1], 198'000, 11, 10, 20);      // a third of the upper line, 1 px off it: not half
  along(batches[1], 205'000, 29, 10, 40);      // the lower line, 1 px off it, 5 ms after the second frame
  std::size_t next = 0;
  const auto supported = event_supported_pieces(truth, {64, 48}, EventSupportRule{}, [&](EventBatch& batch) {
    if (next == batches.size()) return false;
    batch = batches[next++];
    return true;
  });
  ASSERT_EQ(supported.size(), 2u);
  EXPECT_EQ(supported[0], (std::vector<std::uint8_t>{1, 0}));
  EXPECT_EQ(supported[1], (std::vector<std::uint8_t>{0, 1}));
  EXPECT_EQ(next, batches.size());
}

TEST_F(FramesTest, LsdFindsTheSidesOfASquare) {
  const std::vector<Segment> found = lsd_segments(square(20), LsdParams{});
  int vertical_at_left = 0;
  for (const Segment& s : found) {
    if (std::abs(s.q0.x() - 20.0f) < 1.0f && std::abs(s.q1.x() - 20.0f) < 1.0f && s.length() > 18) ++vertical_at_left;
  }
  EXPECT_GE(found.size(), 4u);
  EXPECT_EQ(vertical_at_left, 1);
  LsdParams long_only;
  long_only.min_length_px = 30;
  EXPECT_TRUE(lsd_segments(square(20), long_only).empty());  // the sides are 24 px
}

// An APS frame as a real one: a moving edge blurred across what it moved during the exposure, and
// read noise, the same for the same seed and time.
TEST_F(FramesTest, SimulatedFramesBlurWithTheExposureAndCarryReadNoise) {
  const Scene scene = make_scene("three-lines-fast");
  const EventSimulator simulator(scene, SimulatorConfig{});
  const auto grey_levels = [&](const std::vector<std::uint8_t>& grey) {  // pixels strictly between dark and bright
    return std::count_if(grey.begin(), grey.end(), [](std::uint8_t v) { return v > 40 && v < 200; });
  };
  std::vector<std::uint8_t> sharp, blurred, noisy, again;
  simulator.render_frame(100'000, sharp);
  simulator.render_frame(100'000, blurred, {.exposure_us = 10'000});
  EXPECT_GT(grey_levels(blurred), 2 * grey_levels(sharp));  // the lines move fast: wide ramps instead of steps
  simulator.render_frame(100'000, noisy, {.read_noise = 5});
  simulator.render_frame(100'000, again, {.read_noise = 5});
  EXPECT_EQ(noisy, again);
  double sum = 0, squares = 0;
  for (std::size_t i = 0; i < sharp.size(); ++i) {
    const double d = static_cast<double>(noisy[i]) - static_cast<double>(sharp[i]);
    sum += d;
    squares += d * d;
  }
  const double n = static_cast<double>(sharp.size());
  EXPECT_NEAR(std::sqrt(squares / n - (sum / n) * (sum / n)), 5.0, 1.0);  // clipped at 0 and 255 a little
}

// The whole chain: the simulator's frames, written and read back, LSD on them, scored against
// the scene's exact lines: the imitation the paper relies on is close on a scene of clean edges.
TEST_F(FramesTest, LsdOnSimulatedFramesMatchesTheExactLines) {
  Scene scene = make_scene("three-lines-fast");
  scene.duration_us = 200'000;
  const EventSimulator simulator(scene, SimulatorConfig{});
  EcdFrameWriter writer(folder_);
  std::vector<std::uint8_t> grey;
  for (Timestamp t = 0; t <= scene.duration_us; t += 20'000) {
    simulator.render_frame(t, grey);
    writer.write(t, cv::Mat(scene.sensor.height, scene.sensor.width, CV_8UC1, grey.data()));
  }
  writer.close();
  const auto frames = open_ecd_frames(folder_, scene.sensor);
  const GroundTruthSteps lsd = frame_ground_truth_steps(*frames, LsdParams{});
  ASSERT_EQ(lsd.times.size(), 11u);
  const StreamEvaluator evaluator =
      evaluate_steps_against(lsd, scene_ground_truth_steps(scene, 20'000), scene.sensor, {0.01});
  EXPECT_EQ(evaluator.hold_us(), 30'000);
  EXPECT_GT(evaluator.accuracy().summed_prf(0).f, 0.9);
}

}  // namespace
}  // namespace evldt
