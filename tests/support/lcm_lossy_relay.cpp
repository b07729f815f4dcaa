// Test helper: a lossy link. Forwards every message from one channel to another unchanged, except
// one in every DROP_EVERY, which it drops (the datagram loss tc netem would make, where the kernel
// has no netem): the middle one of each DROP_EVERY, so that a stream of whole cycles does not end
// on a loss, which no sequence gap could reveal. Prints "ready" once subscribed; stops once
// IDLE_SECONDS pass without a message after the first (so a slow run is relayed whole, as a fixed
// duration would not be; before the first it waits up to 10 minutes) and prints what it forwarded and dropped.
// Usage: lcm_lossy_relay URL FROM_CHANNEL TO_CHANNEL DROP_EVERY IDLE_SECONDS

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <lcm/lcm-cpp.hpp>
#include <string>

namespace {

struct Relay {
  lcm::LCM* lcm = nullptr;
  std::string to;
  long drop_every = 0;
  long seen = 0;
  long dropped = 0;
  std::chrono::steady_clock::time_point last_heard = std::chrono::steady_clock::now();
  void on_message(const lcm::ReceiveBuffer* buffer, const std::string&) {
    last_heard = std::chrono::steady_clock::now();
    if (++seen % drop_every == drop_every / 2) {
      ++dropped;
      return;
    }
    lcm->publish(to, buffer->data, buffer->data_size);
  }
};

}  // namespace

int main(int argc, char** argv) {
  if (argc != 6 || std::atol(argv[4]) < 1) {
    std::fprintf(stderr, "usage: %s URL FROM_CHANNEL TO_CHANNEL DROP_EVERY IDLE_SECONDS\n", argv[0]);
    return 1;
  }
  lcm::LCM lcm(argv[1]);
  if (!lcm.good()) return 1;
  Relay relay{&lcm, argv[3], std::atol(argv[4])};
  lcm::Subscription* subscription = lcm.subscribe(argv[2], &Relay::on_message, &relay);
  subscription->setQueueCapacity(10000);
  std::printf("ready\n");
  std::fflush(stdout);
  const auto idle_limit = std::chrono::duration<double>(std::atof(argv[5]));
  const auto first_message_limit = std::chrono::minutes(10);
  while (std::chrono::steady_clock::now() - relay.last_heard < (relay.seen > 0 ? idle_limit : first_message_limit)) {
    if (lcm.handleTimeout(50) < 0) return 1;
  }
  std::printf("relayed %ld dropped %ld\n", relay.seen - relay.dropped, relay.dropped);
  return 0;
}
