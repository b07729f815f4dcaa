#pragma once
// A camera's calibration (pinhole intrinsics and lens distortion), read from the files real
// datasets ship, and what evldt makes of it: the table that moves each sensor pixel into the
// rectified image (the same size and intrinsics, without the distortion), where the lattice, the
// lines and the evaluation live (docs/design.md, section 1).

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "evldt/calibration/rectifier.hpp"
#include "evldt/events/event.hpp"

namespace evldt {

struct CameraModel {
  enum class Distortion { None, RadialTangential, Equidistant };
  SensorSize size{0, 0};                  ///< {0, 0} where the file does not say (the ECD's calib.txt)
  double fx = 0, fy = 0, cx = 0, cy = 0;  ///< OpenCV's convention: pixel (x, y)'s centre is at (x, y)
  Distortion distortion = Distortion::None;
  /// RadialTangential (OpenCV, ROS plumb_bob, Kalibr radtan): k1 k2 p1 p2 [k3 [k4 k5 k6]];
  /// Equidistant (OpenCV fisheye, ROS and Kalibr equidistant): k1 k2 k3 k4.
  std::vector<double> coefficients;
  std::string format;  ///< the kind of file it came from
  std::string path;    ///< the file
};

/// "none", "radtan" or "equidistant".
std::string distortion_name(CameraModel::Distortion distortion);

/// Reads a calibration: ROS camera_info YAML (plumb_bob, rational_polynomial, equidistant), Kalibr
/// camchain YAML (the first camera; radtan, equidistant), OpenCV FileStorage YAML or XML
/// (camera_matrix, distortion_coefficients) or the Event Camera Dataset's calib.txt (fx fy cx cy
/// k1 k2 p1 p2 [k3]). Throws std::runtime_error naming the file and what is wrong with it.
CameraModel read_camera_model(const std::filesystem::path& path);

/// Where the centre of each sensor pixel lies in the rectified image, in evldt's continuous
/// coordinates (pixel (x, y) covers [x, x+1) x [y, y+1)): row-major, x then y per pixel.
std::vector<float> undistorted_pixel_centres(const CameraModel& model, SensorSize sensor);

/// The rectification table of `model` for `sensor` (which must be the model's size where it has one):
/// each rectified pixel is fed by the sensor pixel that sees its centre.
std::shared_ptr<const RectificationTable> rectification_table(const CameraModel& model, SensorSize sensor);

}  // namespace evldt
