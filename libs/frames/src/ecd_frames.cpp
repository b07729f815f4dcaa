#include <cmath>
#include <fstream>
#include <sstream>

#include <opencv2/imgcodecs.hpp>  // its constants; the calls go through evldt::media

#include "evldt/frames/frame_reader.hpp"
#include "evldt/media/media.hpp"

namespace evldt {
namespace {

class EcdFrameReader final : public FrameReader {
 public:
  EcdFrameReader(const std::filesystem::path& list, SensorSize sensor) : folder_(list.parent_path()), sensor_(sensor) {
    in_.open(list);
    if (!in_) throw FrameError(list.string() + ": cannot open the frame list");
    list_ = list.string();
  }

  std::optional<Frame> next() override {
    std::string line;
    while (std::getline(in_, line)) {
      ++line_number_;
      if (line.empty() || line[0] == '#') continue;
      std::istringstream fields(line);
      double seconds = 0;
      std::string file;
      if (!(fields >> seconds >> file) || !std::isfinite(seconds) || seconds < 0) {
        throw FrameError(where() + ": expected \"t_seconds image_path\", got \"" + line + "\"");
      }
      Frame frame;
      frame.t_us = std::llround(seconds * 1e6);
      frame.name = (folder_ / file).string();
      if (started_ && frame.t_us < last_us_) {
        throw FrameError(where() + ": frame " + frame.name + " at " + std::to_string(frame.t_us) +
                         " us is earlier than the one before (" + std::to_string(last_us_) + " us)");
      }
      // Checked first: OpenCV would log its own warning for a missing file.
      if (!std::filesystem::is_regular_file(frame.name))
        throw FrameError(where() + ": frame " + frame.name + " is missing");
      frame.image = media::read_image(frame.name, cv::IMREAD_GRAYSCALE);
      if (frame.image.empty()) throw FrameError(where() + ": frame " + frame.name + " is not an image");
      if (!fits_sensor(sensor_, frame.image.cols, frame.image.rows)) {
        throw FrameError(where() + ": frame " + frame.name + " is " + std::to_string(frame.image.cols) + "x" +
                         std::to_string(frame.image.rows) + ", the sensor " + std::to_string(sensor_.width) + "x" +
                         std::to_string(sensor_.height));
      }
      started_ = true;
      last_us_ = frame.t_us;
      return frame;
    }
    return std::nullopt;
  }

 private:
  [[nodiscard]] std::string where() const { return list_ + ":" + std::to_string(line_number_); }

  std::filesystem::path folder_;
  SensorSize sensor_;
  std::ifstream in_;
  std::string list_;
  int line_number_ = 0;
  bool started_ = false;
  Timestamp last_us_ = 0;
};

}  // namespace

std::unique_ptr<FrameReader> open_ecd_frames(const std::filesystem::path& path, SensorSize sensor) {
  const std::filesystem::path list = std::filesystem::is_directory(path) ? path / "images.txt" : path;
  if (!std::filesystem::is_regular_file(list))
    throw FrameError(list.string() + ": no frame list (ECD layout: images.txt and images/)");
  return std::make_unique<EcdFrameReader>(list, sensor);
}

}  // namespace evldt
