#include "evldt/media/media.hpp"

#include <dlfcn.h>

#include <cstdlib>
#include <filesystem>
#include <stdexcept>
#include <utility>

#include <spdlog/spdlog.h>

#include "module_api.hpp"

namespace evldt::media {
namespace {

// The places the module is looked for, in order (media.hpp).
std::vector<std::string> module_candidates() {
  std::vector<std::string> candidates;
  if (const char* given = std::getenv("EVLDT_MEDIA_MODULE"); given != nullptr && *given != '\0')
    candidates.emplace_back(given);
  Dl_info self{};
  if (dladdr(reinterpret_cast<void*>(&module_candidates), &self) != 0 && self.dli_fname != nullptr) {
    const std::filesystem::path folder = std::filesystem::path(self.dli_fname).parent_path();
    candidates.push_back((folder / EVLDT_MEDIA_MODULE_NAME).string());
    candidates.push_back((folder / EVLDT_MEDIA_FROM_BINDIR).lexically_normal().string());
  }
  candidates.emplace_back(EVLDT_MEDIA_BUILD_PATH);
  candidates.emplace_back(EVLDT_MEDIA_INSTALL_PATH);
  return candidates;
}

const ModuleApi* load_module() {
  std::string tried;
  for (const std::string& path : module_candidates()) {
    if (!std::filesystem::exists(path)) {
      tried += "\n  " + path + ": not there";
      continue;
    }
    void* handle = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (handle == nullptr) {
      tried += "\n  " + path + ": " + dlerror();
      continue;
    }
    using Entry = const ModuleApi* (*)();
    const auto entry = reinterpret_cast<Entry>(dlsym(handle, "evldt_media_module_api"));
    const ModuleApi* api = entry != nullptr ? entry() : nullptr;
    if (api != nullptr && api->version == ModuleApi::kVersion) {
      spdlog::debug("media module {}", path);
      return api;  // kept loaded for the process's life
    }
    tried += "\n  " + path + ": not an evldt media module of this build";
    dlclose(handle);
  }
  throw std::runtime_error("evldt: image and video files need the module " EVLDT_MEDIA_MODULE_NAME
                           " (OpenCV's imgcodecs and videoio); looked for it at:" +
                           tried);
}

const ModuleApi& module() {
  static const ModuleApi* const api = load_module();  // a failed load throws and is tried again next time
  return *api;
}

}  // namespace

bool write_image(const std::string& path, const cv::Mat& image, const std::vector<int>& params) {
  return module().write_image(path, image, params);
}

cv::Mat read_image(const std::string& path, int flags) { return module().read_image(path, flags); }

bool encode_image(const std::string& extension, const cv::Mat& image, std::vector<std::uint8_t>& out,
                  const std::vector<int>& params) {
  return module().encode_image(extension, image, out, params);
}

VideoWriter::VideoWriter() = default;
VideoWriter::~VideoWriter() { release(); }
VideoWriter::VideoWriter(VideoWriter&& other) noexcept : handle_(std::exchange(other.handle_, nullptr)) {}
VideoWriter& VideoWriter::operator=(VideoWriter&& other) noexcept {
  if (this != &other) {
    release();
    handle_ = std::exchange(other.handle_, nullptr);
  }
  return *this;
}

bool VideoWriter::open(const std::string& path, int fourcc, double fps, cv::Size size) {
  release();
  handle_ = module().open_writer(path, fourcc, fps, size);
  return handle_ != nullptr;
}

void VideoWriter::write(const cv::Mat& frame) {
  if (handle_ != nullptr) module().write_frame(handle_, frame);
}

void VideoWriter::release() {
  if (handle_ != nullptr) module().close_writer(std::exchange(handle_, nullptr));
}

VideoCapture::VideoCapture() = default;
VideoCapture::~VideoCapture() { release(); }
VideoCapture::VideoCapture(VideoCapture&& other) noexcept : handle_(std::exchange(other.handle_, nullptr)) {}
VideoCapture& VideoCapture::operator=(VideoCapture&& other) noexcept {
  if (this != &other) {
    release();
    handle_ = std::exchange(other.handle_, nullptr);
  }
  return *this;
}

bool VideoCapture::open(const std::string& path, int api) {
  release();
  handle_ = module().open_capture_file(path, api);
  return handle_ != nullptr;
}

bool VideoCapture::open(int index) {
  release();
  handle_ = module().open_capture_camera(index);
  return handle_ != nullptr;
}

bool VideoCapture::read(cv::Mat& frame) { return handle_ != nullptr && module().read_frame(handle_, frame); }

double VideoCapture::get(int property) const {
  return handle_ != nullptr ? module().capture_property(handle_, property) : 0.0;
}

void VideoCapture::release() {
  if (handle_ != nullptr) module().close_capture(std::exchange(handle_, nullptr));
}

}  // namespace evldt::media
