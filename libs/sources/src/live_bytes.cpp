#include "evldt/sources/live_bytes.hpp"

#include <fcntl.h>
#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/inotify.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>
#include <cerrno>
#include <cstring>
#include <stdexcept>

namespace evldt {
namespace {

constexpr int kStopCheckMs = 100;

std::runtime_error system_error(const std::string& what) {
  return std::runtime_error(what + ": " + std::strerror(errno));
}

/// Waits until `fd` is readable (true) or `stop` is set (false), without using the CPU.
bool wait_readable(int fd, const std::atomic<bool>& stop) {
  while (!stop.load(std::memory_order_relaxed)) {
    pollfd polled{fd, POLLIN, 0};
    const int ready = poll(&polled, 1, kStopCheckMs);
    if (ready > 0) return true;  // readable, or hung up / in error: read() tells which
    if (ready < 0 && errno != EINTR) throw system_error("poll");
  }
  return false;
}

}  // namespace

DescriptorBytes::DescriptorBytes(int fd, std::string name, const std::atomic<bool>& stop, bool owned)
    : fd_(fd), stop_(stop), owned_(owned) {
  name_ = std::move(name);
}

DescriptorBytes::~DescriptorBytes() {
  if (owned_) close(fd_);
}

std::size_t DescriptorBytes::read(std::span<std::uint8_t> into) {
  for (;;) {
    if (!wait_readable(fd_, stop_)) return 0;
    const ssize_t got = ::read(fd_, into.data(), into.size());
    if (got >= 0) return static_cast<std::size_t>(got);
    if (errno != EINTR && errno != EAGAIN) throw system_error("cannot read " + name_);
  }
}

StdinBytes::StdinBytes(const std::atomic<bool>& stop) : DescriptorBytes(STDIN_FILENO, "standard input", stop, false) {}

TcpAddress TcpAddress::parse(const std::string& url) {
  constexpr std::string_view kScheme = "tcp://";
  const std::string rest = url.starts_with(kScheme) ? url.substr(kScheme.size()) : std::string();
  const auto colon = rest.rfind(':');
  if (colon == std::string::npos || colon == 0 || colon + 1 == rest.size()) {
    throw std::invalid_argument("'" + url + "' is not tcp://HOST:PORT");
  }
  TcpAddress address{rest.substr(0, colon), rest.substr(colon + 1)};
  if (address.host.size() > 2 && address.host.front() == '[' && address.host.back() == ']') {
    address.host = address.host.substr(1, address.host.size() - 2);  // [IPv6]
  }
  return address;
}

namespace {

int connect_tcp(const TcpAddress& address) {
  const std::string name = "tcp://" + address.host + ":" + address.port;
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  addrinfo* found = nullptr;
  if (const int error = getaddrinfo(address.host.c_str(), address.port.c_str(), &hints, &found); error != 0) {
    throw std::runtime_error("cannot resolve " + name + ": " + gai_strerror(error));
  }
  int fd = -1;
  std::string failure = "no address";
  for (const addrinfo* candidate = found; candidate != nullptr; candidate = candidate->ai_next) {
    fd = socket(candidate->ai_family, candidate->ai_socktype | SOCK_CLOEXEC, candidate->ai_protocol);
    if (fd < 0) continue;
    if (connect(fd, candidate->ai_addr, candidate->ai_addrlen) == 0) break;
    failure = std::strerror(errno);
    close(fd);
    fd = -1;
  }
  freeaddrinfo(found);
  if (fd < 0) throw std::runtime_error("cannot connect to " + name + ": " + failure);
  return fd;
}

}  // namespace

TcpBytes::TcpBytes(const TcpAddress& address, const std::atomic<bool>& stop)
    : DescriptorBytes(connect_tcp(address), "tcp://" + address.host + ":" + address.port, stop, true) {}

std::size_t TcpBytes::read(std::span<std::uint8_t> into) {
  const std::size_t got = DescriptorBytes::read(into);
  const int on = 1;
  setsockopt(fd(), IPPROTO_TCP, TCP_QUICKACK, &on, sizeof on);  // not sticky: again after every read
  return got;
}

namespace {

int connect_unix(const std::string& path) {
  sockaddr_un address{};
  address.sun_family = AF_UNIX;
  if (path.empty() || path.size() >= sizeof address.sun_path)
    throw std::runtime_error("'" + path + "' is not a Unix socket path");
  path.copy(address.sun_path, path.size());
  const int fd = socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (fd < 0) throw system_error("socket");
  if (connect(fd, reinterpret_cast<const sockaddr*>(&address), sizeof address) != 0) {
    const std::runtime_error error = system_error("cannot connect to unix://" + path);
    close(fd);
    throw error;
  }
  return fd;
}

}  // namespace

UnixSocketBytes::UnixSocketBytes(const std::string& path, const std::atomic<bool>& stop)
    : DescriptorBytes(connect_unix(path), "unix://" + path, stop, true) {}

FollowedFileBytes::FollowedFileBytes(const std::filesystem::path& path, std::chrono::duration<double> idle,
                                     const std::atomic<bool>& stop)
    : path_(path), idle_(idle), stop_(stop) {
  name_ = path.string();
  fd_ = open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd_ < 0) throw system_error("cannot open event file '" + name_ + "'");
  struct stat info {};
  if (fstat(fd_, &info) != 0) {
    const std::runtime_error error = system_error("cannot stat '" + name_ + "'");
    close(fd_);  // the destructor does not run for a constructor that throws
    throw error;
  }
  device_ = info.st_dev;
  inode_ = info.st_ino;
  watch_fd_ = inotify_init1(IN_NONBLOCK | IN_CLOEXEC);
  if (watch_fd_ < 0 ||
      inotify_add_watch(watch_fd_, path.c_str(), IN_MODIFY | IN_ATTRIB | IN_MOVE_SELF | IN_DELETE_SELF) < 0) {
    // Without inotify (limits reached) the wait below still ends every 100 ms: slower, never wrong.
    if (watch_fd_ >= 0) close(watch_fd_);
    watch_fd_ = -1;
  }
}

