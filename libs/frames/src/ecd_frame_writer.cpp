#include <cstdio>
#include <stdexcept>

#include "evldt/frames/frame_writer.hpp"
#include "evldt/media/media.hpp"

namespace evldt {

EcdFrameWriter::EcdFrameWriter(const std::filesystem::path& folder)
    : folder_(folder), list_path_(folder / "images.txt") {
  std::filesystem::create_directories(folder_ / "images");
  list_.open(list_path_);
  if (!list_) throw std::runtime_error(list_path_.string() + ": cannot write");
}

void EcdFrameWriter::write(Timestamp t_us, const cv::Mat& grey) {
  char name[32];
  std::snprintf(name, sizeof name, "images/frame_%08d.png", written_);
  if (!media::write_image((folder_ / name).string(), grey))
    throw std::runtime_error((folder_ / name).string() + ": cannot write");
  char line[64];
  std::snprintf(line, sizeof line, "%.6f %s\n", static_cast<double>(t_us) * 1e-6, name);
  list_ << line;
  ++written_;
}

void EcdFrameWriter::close() {
  list_.close();
  if (list_.fail()) throw std::runtime_error(list_path_.string() + ": write failed");
}

}  // namespace evldt
