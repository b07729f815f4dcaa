// The frames of a video file: the images --from-video emulates events from, on the same clock, so
// that LSD on them is a ground truth pixel-aligned with those events.

#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>  // its constants; the calls go through evldt::media

#include "evldt/frames/frame_reader.hpp"
#include "evldt/media/media.hpp"
#include "video_frames.hpp"

namespace evldt {
namespace {

class VideoFrameReader final : public FrameReader {
 public:
  VideoFrameReader(media::VideoCapture capture, const std::filesystem::path& path, SensorSize sensor)
      : capture_(std::move(capture)), path_(path.string()), sensor_(sensor) {
    const double file_fps = capture_.get(cv::CAP_PROP_FPS);
    fps_ = file_fps > 0 && file_fps < 10000 ? file_fps : 30.0;
  }

  std::optional<Frame> next() override {
    if (!capture_.read(image_) || image_.empty()) return std::nullopt;
    Frame frame;
    frame.name = path_ + ", frame " + std::to_string(index_);
    frame.t_us = video_frame_time_us(index_++, fps_);
    if (!fits_sensor(sensor_, image_.cols, image_.rows)) {
      throw FrameError(frame.name + " is " + std::to_string(image_.cols) + "x" + std::to_string(image_.rows) +
                       ", the sensor " + std::to_string(sensor_.width) + "x" + std::to_string(sensor_.height));
    }
    if (image_.channels() == 1) {
      image_.copyTo(frame.image);
    } else {
      cv::cvtColor(image_, frame.image, image_.channels() == 4 ? cv::COLOR_BGRA2GRAY : cv::COLOR_BGR2GRAY);
    }
    if (frame.image.depth() != CV_8U) frame.image.convertTo(frame.image, CV_8U);
    return frame;
  }

 private:
  media::VideoCapture capture_;
  std::string path_;
  SensorSize sensor_;
  double fps_ = 30;
  std::uint64_t index_ = 0;
  cv::Mat image_;
};

}  // namespace

Timestamp video_frame_time_us(std::uint64_t index, double fps) {
  return static_cast<Timestamp>(static_cast<double>(index) * 1e6 / fps);
}

std::unique_ptr<FrameReader> open_video_frames(const std::filesystem::path& path, SensorSize sensor) {
  media::VideoCapture capture;
  // FFmpeg alone: the other backends would log their own errors for a file that is no video.
  if (!capture.open(path.string(), cv::CAP_FFMPEG)) return nullptr;
  return std::make_unique<VideoFrameReader>(std::move(capture), path, sensor);
}

}  // namespace evldt
