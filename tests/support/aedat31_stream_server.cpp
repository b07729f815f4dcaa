// Test helper: cAER / libcaer's AEDAT 3.1 network output imitated from a recording (its events in
// that framing: support/aedat31_network.hpp), sent to the first client of a loopback port of its
// own, whose number is written to PORT_FILE; then it exits.
// Usage: aedat31_stream_server FILE PORT_FILE

#include <cstdio>
#include <vector>

#include "evldt/events/event_stream_reader.hpp"
#include "support/aedat31_network.hpp"
#include "support/loopback_server.hpp"

int main(int argc, char** argv) {
  using namespace evldt::test_support;
  if (argc != 3) {
    std::fprintf(stderr, "usage: aedat31_stream_server FILE PORT_FILE\n");
    return 1;
  }
  std::vector<evldt::Event> events;
  evldt::EventStreamReader reader(argv[1]);
  evldt::EventBatch batch;
  while (reader.read(batch)) {
    for (std::size_t i = 0; i < batch.size(); ++i) events.push_back(batch[i]);
  }
  const std::vector<std::uint8_t> stream = aedat31_network_stream(events);
  const LoopbackListener listener = listen_on_loopback();
  if (listener.fd < 0) return 1;
  write_port_file(listener.port, argv[2]);
  const int client = accept(listener.fd, nullptr, nullptr);
  if (client < 0 || !send_all(client, stream.data(), stream.size())) return 1;
  close(client);
  close(listener.fd);
  return 0;
}
