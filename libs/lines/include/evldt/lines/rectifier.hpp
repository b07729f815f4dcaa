#pragma once
// Events moved from sensor pixels into the rectified image of a calibrated camera, through a table
// made once per sensor (libs/calibration): after the noise filters, which work on sensor pixels, and
// before storage. An event whose pixel lands off the rectified image is dropped and counted.

#include <cstdint>
#include <string>
#include <vector>

#include "evldt/events/event.hpp"

namespace evldt {

/// The camera a table was made of, as consumers of the lines need it (CAMERA_INFO messages).
struct LensDescription {
  double fx = 0, fy = 0, cx = 0, cy = 0;  ///< of the rectified image, OpenCV's convention
  std::string distortion;                 ///< of the sensor: "none", "radtan", "equidistant"
  std::vector<double> coefficients;
  std::string calibration;                ///< the file it was read from
};

struct RectificationTable {
  static constexpr std::uint32_t kOff = 0xFFFFFFFFu;
  SensorSize sensor;
  LensDescription lens;
  /// Per sensor pixel (row-major): its rectified pixel as x | y << 16, or kOff.
  std::vector<std::uint32_t> target;
};

class Rectifier {
 public:
  explicit Rectifier(const RectificationTable& table) : table_(&table) {}
  /// `out` = the events of `in` at their rectified pixels, those off the image left out.
  void apply(const EventBatch& in, EventBatch& out) {
    out.clear();
    const std::uint32_t* target = table_->target.data();
    const auto width = static_cast<std::uint32_t>(table_->sensor.width);
    for (std::size_t i = 0; i < in.size(); ++i) {
      const std::uint32_t to = target[static_cast<std::uint32_t>(in.y[i]) * width + in.x[i]];
      if (to == RectificationTable::kOff) {
        ++dropped_;
        continue;
      }
      out.push_back(in.t[i], static_cast<std::uint16_t>(to & 0xFFFFu), static_cast<std::uint16_t>(to >> 16), in.p[i]);
    }
  }
  /// Events left out so far: their pixel lies off the rectified image.
  [[nodiscard]] std::uint64_t dropped() const { return dropped_; }

 private:
  const RectificationTable* table_;
  std::uint64_t dropped_ = 0;
};

}  // namespace evldt
