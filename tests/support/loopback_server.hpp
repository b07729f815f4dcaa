#pragma once
// For the test servers imitating camera software on this host: a TCP listener on a loopback port
// of its own, its number handed to a test script through a file, and sending a whole buffer.

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

namespace evldt::test_support {

struct LoopbackListener {
  int fd = -1;  ///< -1 if it could not listen
  int port = 0;
};

/// Listens on 127.0.0.1 on a port the kernel chooses.
inline LoopbackListener listen_on_loopback() {
  LoopbackListener listener{socket(AF_INET, SOCK_STREAM, 0), 0};
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  socklen_t size = sizeof address;
  if (listener.fd < 0 || bind(listener.fd, reinterpret_cast<sockaddr*>(&address), sizeof address) != 0 ||
      listen(listener.fd, 1) != 0 || getsockname(listener.fd, reinterpret_cast<sockaddr*>(&address), &size) != 0) {
    if (listener.fd >= 0) close(listener.fd);
    return {};
  }
  listener.port = ntohs(address.sin_port);
  return listener;
}

/// Writes the port number to `path` at once (renamed into place), so a script waiting for the
/// file never reads half of it.
inline void write_port_file(int port, const std::string& path) {
  std::ofstream(path + ".tmp") << port;
  std::filesystem::rename(path + ".tmp", path);
}

/// Sends all of `data`; false if the peer went away.
inline bool send_all(int fd, const std::uint8_t* data, std::size_t size) {
  while (size > 0) {
    const ssize_t sent = send(fd, data, size, MSG_NOSIGNAL);
    if (sent <= 0) return false;
    data += sent;
    size -= static_cast<std::size_t>(sent);
  }
  return true;
}

}  // namespace evldt::test_support
