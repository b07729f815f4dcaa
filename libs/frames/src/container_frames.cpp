// Frames from containers that hold images beside events (ROS 1 and 2 bags, MCAP, MVSEC's HDF5, AEDAT
// 4.0, 3.1 and 2.0): each image,
// through the conversion its pixel encoding names, to the 8-bit grey frame LSD runs on.

#include <opencv2/imgproc.hpp>

#include "evldt/containers/image_source.hpp"
#include "evldt/frames/frame_reader.hpp"
#include "video_frames.hpp"

namespace evldt {
namespace {

constexpr std::uint32_t kMaxSide = 1u << 16;  // px: larger than any sensor; beyond it the size is garbage

/// The image as 8-bit grey, or FrameError naming the frame. 16-bit pixels keep their high byte (a
/// DAVIS's 10-bit APS read as mono16 spans the whole 16-bit range).
cv::Mat grey_of(const RecordingImage& image, const std::string& name) {
  const std::string& encoding = image.encoding;
  const int channels = encoding == "bgr8" || encoding == "rgb8" ? 3 : 1;
  const int depth = encoding == "mono16" ? 2 : 1;
  if (encoding != "mono8" && encoding != "mono16" && channels == 1) {
    throw FrameError(name + ": pixel encoding '" + encoding + "' is not one evldt reads (mono8, mono16, bgr8, rgb8)");
  }
  if (image.step < std::uint64_t{image.width} * static_cast<std::uint64_t>(channels * depth)) {
    throw FrameError(name + ": rows of " + std::to_string(image.step) + " bytes are too short for " +
                     std::to_string(image.width) + " " + encoding + " pixels");
  }
  const int rows = static_cast<int>(image.height), cols = static_cast<int>(image.width);
  cv::Mat grey;
  if (depth == 2) {
    // Byte by byte: the message's 16-bit pixels need not be aligned.
    const int high = image.big_endian ? 0 : 1;
    grey.create(rows, cols, CV_8UC1);
    for (int y = 0; y < rows; ++y) {
      const std::uint8_t* row = image.data.data() + static_cast<std::size_t>(y) * image.step;
      auto* out = grey.ptr<std::uint8_t>(y);
      for (int x = 0; x < cols; ++x) out[x] = row[2 * x + high];
    }
  } else {
    // A view of the container's bytes (valid while this runs); OpenCV copies into the result.
    const cv::Mat view(rows, cols, CV_8UC(channels), const_cast<std::uint8_t*>(image.data.data()), image.step);
    if (channels == 3) {
      cv::cvtColor(view, grey, encoding == "bgr8" ? cv::COLOR_BGR2GRAY : cv::COLOR_RGB2GRAY);
    } else {
      grey = view.clone();
    }
  }
  return grey;
}

class ImageFrameReader final : public FrameReader {
 public:
  ImageFrameReader(std::unique_ptr<ImageSource> images, SensorSize sensor)
      : images_(std::move(images)), sensor_(sensor) {}

  std::optional<Frame> next() override {
    RecordingImage image;
    std::string location;
    try {
      if (!images_->next(image, location)) return std::nullopt;
    } catch (const std::runtime_error& error) {
      throw FrameError(error.what());
    }
    Frame frame;
    frame.t_us = image.t_us;
    frame.name = location;
    if (started_ && frame.t_us < last_us_) {
      throw FrameError(location + ": frame at " + std::to_string(frame.t_us) + " us is earlier than the one before (" +
                       std::to_string(last_us_) + " us)");
    }
    if (image.width > kMaxSide || image.height > kMaxSide ||
        !fits_sensor(sensor_, static_cast<int>(image.width), static_cast<int>(image.height))) {
      throw FrameError(location + ": frame is " + std::to_string(image.width) + "x" + std::to_string(image.height) +
                       ", the sensor " + std::to_string(sensor_.width) + "x" + std::to_string(sensor_.height));
    }
    frame.image = grey_of(image, location);
    started_ = true;
    last_us_ = frame.t_us;
    return frame;
  }

 private:
  std::unique_ptr<ImageSource> images_;
  SensorSize sensor_;
  bool started_ = false;
  Timestamp last_us_ = 0;
};

}  // namespace

bool fits_sensor(SensorSize& sensor, int width, int height) {
  if (sensor.width == 0 && sensor.height == 0) sensor = {width, height};
  return sensor.width == width && sensor.height == height;
}

SensorSize frames_sensor_size(const std::filesystem::path& path, const std::string& stream) {
  SensorSize size{0, 0};
  const auto frames = open_frames(path, stream, size);
  const auto first = frames->next();
  if (!first) throw FrameError(path.string() + ": no frame to take the sensor size from");
  return {first->image.cols, first->image.rows};
}

std::unique_ptr<FrameReader> open_frames(const std::filesystem::path& path, const std::string& stream,
                                         SensorSize sensor) {
  if (std::filesystem::is_directory(path) || path.filename() == "images.txt") return open_ecd_frames(path, sensor);
  std::unique_ptr<ImageSource> images;
  try {
    images = open_image_container(path, stream);
  } catch (const std::runtime_error& error) {
    throw FrameError(error.what());
  }
  if (images) return std::make_unique<ImageFrameReader>(std::move(images), sensor);
  if (auto video = open_video_frames(path, sensor)) return video;
  throw FrameError(path.string() +
                   ": not a source of frames evldt reads (an ECD folder with images.txt, a ROS 1 or 2 bag or MCAP "
                   "file, MVSEC's HDF5, an AEDAT 4.0, 3.1 or 2.0 recording, a video file)");
}

}  // namespace evldt
