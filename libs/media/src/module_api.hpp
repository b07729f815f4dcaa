#pragma once
// What the media module (opencv_media.cpp) hands the loader (media.cpp): the calls into OpenCV's
// imgcodecs and videoio. Both sides are built together, so C++ types cross freely; kVersion guards
// against a module of another build found on the search path.

#include <cstdint>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace evldt::media {

struct ModuleApi {
  static constexpr int kVersion = 1;
  int version;
  bool (*write_image)(const std::string& path, const cv::Mat& image, const std::vector<int>& params);
  cv::Mat (*read_image)(const std::string& path, int flags);
  bool (*encode_image)(const std::string& extension, const cv::Mat& image, std::vector<std::uint8_t>& out,
                       const std::vector<int>& params);
  void* (*open_writer)(const std::string& path, int fourcc, double fps, cv::Size size);  // null: not opened
  void (*write_frame)(void* writer, const cv::Mat& frame);
  void (*close_writer)(void* writer);
  void* (*open_capture_file)(const std::string& path, int api);  // null: not opened
  void* (*open_capture_camera)(int index);
  bool (*read_frame)(void* capture, cv::Mat& frame);
  double (*capture_property)(void* capture, int property);
  void (*close_capture)(void* capture);
};

}  // namespace evldt::media

/// The module's one exported symbol.
extern "C" const evldt::media::ModuleApi* evldt_media_module_api();
