// Test helper: a subscriber on a far host, as a robot's consumer of evldt would be. Prints "ready"
// once subscribed, then one line per message it hears, for the service tests to check and wait on:
//   list RECV_WALL_US EPOCH SEQ T_US NEWEST_BATCH_SEQ NUM_SEGMENTS ID...
//   stats RECV_WALL_US SERVICE EPOCH BATCHES_RECEIVED BATCHES_LOST INVALID_MESSAGES WORDS_SKIPPED BATCHES_SHED
//   invalid RECV_WALL_US CHANNEL
// Usage: lcm_lines_probe URL CAMERA SECONDS   (it stops after SECONDS, or at SIGTERM)

#include <cinttypes>
#include <cstdio>
#include <cstdlib>
#include <lcm/lcm-cpp.hpp>
#include <string>

#include "evldt/transport/channels.hpp"
#include "evldt/transport/messages.hpp"

namespace {

std::span<const std::uint8_t> payload_of(const lcm::ReceiveBuffer* buffer) {
  return {static_cast<const std::uint8_t*>(buffer->data), buffer->data_size};
}

struct Probe {
  void on_list(const lcm::ReceiveBuffer* buffer, const std::string& channel) {
    evldt::segment_list_t list;
    if (evldt::decode_message(payload_of(buffer), list) != evldt::WireError::None) return invalid(channel);
    std::printf("list %" PRId64 " %" PRId64 " %" PRId64 " %" PRId64 " %" PRId64 " %d", evldt::wall_clock_us(),
                list.epoch, list.seq, list.t_us, list.newest_batch_seq, list.num_segments);
    for (const auto& segment : list.segments) std::printf(" %" PRId64, segment.id);
    std::printf("\n");
  }
  void on_stats(const lcm::ReceiveBuffer* buffer, const std::string& channel) {
    evldt::stats_t stats;
    if (evldt::decode_message(payload_of(buffer), stats) != evldt::WireError::None) return invalid(channel);
    std::printf("stats %" PRId64 " %s %" PRId64 " %" PRId64 " %" PRId64 " %" PRId64 " %" PRId64 " %" PRId64 "\n",
                evldt::wall_clock_us(), stats.service.c_str(), stats.epoch, stats.batches_received, stats.batches_lost,
                stats.invalid_messages, stats.words_skipped, stats.batches_shed);
  }
  static void invalid(const std::string& channel) {
    std::printf("invalid %" PRId64 " %s\n", evldt::wall_clock_us(), channel.c_str());
  }
};

}  // namespace

int main(int argc, char** argv) {
  if (argc != 4) {
    std::fprintf(stderr, "usage: %s URL CAMERA SECONDS\n", argv[0]);
    return 1;
  }
  lcm::LCM lcm(argv[1]);
  if (!lcm.good()) return 1;
  Probe probe;
  lcm.subscribe(evldt::lines_channel(argv[2]), &Probe::on_list, &probe);
  lcm.subscribe(std::string(evldt::kStatsChannel), &Probe::on_stats, &probe);
  std::printf("ready\n");
  std::fflush(stdout);
  const std::int64_t end = evldt::wall_clock_us() + static_cast<std::int64_t>(std::atof(argv[3]) * 1e6);
  while (evldt::wall_clock_us() < end) {
    if (lcm.handleTimeout(50) < 0) return 1;
    std::fflush(stdout);
  }
  return 0;
}