FollowedFileBytes::~FollowedFileBytes() {
  close(fd_);
  if (watch_fd_ >= 0) close(watch_fd_);
}

void FollowedFileBytes::check_still_the_file() const {
  struct stat info {};
  if (stat(path_.c_str(), &info) != 0 || info.st_dev != device_ || info.st_ino != inode_) {
    throw std::runtime_error("'" + name_ + "' was removed or replaced while it was followed (" +
                             std::to_string(offset_) + " bytes read)");
  }
  if (static_cast<std::uint64_t>(info.st_size) < offset_) {
    throw std::runtime_error("'" + name_ + "' shrank to " + std::to_string(info.st_size) +
                             " bytes while it was followed (" + std::to_string(offset_) + " bytes read)");
  }
}

std::size_t FollowedFileBytes::read(std::span<std::uint8_t> into) {
  auto last_growth = std::chrono::steady_clock::now();
  for (;;) {
    const ssize_t got = ::read(fd_, into.data(), into.size());
    if (got < 0 && errno != EINTR) throw system_error("cannot read '" + name_ + "'");
    if (got > 0) {
      offset_ += static_cast<std::uint64_t>(got);
      return static_cast<std::size_t>(got);
    }
    // At the end of what is written so far: wait for the recorder to write more.
    check_still_the_file();
    if (stop_.load(std::memory_order_relaxed) || std::chrono::steady_clock::now() - last_growth >= idle_) return 0;
    if (watch_fd_ >= 0) {
      pollfd polled{watch_fd_, POLLIN, 0};
      if (poll(&polled, 1, kStopCheckMs) > 0) {
        alignas(inotify_event) char drained[4096];
        while (::read(watch_fd_, drained, sizeof drained) > 0) {
        }
      }
    } else {
      usleep(kStopCheckMs * 1000);
    }
    struct stat info {};
    if (fstat(fd_, &info) == 0 && static_cast<std::uint64_t>(info.st_size) > offset_)
      last_growth = std::chrono::steady_clock::now();
  }
}

}  // namespace evldt
