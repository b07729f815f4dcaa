// Test helper: cAER / libcaer's AEDAT 3.1 network output imitated from a recording: its events as
// polarity packets of 500 (iniVation's AEDAT 3.1 description) after libcaer's 20-byte network
// header (network.h), sent to the first client of a loopback port of its own, whose number is
// written to PORT_FILE; then it exits.
// Usage: aedat31_stream_server FILE PORT_FILE

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "evldt/events/event_stream_reader.hpp"

namespace {

void append_le(std::vector<std::uint8_t>& bytes, std::uint64_t value, int size) {
  for (int i = 0; i < size; ++i) bytes.push_back(static_cast<std::uint8_t>(value >> (8 * i)));
}

void append_packet(std::vector<std::uint8_t>& bytes, const evldt::EventBatch& events, std::size_t begin, std::size_t end) {
  const auto count = static_cast<std::uint32_t>(end - begin);
  const auto overflow = static_cast<std::uint32_t>(events.t[begin] >> 31);
  append_le(bytes, 1, 2);  // polarity events
  append_le(bytes, 1, 2);  // source id
  for (const std::uint32_t field : {8u, 4u, overflow, count, count, count}) append_le(bytes, field, 4);
  for (std::size_t i = begin; i < end; ++i) {
    append_le(bytes, std::uint64_t{events.x[i]} << 17 | std::uint64_t{events.y[i]} << 2 | (events.p[i] > 0 ? 2u : 0u) | 1u, 4);
    append_le(bytes, static_cast<std::uint64_t>(events.t[i]) & 0x7FFFFFFFu, 4);
  }
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: aedat31_stream_server FILE PORT_FILE\n");
    return 1;
  }
  std::vector<std::uint8_t> stream;
  append_le(stream, 0x1D378BC90B9A6658, 8);  // magic number
  append_le(stream, 0, 8);                   // sequence number
  stream.push_back(1);                       // version
  stream.push_back(0);                       // format
  append_le(stream, 1, 2);                   // source id
  evldt::EventStreamReader reader(argv[1]);
  evldt::EventBatch events;
  while (reader.read(events)) {
    for (std::size_t begin = 0; begin < events.size();) {
      // A packet never spans a change of the time's high bits (its overflow field holds them).
      std::size_t end = begin;
      while (end < events.size() && end - begin < 500 && (events.t[end] >> 31) == (events.t[begin] >> 31)) ++end;
      append_packet(stream, events, begin, end);
      begin = end;
    }
  }
  const int listener = socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  socklen_t size = sizeof address;
  if (bind(listener, reinterpret_cast<sockaddr*>(&address), sizeof address) != 0 || listen(listener, 1) != 0 ||
      getsockname(listener, reinterpret_cast<sockaddr*>(&address), &size) != 0) {
    return 1;
  }
  const std::string port_file = argv[2];
  std::ofstream(port_file + ".tmp") << ntohs(address.sin_port);
  std::filesystem::rename(port_file + ".tmp", port_file);
  const int client = accept(listener, nullptr, nullptr);
  if (client < 0) return 1;
  for (std::size_t at = 0; at < stream.size();) {
    const ssize_t sent = send(client, stream.data() + at, std::min<std::size_t>(stream.size() - at, 4096), MSG_NOSIGNAL);
    if (sent <= 0) return 1;
    at += static_cast<std::size_t>(sent);
  }
  close(client);
  close(listener);
  return 0;
}
