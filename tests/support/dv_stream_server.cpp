// Test helper: DV's AEDAT 4.0 network output imitated from a recording: to each client, in the order
// they connect, the file's IOHeader and its packets (no version line, no data table), as
// dv-runtime's net-tcp-server sends them. Listens on a loopback port of its own and writes its
// number to PORT_FILE; serves CLIENTS clients (the first one half the packets, then closes, when
// "split" is given, the next the header again and the rest), then exits.
// Usage: dv_stream_server FILE.aedat4 PORT_FILE [split]

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "aedat4_header_generated.h"

namespace {

std::uint32_t load_le32(const std::uint8_t* p) {
  return static_cast<std::uint32_t>(p[0]) | static_cast<std::uint32_t>(p[1]) << 8 | static_cast<std::uint32_t>(p[2]) << 16 |
         static_cast<std::uint32_t>(p[3]) << 24;
}

bool send_all(int fd, const std::uint8_t* data, std::size_t size) {
  while (size > 0) {
    const ssize_t sent = send(fd, data, size, MSG_NOSIGNAL);
    if (sent <= 0) return false;
    data += sent;
    size -= static_cast<std::size_t>(sent);
  }
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3 || argc > 4) {
    std::fprintf(stderr, "usage: dv_stream_server FILE.aedat4 PORT_FILE [split]\n");
    return 1;
  }
  std::ifstream in(argv[1], std::ios::binary);
  const std::vector<std::uint8_t> bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  const std::size_t at = std::string_view("#!AER-DAT4.0\r\n").size();
  if (bytes.size() < at + 4) return 1;
  const std::uint32_t header_size = load_le32(bytes.data() + at);
  const std::vector<std::uint8_t> header(bytes.begin() + static_cast<std::ptrdiff_t>(at),
                                         bytes.begin() + static_cast<std::ptrdiff_t>(at + 4 + header_size));
  const auto* io = evldt::aedat4::GetSizePrefixedIOHeader(header.data());
  const std::size_t end = io->dataTablePosition() >= 0 ? static_cast<std::size_t>(io->dataTablePosition()) : bytes.size();
  std::vector<std::pair<std::size_t, std::size_t>> packets;
  for (std::size_t packet = at + 4 + header_size; packet + 8 <= end;) {
    const std::size_t length = 8 + load_le32(bytes.data() + packet + 4);
    packets.emplace_back(packet, length);
    packet += length;
  }
  const bool split = argc == 4 && std::string(argv[3]) == "split";
  std::vector<std::pair<std::size_t, std::size_t>> connections;  // packet ranges, one per client
  if (split) {
    connections = {{0, packets.size() / 2}, {packets.size() / 2, packets.size()}};
  } else {
    connections = {{0, packets.size()}};
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
  for (const auto& [first, last] : connections) {
    const int client = accept(listener, nullptr, nullptr);
    if (client < 0) return 1;
    bool open = send_all(client, header.data(), header.size());
    for (std::size_t i = first; open && i < last; ++i) open = send_all(client, bytes.data() + packets[i].first, packets[i].second);
    close(client);
  }
  close(listener);
  return 0;
}
