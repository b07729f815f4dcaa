#pragma once
// Writes rendered frames to an mp4 and/or numbered PNG files (offline runner and headless viz).

#include <filesystem>
#include <opencv2/core.hpp>

#include "evldt/media/media.hpp"

namespace evldt {

class FrameWriter {
 public:
  /// Either path may be empty (not written). Throws std::runtime_error if the video cannot be opened
  /// or the directory created.
  FrameWriter(const std::filesystem::path& video, const std::filesystem::path& frames_dir, double fps, cv::Size size);
  [[nodiscard]] bool enabled() const { return video_.is_open() || !frames_dir_.empty(); }
  /// Throws std::runtime_error if a PNG cannot be written.
  void write(const cv::Mat& frame);
  [[nodiscard]] int frames() const { return frames_; }

 private:
  media::VideoWriter video_;
  std::filesystem::path frames_dir_;
  int frames_ = 0;
};

}  // namespace evldt
