#pragma once
// Bytes from a camera while it records: a file its recorder is still writing, standard
// input (`any_driver | evldt-camera -`) and a TCP stream. Each waits for bytes without using the CPU
// (poll, inotify) and gives up waiting when `stop` is set (checked every 100 ms), which ends the
// stream as its end of file would.

#include <atomic>
#include <chrono>
#include <filesystem>
#include <string>

#include "evldt/events/byte_source.hpp"

namespace evldt {

/// An open descriptor: a pipe, a FIFO, a socket. Ends at its end of file (the writer closed it).
class DescriptorBytes : public ByteSource {
 public:
  /// Takes `fd` (closed by the destructor when `owned`); `name` is for messages.
  DescriptorBytes(int fd, std::string name, const std::atomic<bool>& stop, bool owned);
  ~DescriptorBytes() override;
  DescriptorBytes(const DescriptorBytes&) = delete;
  DescriptorBytes& operator=(const DescriptorBytes&) = delete;
  std::size_t read(std::span<std::uint8_t> into) override;

 protected:
  [[nodiscard]] int fd() const { return fd_; }

 private:
  int fd_;
  const std::atomic<bool>& stop_;
  bool owned_;
};

/// Standard input.
class StdinBytes final : public DescriptorBytes {
 public:
  explicit StdinBytes(const std::atomic<bool>& stop);
};

/// "tcp://HOST:PORT" -> host and port; throws std::invalid_argument naming the text otherwise.
struct TcpAddress {
  std::string host;
  std::string port;
  static TcpAddress parse(const std::string& url);
};

/// A TCP stream a server sends (connected at construction: std::runtime_error naming the address if
/// it cannot be). Ends when the server closes the connection.
class TcpBytes final : public DescriptorBytes {
 public:
  TcpBytes(const TcpAddress& address, const std::atomic<bool>& stop);
  /// Acknowledges what it read at once (TCP_QUICKACK): a sender whose small writes wait for the
  /// acknowledgement of the last (Nagle's algorithm) is otherwise held 40 ms by a delayed one
  /// (measured: p99 40 ms from sensor to publish at 0.8 Mev/s in 2 KiB writes, 3 ms with it).
  std::size_t read(std::span<std::uint8_t> into) override;
};

/// A Unix stream socket a server listens on (DV's net-socket-server): "unix:///run/dv.sock" ->
/// the path; connected at construction (std::runtime_error naming it if it cannot be). Ends when the
/// server closes the connection.
class UnixSocketBytes final : public DescriptorBytes {
 public:
  UnixSocketBytes(const std::string& path, const std::atomic<bool>& stop);
};

/// A file that a recorder may still be writing: reads what is there, then waits for more (inotify)
/// and ends once it has not grown for `idle` (or on stop). A file that shrinks or is replaced (a new
/// file under the name) is an error: std::runtime_error, naming it.
class FollowedFileBytes final : public ByteSource {
 public:
  FollowedFileBytes(const std::filesystem::path& path, std::chrono::duration<double> idle,
                    const std::atomic<bool>& stop);
  ~FollowedFileBytes() override;
  FollowedFileBytes(const FollowedFileBytes&) = delete;
  FollowedFileBytes& operator=(const FollowedFileBytes&) = delete;
  std::size_t read(std::span<std::uint8_t> into) override;

 private:
  /// Throws if the file under the name is no longer the one read, or is shorter than what was read.
  void check_still_the_file() const;

  std::filesystem::path path_;
  int fd_ = -1;
  int watch_fd_ = -1;  // inotify: wakes the wait when the file is written
  std::chrono::duration<double> idle_;
  const std::atomic<bool>& stop_;
  std::uint64_t offset_ = 0;
  unsigned long long device_ = 0, inode_ = 0;
};

}  // namespace evldt
