// The media module: OpenCV's imgcodecs and videoio behind the loader's table (module_api.hpp).

#include <memory>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include "module_api.hpp"

namespace evldt::media {
namespace {

bool write_image(const std::string& path, const cv::Mat& image, const std::vector<int>& params) {
  return cv::imwrite(path, image, params);
}

cv::Mat read_image(const std::string& path, int flags) { return cv::imread(path, flags); }

bool encode_image(const std::string& extension, const cv::Mat& image, std::vector<std::uint8_t>& out,
                  const std::vector<int>& params) {
  return cv::imencode(extension, image, out, params);
}

void* open_writer(const std::string& path, int fourcc, double fps, cv::Size size) {
  auto writer = std::make_unique<cv::VideoWriter>();
  if (!writer->open(path, fourcc, fps, size) || !writer->isOpened()) return nullptr;
  return writer.release();
}

void write_frame(void* writer, const cv::Mat& frame) { static_cast<cv::VideoWriter*>(writer)->write(frame); }

void close_writer(void* writer) { delete static_cast<cv::VideoWriter*>(writer); }

void* opened(std::unique_ptr<cv::VideoCapture> capture, bool open) {
  return open && capture->isOpened() ? capture.release() : nullptr;
}

void* open_capture_file(const std::string& path, int api) {
  auto capture = std::make_unique<cv::VideoCapture>();
  const bool open = capture->open(path, api);
  return opened(std::move(capture), open);
}

void* open_capture_camera(int index) {
  auto capture = std::make_unique<cv::VideoCapture>();
  const bool open = capture->open(index);
  return opened(std::move(capture), open);
}

bool read_frame(void* capture, cv::Mat& frame) { return static_cast<cv::VideoCapture*>(capture)->read(frame); }

double capture_property(void* capture, int property) { return static_cast<cv::VideoCapture*>(capture)->get(property); }

void close_capture(void* capture) { delete static_cast<cv::VideoCapture*>(capture); }

constexpr ModuleApi kApi{ModuleApi::kVersion, write_image, read_image,       encode_image,
                         open_writer,         write_frame, close_writer,     open_capture_file,
                         open_capture_camera, read_frame,  capture_property, close_capture};

}  // namespace
}  // namespace evldt::media

extern "C" __attribute__((visibility("default"))) const evldt::media::ModuleApi* evldt_media_module_api() {
  return &evldt::media::kApi;
}
