#include "evldt/calibration/camera_model.hpp"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <fstream>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <sstream>
#include <stdexcept>

namespace evldt {

namespace {

[[noreturn]] void fail(const std::filesystem::path& path, const std::string& what) {
  throw std::runtime_error(path.string() + ": " + what);
}

CameraModel::Distortion distortion_of(const std::filesystem::path& path, const std::string& name) {
  if (name == "plumb_bob" || name == "rational_polynomial" || name == "radtan" || name == "radial-tangential") {
    return CameraModel::Distortion::RadialTangential;
  }
  if (name == "equidistant" || name == "fisheye") return CameraModel::Distortion::Equidistant;
  if (name == "none") return CameraModel::Distortion::None;
  fail(path,
       "distortion model '" + name + "' is not one evldt knows (plumb_bob, rational_polynomial, radtan, equidistant)");
}

std::vector<double> numbers_of(const YAML::Node& node) {
  std::vector<double> out;
  for (const YAML::Node& value : node) out.push_back(value.as<double>());
  return out;
}

/// ROS camera_info (camera_calibration_parsers): camera_matrix.data, distortion_model, distortion_coefficients.data.
CameraModel from_ros(const std::filesystem::path& path, const YAML::Node& root) {
  CameraModel model;
  model.format = "ROS camera_info";
  if (root["image_width"] && root["image_height"])
    model.size = {root["image_width"].as<int>(), root["image_height"].as<int>()};
  const std::vector<double> k = numbers_of(root["camera_matrix"]["data"]);
  if (k.size() != 9) fail(path, "camera_matrix.data must hold 9 numbers");
  model.fx = k[0];
  model.cx = k[2];
  model.fy = k[4];
  model.cy = k[5];
  model.distortion =
      distortion_of(path, root["distortion_model"] ? root["distortion_model"].as<std::string>() : "plumb_bob");
  if (root["distortion_coefficients"]) model.coefficients = numbers_of(root["distortion_coefficients"]["data"]);
  return model;
}

/// Kalibr's camchain: the first camera (cam0), pinhole intrinsics [fu, fv, pu, pv].
CameraModel from_kalibr(const std::filesystem::path& path, const YAML::Node& camera) {
  CameraModel model;
  model.format = "Kalibr camchain";
  if (camera["camera_model"] && camera["camera_model"].as<std::string>() != "pinhole") {
    fail(path, "camera model '" + camera["camera_model"].as<std::string>() + "' is not pinhole");
  }
  const std::vector<double> k = numbers_of(camera["intrinsics"]);
  if (k.size() != 4) fail(path, "intrinsics must hold 4 numbers (fu, fv, pu, pv)");
  model.fx = k[0];
  model.fy = k[1];
  model.cx = k[2];
  model.cy = k[3];
  if (camera["resolution"]) {
    const std::vector<double> size = numbers_of(camera["resolution"]);
    if (size.size() == 2) model.size = {static_cast<int>(size[0]), static_cast<int>(size[1])};
  }
  model.distortion =
      distortion_of(path, camera["distortion_model"] ? camera["distortion_model"].as<std::string>() : "none");
  if (camera["distortion_coeffs"]) model.coefficients = numbers_of(camera["distortion_coeffs"]);
  return model;
}

/// OpenCV's FileStorage (YAML 1.0 or XML): camera_matrix and distortion_coefficients as opencv-matrix.
CameraModel from_opencv(const std::filesystem::path& path) {
  cv::FileStorage storage;
  try {
    storage.open(path.string(), cv::FileStorage::READ);
  } catch (const cv::Exception& error) {
    fail(path, std::string("not a FileStorage file: ") + error.what());
  }
  if (!storage.isOpened()) fail(path, "cannot be opened as an OpenCV FileStorage file");
  cv::Mat k, d;
  storage["camera_matrix"] >> k;
  storage["distortion_coefficients"] >> d;
  if (k.empty()) fail(path, "no camera_matrix");
  k.convertTo(k, CV_64F);
  if (k.rows != 3 || k.cols != 3) fail(path, "camera_matrix is not 3x3");
  CameraModel model;
  model.format = "OpenCV FileStorage";
  model.fx = k.at<double>(0, 0);
  model.fy = k.at<double>(1, 1);
  model.cx = k.at<double>(0, 2);
  model.cy = k.at<double>(1, 2);
  int width = 0, height = 0;
  storage["image_width"] >> width;
  storage["image_height"] >> height;
  if (width > 0 && height > 0) model.size = {width, height};
  if (!d.empty()) {
    d.convertTo(d, CV_64F);
    model.coefficients.assign(d.begin<double>(), d.end<double>());
  }
  std::string name;
  storage["distortion_model"] >> name;
  model.distortion = name.empty() ? (model.coefficients.empty() ? CameraModel::Distortion::None
                                                                : CameraModel::Distortion::RadialTangential)
                                  : distortion_of(path, name);
  return model;
}

/// The Event Camera Dataset's calib.txt: fx fy cx cy k1 k2 p1 p2 [k3], the sensor size not given.
CameraModel from_ecd(const std::filesystem::path& path, const std::string& text) {
  std::istringstream in(text);
  std::vector<double> values;
  std::string word;
  while (in >> word) {
    try {
      std::size_t used = 0;
      values.push_back(std::stod(word, &used));
      if (used != word.size()) throw std::invalid_argument(word);
    } catch (const std::exception&) {
      fail(path, "'" + word + "' is not a number (calib.txt holds fx fy cx cy k1 k2 p1 p2 [k3])");
    }
  }
  if (values.size() != 4 && values.size() != 8 && values.size() != 9) {
    fail(path, "calib.txt holds fx fy cx cy k1 k2 p1 p2 [k3]: found " + std::to_string(values.size()) + " numbers");
  }
  CameraModel model;
  model.format = "ECD calib.txt";
  model.fx = values[0];
  model.fy = values[1];
  model.cx = values[2];
  model.cy = values[3];
  model.coefficients.assign(values.begin() + 4, values.end());
  model.distortion =
      model.coefficients.empty() ? CameraModel::Distortion::None : CameraModel::Distortion::RadialTangential;
  return model;
}

void check(const std::filesystem::path& path, const CameraModel& model) {
  const auto finite = [](double v) { return std::isfinite(v); };
  if (!(model.fx > 0 && model.fy > 0 && finite(model.fx) && finite(model.fy) && finite(model.cx) && finite(model.cy))) {
    fail(path, "the focal lengths must be positive and the principal point finite");
  }
  for (const double c : model.coefficients) {
    if (!finite(c)) fail(path, "a distortion coefficient is not a finite number");
  }
  const std::size_t n = model.coefficients.size();
  if (model.distortion == CameraModel::Distortion::RadialTangential && n != 4 && n != 5 && n != 8) {
    fail(path, "radial-tangential distortion takes 4, 5 or 8 coefficients, not " + std::to_string(n));
  }
  if (model.distortion == CameraModel::Distortion::Equidistant && n != 4) {
    fail(path, "equidistant distortion takes 4 coefficients, not " + std::to_string(n));
  }
  if (model.size.width < 0 || model.size.height < 0 || model.size.width > kMaxSensorSide ||
      model.size.height > kMaxSensorSide) {
    fail(path, "the image size is out of range");
  }
}

}  // namespace

std::string distortion_name(CameraModel::Distortion distortion) {
  switch (distortion) {
    case CameraModel::Distortion::None:
      return "none";
    case CameraModel::Distortion::RadialTangential:
      return "radtan";
    case CameraModel::Distortion::Equidistant:
      return "equidistant";
  }
  return "?";
}

CameraModel read_camera_model(const std::filesystem::path& path) {
  std::ifstream file(path, std::ios::binary);
  if (!file) fail(path, "cannot be opened");
  const std::string text((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  CameraModel model;
  const std::string extension = path.extension().string();
  if (extension == ".xml" || text.rfind("%YAML", 0) == 0 || text.find("!!opencv-matrix") != std::string::npos) {
    model = from_opencv(path);
  } else if (text.find(':') == std::string::npos) {
    model = from_ecd(path, text);
  } else {
    YAML::Node root;
    try {
      root = YAML::Load(text);
    } catch (const YAML::Exception& error) {
      fail(path, std::string("not valid YAML: ") + error.what());
    }
    try {
      if (root.IsMap() && root["camera_matrix"]) {
        model = from_ros(path, root);
      } else if (root.IsMap() && root["cam0"]) {
        model = from_kalibr(path, root["cam0"]);
      } else if (root.IsMap() && root["intrinsics"]) {
        model = from_kalibr(path, root);
      } else {
        fail(path, "neither a ROS camera_info (camera_matrix) nor a Kalibr camchain (cam0, intrinsics)");
      }
    } catch (const YAML::Exception& error) {
      fail(path, std::string("a field is missing or of the wrong type: ") + error.what());
    }
  }
  check(path, model);
  model.path = path.string();
  return model;
}

std::vector<float> undistorted_pixel_centres(const CameraModel& model, SensorSize sensor) {
  const std::size_t pixels = static_cast<std::size_t>(sensor.width) * static_cast<std::size_t>(sensor.height);
  std::vector<cv::Point2d> distorted;
  distorted.reserve(pixels);
  for (int y = 0; y < sensor.height; ++y) {
    for (int x = 0; x < sensor.width; ++x) distorted.emplace_back(x, y);  // OpenCV: a pixel's centre at its index
  }
  std::vector<cv::Point2d> rectified;
  const cv::Matx33d k(model.fx, 0, model.cx, 0, model.fy, model.cy, 0, 0, 1);
  switch (model.distortion) {
    case CameraModel::Distortion::None:
      rectified = distorted;
      break;
    case CameraModel::Distortion::RadialTangential:
      // The iterative inverse, run to convergence: the default 5 rounds leave tenths of a pixel at a
      // strong lens's corners.
      cv::undistortPoints(distorted, rectified, k, model.coefficients, cv::noArray(), k,
                          cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 100, 1e-9));
      break;
    case CameraModel::Distortion::Equidistant:
      cv::fisheye::undistortPoints(distorted, rectified, k, model.coefficients, cv::noArray(), k,
                                   cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 100, 1e-9));
      break;
  }
  std::vector<float> centres(2 * pixels);
  for (std::size_t i = 0; i < pixels; ++i) {
    centres[2 * i] = static_cast<float>(rectified[i].x + 0.5);  // evldt: a pixel's centre at index + 0.5
    centres[2 * i + 1] = static_cast<float>(rectified[i].y + 0.5);
  }
  return centres;
}

std::shared_ptr<const RectificationTable> rectification_table(const CameraModel& model, SensorSize sensor) {
  if (model.size.width > 0 && !(model.size == sensor)) {
    throw std::invalid_argument("the calibration is of a " + std::to_string(model.size.width) + "x" +
                                std::to_string(model.size.height) + " camera, the sensor " +
                                std::to_string(sensor.width) + "x" + std::to_string(sensor.height));
  }
  // Per rectified pixel, where its centre lies on the sensor (OpenCV's maps: a pixel's centre at its
  // index), and so the sensor pixel that sees it.
  const cv::Size size(sensor.width, sensor.height);
  const cv::Matx33d k(model.fx, 0, model.cx, 0, model.fy, model.cy, 0, 0, 1);
  cv::Mat map_x, map_y;
  switch (model.distortion) {
    case CameraModel::Distortion::None:
      cv::initUndistortRectifyMap(k, cv::noArray(), cv::noArray(), k, size, CV_32FC1, map_x, map_y);
      break;
    case CameraModel::Distortion::RadialTangential:
      cv::initUndistortRectifyMap(k, model.coefficients, cv::noArray(), k, size, CV_32FC1, map_x, map_y);
      break;
    case CameraModel::Distortion::Equidistant:
      cv::fisheye::initUndistortRectifyMap(k, model.coefficients, cv::Matx33d::eye(), k, size, CV_32FC1, map_x, map_y);
      break;
  }
  std::vector<std::int32_t> sources(static_cast<std::size_t>(sensor.width) * static_cast<std::size_t>(sensor.height),
                                    -1);
  for (int y = 0; y < sensor.height; ++y) {
    for (int x = 0; x < sensor.width; ++x) {
      const float sx = std::round(map_x.at<float>(y, x)), sy = std::round(map_y.at<float>(y, x));
      if (!(sx >= 0 && sy >= 0 && sx < static_cast<float>(sensor.width) && sy < static_cast<float>(sensor.height)))
        continue;
      sources[static_cast<std::size_t>(y) * static_cast<std::size_t>(sensor.width) + static_cast<std::size_t>(x)] =
          static_cast<std::int32_t>(sy) * sensor.width + static_cast<std::int32_t>(sx);
    }
  }
  auto table = std::make_shared<RectificationTable>(RectificationTable::from_sources(sensor, sources));
  table->lens = {model.fx,           model.fy,  model.cx, model.cy, distortion_name(model.distortion),
                 model.coefficients, model.path};
  return table;
}

}  // namespace evldt
