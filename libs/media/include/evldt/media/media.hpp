#pragma once
// Image and video files through OpenCV (imwrite, imread, imencode, VideoWriter, VideoCapture),
// from a module loaded the first time one is used (libs/media/CMakeLists.txt says why). The module
// is looked for at $EVLDT_MEDIA_MODULE, beside the binary that holds this code (the Python
// extension carries one), where the install rules put it relative to that binary (a package unpacked
// under another root), in the build tree, then where it is installed; when none loads, the call
// throws std::runtime_error saying where it looked. OpenCV's constants (cv::IMWRITE_*,
// cv::IMREAD_*, cv::CAP_*) come from its headers as usual.

#include <cstdint>
#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace evldt::media {

/// cv::imwrite: whether the file was written.
bool write_image(const std::string& path, const cv::Mat& image, const std::vector<int>& params = {});
/// cv::imread: empty when the file is no image.
cv::Mat read_image(const std::string& path, int flags);
/// cv::imencode into `out` (".jpg", ".png", ...): whether it was encoded.
bool encode_image(const std::string& extension, const cv::Mat& image, std::vector<std::uint8_t>& out,
                  const std::vector<int>& params = {});

/// cv::VideoWriter::fourcc, without loading the module.
constexpr int fourcc(char c1, char c2, char c3, char c4) {
  return (c1 & 255) | ((c2 & 255) << 8) | ((c3 & 255) << 16) | ((c4 & 255) << 24);
}

/// cv::VideoWriter.
class VideoWriter {
 public:
  VideoWriter();
  ~VideoWriter();
  VideoWriter(VideoWriter&&) noexcept;
  VideoWriter& operator=(VideoWriter&&) noexcept;
  /// cv::VideoWriter::open: whether it is open.
  bool open(const std::string& path, int fourcc, double fps, cv::Size size);
  [[nodiscard]] bool is_open() const { return handle_ != nullptr; }
  void write(const cv::Mat& frame);
  /// Finishes the file (as the destructor does).
  void release();

 private:
  void* handle_ = nullptr;
};

/// cv::VideoCapture.
class VideoCapture {
 public:
  VideoCapture();
  ~VideoCapture();
  VideoCapture(VideoCapture&&) noexcept;
  VideoCapture& operator=(VideoCapture&&) noexcept;
  /// A file, with OpenCV's backend `api` (cv::CAP_ANY: any); whether it is open.
  bool open(const std::string& path, int api);
  /// A camera by index; whether it is open.
  bool open(int index);
  [[nodiscard]] bool is_open() const { return handle_ != nullptr; }
  /// The next frame into `frame`: false at the end.
  bool read(cv::Mat& frame);
  /// cv::VideoCapture::get (cv::CAP_PROP_*).
  [[nodiscard]] double get(int property) const;
  void release();

 private:
  void* handle_ = nullptr;
};

}  // namespace evldt::media
