#pragma once
// The video reader of open_frames, for a file no container reader recognised.

#include <filesystem>
#include <memory>

#include "evldt/frames/frame_reader.hpp"

namespace evldt {

/// A video file's frames, or nullptr when OpenCV cannot open it as a video.
std::unique_ptr<FrameReader> open_video_frames(const std::filesystem::path& path, SensorSize sensor);

}  // namespace evldt
