#pragma once
// Writes frames in the Event Camera Dataset's layout (images.txt and images/frame_NNNNNNNN.png),
// which open_ecd_frames reads: the simulator's frames beside its events.txt.

#include <filesystem>
#include <fstream>

#include <opencv2/core.hpp>

#include "evldt/events/event.hpp"

namespace evldt {

class EcdFrameWriter {
 public:
  /// Creates `folder`/images and `folder`/images.txt; throws std::runtime_error where it cannot.
  explicit EcdFrameWriter(const std::filesystem::path& folder);
  /// Appends a frame (8-bit grey) taken at t_us; throws std::runtime_error when it cannot be written.
  void write(Timestamp t_us, const cv::Mat& grey);
  /// Flushes images.txt; throws std::runtime_error on a write error.
  void close();
  [[nodiscard]] const std::filesystem::path& list_path() const { return list_path_; }

 private:
  std::filesystem::path folder_, list_path_;
  std::ofstream list_;
  int written_ = 0;
};

}  // namespace evldt
