#pragma once
// LCM channel names (upper case, one set per camera) and the wall clock messages are stamped with.

#include <cstdint>
#include <string>
#include <string_view>

namespace evldt {

inline constexpr std::string_view kStatsChannel = "EVLDT_STATS";
/// The default URL: multicast on this host only (ttl=0); ttl=1 reaches the robot's LAN.
inline constexpr std::string_view kDefaultLcmUrl = "udpm://239.255.76.67:7667?ttl=0";

/// Event batches a subscriber lets LCM queue for it (about 4 s at the default 1 kHz batch rate;
/// LCM's own default of 30 loses batches whenever the handler stalls for a few milliseconds).
inline constexpr int kEventQueueCapacity = 4096;

/// "front" -> "EVENTS_FRONT".
std::string events_channel(std::string_view camera);
/// "front" -> "LINES_FRONT".
std::string lines_channel(std::string_view camera);
/// "front" -> "WHOLE_LINES_FRONT": segment lists whose entries are whole lines (whole_lines.hpp).
std::string whole_lines_channel(std::string_view camera);
/// "front" -> "CAMERA_INFO_FRONT": the calibrated camera the lines are given in (camera_info_t).
std::string camera_info_channel(std::string_view camera);
/// Throws std::invalid_argument unless the camera name is 1-32 letters, digits or '_'.
void check_camera_name(std::string_view camera);

/// Microseconds since the Unix epoch (comparable across processes; across hosts only as far as
/// their clocks are synchronised).
std::int64_t wall_clock_us();

}  // namespace evldt
