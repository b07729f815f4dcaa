#pragma once
// Intensity frames a recording holds beside its events (a DAVIS's APS frames, a simulator's
// renderings), pixel-aligned with the events: the ground truth the paper draws lines from.
// A reader per container, behind one interface, as the event readers are: the Event Camera
// Dataset's folder layout; sensor_msgs/Image in ROS 1 and 2 bags (.db3, MCAP), MVSEC's HDF5 and AEDAT
// frames, whose containers (libs/containers) yield images that are converted here by their pixel
// encoding; video files, whose frames are those events are emulated from (--from-video).

#include <filesystem>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>

#include <opencv2/core.hpp>

#include "evldt/events/event.hpp"

namespace evldt {

/// One frame: 8-bit grey, the sensor's size.
struct Frame {
  Timestamp t_us = 0;  ///< exposure time stamp, on the events' clock
  cv::Mat image;       ///< CV_8UC1, sensor.height x sensor.width
  std::string name;    ///< where it came from, for messages (the image file)
};

/// A frame that cannot be used: the message names the frame and the reason. Nothing is scored
/// from a source once it has thrown.
class FrameError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class FrameReader {
 public:
  virtual ~FrameReader() = default;
  /// The next frame in time order, nullopt at the end; throws FrameError for a frame that is
  /// missing, unreadable, of another size than the sensor, or earlier than the one before.
  virtual std::optional<Frame> next() = 0;
};

/// The Event Camera Dataset's layout: `images.txt` (lines "t_seconds images/frame_00000000.png",
/// paths relative to its folder) and the images. `path` is the folder or its images.txt. Throws
/// FrameError when there is no images.txt.
std::unique_ptr<FrameReader> open_ecd_frames(const std::filesystem::path& path, SensorSize sensor);

/// The time of frame `index` of a video file at `fps` frames a second: the clock of the frames read
/// here and of the events emulated from the video (libs/sources).
Timestamp video_frame_time_us(std::uint64_t index, double fps);

/// Whether a frame of width x height belongs to `sensor`; an unset sensor ({0, 0}) takes the size of
/// the first frame asked about, which every later one must then have.
bool fits_sensor(SensorSize& sensor, int width, int height);

/// The size of the first frame of `path` (as open_frames reads it): the sensor's, where a recording
/// says it only by its frames. Throws FrameError as open_frames does, or when there is no frame.
SensorSize frames_sensor_size(const std::filesystem::path& path, const std::string& stream);

/// The frames of `path`, whichever container it is: an ECD folder (or its images.txt); a ROS 1 or
/// ROS 2 bag's (.db3 or MCAP) sensor_msgs/Image topic `stream` (empty: the first; pixel encodings
/// mono8, mono16 (its high byte), bgr8 and rgb8, as grey); MVSEC's HDF5 frames `stream` (empty:
/// /davis/left/image_raw, with its _ts times); the frames of an AEDAT 4.0 recording's first frame
/// stream, of AEDAT 3.1 frame packets, of jAER's AEDAT 2.0 DAVIS APS samples (reset - signal), each at
/// the middle of its exposure (libs/containers: aedat4.hpp, aedat_images.hpp); else a video file OpenCV opens (as grey,
/// at its frame rate, else 30 fps, as --from-video emulates events from it). `sensor` {0, 0}: the first frame's size.
/// Throws FrameError naming the path for anything else or a container without them.
std::unique_ptr<FrameReader> open_frames(const std::filesystem::path& path, const std::string& stream,
                                         SensorSize sensor);

}  // namespace evldt
