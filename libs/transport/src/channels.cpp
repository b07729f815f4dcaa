#include "evldt/transport/channels.hpp"

#include <algorithm>
#include <cctype>
#include <chrono>
#include <stdexcept>

namespace evldt {
namespace {

std::string channel(std::string_view prefix, std::string_view camera) {
  check_camera_name(camera);
  std::string name(prefix);
  for (const char c : camera) name += static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return name;
}

}  // namespace

void check_camera_name(std::string_view camera) {
  const bool valid = !camera.empty() && camera.size() <= 32 && std::all_of(camera.begin(), camera.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_';
  });
  if (!valid) {
    throw std::invalid_argument("camera name '" + std::string(camera) + "' must be 1-32 letters, digits or '_'");
  }
}

std::string events_channel(std::string_view camera) { return channel("EVENTS_", camera); }
std::string lines_channel(std::string_view camera) { return channel("LINES_", camera); }
std::string camera_info_channel(std::string_view camera) { return channel("CAMERA_INFO_", camera); }
std::string whole_lines_channel(std::string_view camera) { return channel("WHOLE_LINES_", camera); }

std::int64_t wall_clock_us() {
  return std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

}  // namespace evldt
