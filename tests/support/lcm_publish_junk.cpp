// Test helper: publishes payloads that are not valid evldt event batches on a channel, as foreign
// or broken publishers would. Usage: lcm_publish_junk URL CHANNEL COUNT
// Cycles through random bytes, an empty payload, a truncated valid batch and a batch with a forged
// event count.

#include <cstdio>
#include <cstdlib>
#include <lcm/lcm-cpp.hpp>
#include <random>
#include <vector>

#include "evldt/event_batch_t.hpp"

int main(int argc, char** argv) {
  if (argc != 4) {
    std::fprintf(stderr, "usage: %s URL CHANNEL COUNT\n", argv[0]);
    return 1;
  }
  lcm::LCM lcm(argv[1]);
  if (!lcm.good()) return 1;
  const int count = std::atoi(argv[3]);
  evldt::event_batch_t batch{};
  batch.width = 240;
  batch.height = 180;
  batch.num_events = 100;
  batch.dt_us.assign(100, 0);
  batch.x.assign(100, 1);
  batch.y.assign(100, 1);
  batch.polarity.assign(100, 1);
  std::vector<std::uint8_t> valid(static_cast<std::size_t>(batch.getEncodedSize()));
  batch.encode(valid.data(), 0, static_cast<int>(valid.size()));
  std::mt19937 random(7);
  for (int i = 0; i < count; ++i) {
    std::vector<std::uint8_t> payload;
    switch (i % 4) {
      case 0:
        payload.resize(200);
        for (auto& byte : payload) byte = static_cast<std::uint8_t>(random());
        break;
      case 1:
        break;  // empty
      case 2:
        payload.assign(valid.begin(), valid.begin() + static_cast<std::ptrdiff_t>(valid.size() / 2));
        break;
      case 3: {
        payload = valid;
        // num_events sits right before the event arrays: forge it to 2^31 - 1.
        const std::size_t count_at = valid.size() - 100 * 9 - 4;
        payload[count_at] = 0x7f;
        payload[count_at + 1] = payload[count_at + 2] = payload[count_at + 3] = 0xff;
        break;
      }
    }
    if (lcm.publish(argv[2], payload.data(), static_cast<unsigned>(payload.size())) != 0) return 1;
  }
  return 0;
}
