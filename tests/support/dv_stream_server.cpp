// Test helper: DV's AEDAT 4.0 network output imitated from a recording: to each client, in the order
// they connect, the file's IOHeader and its packets (no version line, no data table), as
// dv-runtime's net-tcp-server sends them. Listens on a loopback port of its own and writes its
// number to PORT_FILE; serves one client the whole recording, or with "split" two: the first half
// the packets (then it closes), the next the header again and the rest; then it exits.
// Usage: dv_stream_server FILE.aedat4 PORT_FILE [split]

#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include "support/dv_framing.hpp"
#include "support/loopback_server.hpp"

int main(int argc, char** argv) {
  using namespace evldt::test_support;
  if (argc < 3 || argc > 4) {
    std::fprintf(stderr, "usage: dv_stream_server FILE.aedat4 PORT_FILE [split]\n");
    return 1;
  }
  const DvFraming file(argv[1]);
  const bool split = argc == 4 && std::string(argv[3]) == "split";
  std::vector<std::vector<std::uint8_t>> connections;
  if (split) {
    connections = {file.stream(0, file.packets() / 2), file.stream(file.packets() / 2, file.packets())};
  } else {
    connections = {file.stream(0, file.packets())};
  }
  const LoopbackListener listener = listen_on_loopback();
  if (listener.fd < 0) return 1;
  write_port_file(listener.port, argv[2]);
  for (const auto& bytes : connections) {
    const int client = accept(listener.fd, nullptr, nullptr);
    if (client < 0) return 1;
    send_all(client, bytes.data(), bytes.size());
    close(client);
  }
  close(listener.fd);
  return 0;
}
