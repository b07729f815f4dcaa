#include "evldt/render/frame_writer.hpp"

#include <cstdio>
#include <stdexcept>

namespace evldt {

FrameWriter::FrameWriter(const std::filesystem::path& video, const std::filesystem::path& frames_dir, double fps,
                         cv::Size size)
    : frames_dir_(frames_dir) {
  if (!video.empty() && !video_.open(video.string(), media::fourcc('m', 'p', '4', 'v'), fps, size)) {
    throw std::runtime_error("cannot open video writer for " + video.string());
  }
  if (!frames_dir_.empty()) std::filesystem::create_directories(frames_dir_);
}

void FrameWriter::write(const cv::Mat& frame) {
  if (video_.is_open()) video_.write(frame);
  if (!frames_dir_.empty()) {
    char name[32];
    std::snprintf(name, sizeof name, "frame_%06d.png", frames_);
    const auto path = frames_dir_ / name;
    if (!media::write_image(path.string(), frame)) throw std::runtime_error("cannot write " + path.string());
  }
  ++frames_;
}

}  // namespace evldt
