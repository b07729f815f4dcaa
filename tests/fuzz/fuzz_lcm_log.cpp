// Fuzz target for reading lcm-logger recordings (LcmLogEventReader for the events, read_segment_log
// for the segments), through LCM's LogFile API. Checks: only std::runtime_error escapes, events
// handed out are on the sensor, and segment rows are finite.

#include <cstdint>
#include <stdexcept>

#include "evldt/transport/lcm_log.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using evldt::fuzz::require;
  const evldt::fuzz::TempFile file({data, size}, ".lcm");
  try {
    evldt::LcmLogEventReader reader(file.path(), {}, 0);
    const evldt::SensorSize sensor = reader.sensor();
    evldt::EventBatch batch;
    while (reader.read(batch)) {
      for (std::size_t i = 0; i < batch.size(); ++i)
        require(sensor.contains(batch.x[i], batch.y[i]), "event off the sensor");
    }
  } catch (const std::runtime_error&) {
    // No valid event batch in the file: refused with a message.
  }
  try {
    for (const evldt::SegmentRow& row : evldt::read_segment_log(file.path())) {
      require(row.segment.q0.allFinite() && row.segment.q1.allFinite(), "a non-finite segment was read");
    }
  } catch (const std::runtime_error&) {
    // No valid segment list in the file.
  }
  return 0;
}
