// Test helper: how many messages a (possibly still growing) lcm-log holds on one channel, so that a
// test can wait until a logger has recorded a whole stream instead of sleeping. A record cut short
// at the end of a file being written is not counted.
// Usage: lcm_log_count FILE CHANNEL

#include <cstdio>
#include <lcm/lcm-cpp.hpp>
#include <string>

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: %s FILE CHANNEL\n", argv[0]);
    return 1;
  }
  lcm::LogFile log(argv[1], "r");
  if (!log.good()) {
    std::printf("0\n");  // not created yet
    return 0;
  }
  const std::string channel = argv[2];
  long count = 0;
  while (const lcm::LogEvent* event = log.readNextEvent()) count += event->channel == channel ? 1 : 0;
  std::printf("%ld\n", count);
  return 0;
}
