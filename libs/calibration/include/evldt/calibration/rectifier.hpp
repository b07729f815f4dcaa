#pragma once
// Events moved from sensor pixels into the rectified image of a calibrated camera, through a table
// made once per sensor (libs/calibration): after the noise filters, which work on sensor pixels, and
// before storage. An event whose pixel sees nothing of the rectified image is dropped and counted.

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
  std::string calibration;  ///< the file it was read from
};

struct RectificationTable {
  SensorSize sensor;
  LensDescription lens;
  /// The rectified pixels each sensor pixel's events go to (x | y << 16): those of sensor pixel i
  /// (row-major) are targets[first[i] .. first[i + 1]). Each rectified pixel is fed by the sensor
  /// pixel that sees its centre, so where a lens squeezes the image a sensor pixel feeds two or
  /// more, and none where it sees beyond the rectified image.
  std::vector<std::uint32_t> first, targets;

  /// The table of `sensor` from, per rectified pixel (row-major, the sensor's size), the index of
  /// the sensor pixel that sees it, or -1.
  static RectificationTable from_sources(SensorSize sensor, const std::vector<std::int32_t>& source_of_rectified) {
    RectificationTable table;
    table.sensor = sensor;
    const std::size_t pixels = static_cast<std::size_t>(sensor.width) * static_cast<std::size_t>(sensor.height);
    table.first.assign(pixels + 1, 0);
    for (const std::int32_t source : source_of_rectified) {
      if (source >= 0) ++table.first[static_cast<std::size_t>(source) + 1];
    }
    for (std::size_t i = 0; i < pixels; ++i) table.first[i + 1] += table.first[i];
    table.targets.resize(table.first[pixels]);
    std::vector<std::uint32_t> filled(table.first.begin(), table.first.end() - 1);
    for (std::size_t r = 0; r < source_of_rectified.size(); ++r) {
      const std::int32_t source = source_of_rectified[r];
      if (source < 0) continue;
      const auto x = static_cast<std::uint32_t>(r % static_cast<std::size_t>(sensor.width));
      const auto y = static_cast<std::uint32_t>(r / static_cast<std::size_t>(sensor.width));
      table.targets[filled[static_cast<std::size_t>(source)]++] = x | y << 16;
    }
    return table;
  }
};

class Rectifier {
 public:
  explicit Rectifier(const RectificationTable& table)
      : table_(&table),
        turn_(static_cast<std::size_t>(table.sensor.width) * static_cast<std::size_t>(table.sensor.height), 0) {}
  /// `out` = the events of `in` at rectified pixels, in order; those of a pixel that feeds none left
  /// out. A pixel that feeds several sends its events to each in turn: the rectified edge is held at
  /// every pixel, and no event is counted twice.
  void apply(const EventBatch& in, EventBatch& out) {
    const std::size_t n = in.size();
    out.truncate(n);  // room for every event: no allocation once as large
    // The columns as plain pointers: the byte stores (turns, polarities) may alias anything, and
    // through the vectors the compiler would reload their pointers at every event.
    const Timestamp* const in_t = in.t.data();
    const std::uint16_t *const in_x = in.x.data(), *const in_y = in.y.data();
    const std::int8_t* const in_p = in.p.data();
    Timestamp* const out_t = out.t.data();
    std::uint16_t *const out_x = out.x.data(), *const out_y = out.y.data();
    std::int8_t* const out_p = out.p.data();
    const std::uint32_t* const first = table_->first.data();
    const std::uint32_t* const targets = table_->targets.data();
    std::uint8_t* const turns = turn_.data();
    const auto width = static_cast<std::uint32_t>(table_->sensor.width);
    std::size_t kept = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const std::uint32_t pixel = static_cast<std::uint32_t>(in_y[i]) * width + in_x[i];
      const std::uint32_t begin = first[pixel], count = first[pixel + 1] - begin;
      if (count == 0) {
        ++dropped_;
        continue;
      }
      std::uint32_t k = begin;
      if (count > 1) {
        std::uint8_t& turn = turns[pixel];
        k += turn % count;
        turn = static_cast<std::uint8_t>(turn + 1);
      }
      out_t[kept] = in_t[i];
      out_x[kept] = static_cast<std::uint16_t>(targets[k] & 0xFFFFu);
      out_y[kept] = static_cast<std::uint16_t>(targets[k] >> 16);
      out_p[kept] = in_p[i];
      ++kept;
    }
    out.truncate(kept);
  }
  /// Events left out so far: their pixel feeds no rectified pixel.
  [[nodiscard]] std::uint64_t dropped() const { return dropped_; }

 private:
  const RectificationTable* table_;
  std::vector<std::uint8_t> turn_;  ///< per sensor pixel that feeds several: which of them is next
  std::uint64_t dropped_ = 0;
};

}  // namespace evldt
