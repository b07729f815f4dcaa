#pragma once
// The APS frames of iniVation's and jAER's older recordings, beside their events:
//   AEDAT 3.1 (cAER): frame packets (type 2). A frame event is uint32 info ([0] valid, [3:1] colour
//     channels), int32 start / end of frame, start / end of exposure (31 bits, with the packet's
//     overflow as the events' times), int32 lengthX, lengthY, positionX, positionY, then lengthX x
//     lengthY x channels little-endian uint16 pixels (normalised to 16 bits, rows from the top) in
//     an event of the packet's event size. Its time is the middle of its exposure (as libcaer's).
//   AEDAT 2.0 (jAER, DAVIS): APS samples among the events, address [31] set, [30:22] y, [21:12] x
//     (both mirrored, as the events'), [11:10] the read (0 reset, 1 signal; 2 and 3, colour pixels'
//     resets and IMU samples, are skipped), [9:0] the 10-bit ADC value. A frame is reset - signal
//     of every pixel, complete once each pixel has both; its time is halfway between its last reset
//     read and its first signal read (the exposure of a global shutter). A frame a recording cut
//     into (started before it, or a next frame begun first) is skipped and counted.

#include <filesystem>
#include <memory>
#include <string_view>

#include "evldt/containers/image_source.hpp"

namespace evldt {

inline constexpr std::string_view kAedat31Magic = "#!AER-DAT3";
inline constexpr std::string_view kAedat2Magic = "#!AER-DAT2";

/// Throws std::runtime_error naming the file for one that is not AEDAT 3.x.
std::unique_ptr<ImageSource> open_aedat31_images(const std::filesystem::path& path);
/// Throws std::runtime_error naming the file for one that is not AEDAT 2.0, or whose chip has no APS
/// (a DVS128).
std::unique_ptr<ImageSource> open_aedat2_images(const std::filesystem::path& path);

}  // namespace evldt
