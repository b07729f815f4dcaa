#pragma once
// Intensity images that containers hold beside events (a DAVIS's APS frames), kept apart from their
// pixel encodings as events are from theirs: a container yields images with their encoding's name,
// and libs/frames turns each into a grey frame.

#include <cstdint>
#include <filesystem>
#include <memory>
#include <span>
#include <string>

#include "evldt/events/event.hpp"

namespace evldt {

/// One image as a container stores it.
struct RecordingImage {
  Timestamp t_us = 0;  ///< on the clock of the container's events
  std::uint32_t width = 0, height = 0;
  std::string encoding;  ///< ROS's names: "mono8", "mono16", "bgr8", "rgb8"...
  bool big_endian = false;
  std::uint32_t step = 0;              ///< bytes per row
  std::span<const std::uint8_t> data;  ///< at least step * height bytes, valid until the next image
};

/// The images of one stream of a container, in the container's order.
class ImageSource {
 public:
  virtual ~ImageSource() = default;
  /// The next image; false at the end. `location` is set to which one it is (file, message or
  /// index), for errors. Throws std::runtime_error naming the file and image for one that cannot
  /// be read.
  virtual bool next(RecordingImage& image, std::string& location) = 0;
  /// "ROS 1 bag, /dvs/image_raw (sensor_msgs/Image)".
  [[nodiscard]] virtual std::string description() const = 0;
};

/// The images of the container `path` holds, recognised by its first bytes: a ROS 1 bag's, ROS 2
/// bag's (.db3) or MCAP file's image topic `stream` (empty: the first), an HDF5 file's frames `stream` (empty: MVSEC's
/// /davis/left/image_raw), an AEDAT 4.0 file's first frame stream, AEDAT 3.1 frame packets, jAER's
/// AEDAT 2.0 DAVIS APS samples; nullptr for a file that is none of them. Throws std::runtime_error naming
/// the file for a container without such images.
std::unique_ptr<ImageSource> open_image_container(const std::filesystem::path& path, const std::string& stream);

}  // namespace evldt
