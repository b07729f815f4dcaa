#pragma once
// One message into an lcm-log file, for tests that build a recording by hand.

#include <gtest/gtest.h>

#include <cstdint>
#include <lcm/lcm-cpp.hpp>
#include <span>
#include <string>

namespace evldt::test_support {

/// Writes `bytes` on `channel` with the log time `t_us`; a failed write fails the test.
inline void write_log_event(lcm::LogFile& log, std::int64_t t_us, const std::string& channel,
                            std::span<const std::uint8_t> bytes) {
  lcm::LogEvent event{};
  event.timestamp = t_us;
  event.channel = channel;
  event.datalen = static_cast<std::int32_t>(bytes.size());
  event.data = const_cast<std::uint8_t*>(bytes.data());  // LogFile only reads it
  ASSERT_EQ(log.writeEvent(&event), 0);
}

}  // namespace evldt::test_support
