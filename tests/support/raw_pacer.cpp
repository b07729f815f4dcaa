// Test helper: a camera driver's output imitated from a RAW (EVT 2.0/2.1/3.0) recording. Its bytes
// go out in pieces (PIECE_BYTES, default 16 KiB), each once the events it holds are due at SPEED x
// real time (0: at once), so a reader sees the stream as a live camera makes it: on standard output,
// to the first client of a TCP port (its number is written to PORT_FILE once it listens), or
// appended to a file.
// Usage: raw_pacer FILE SPEED stdout|tcp PORT_FILE|append OUT_FILE [PIECE_BYTES]

#include <unistd.h>

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "evldt/events/event_decoder.hpp"
#include "evldt/events/event_stream_reader.hpp"
#include "evldt/transport/pacer.hpp"
#include "support/loopback_server.hpp"

namespace {

bool write_all(int fd, const std::uint8_t* data, std::size_t size) {
  while (size > 0) {
    const ssize_t written = write(fd, data, size);
    if (written <= 0) return false;
    data += written;
    size -= static_cast<std::size_t>(written);
  }
  return true;
}

int open_output(const std::string& mode, const std::string& target) {
  if (mode == "stdout") return STDOUT_FILENO;
  if (mode == "append") {
    std::FILE* file = std::fopen(target.c_str(), "ab");
    return file ? fileno(file) : -1;
  }
  if (mode != "tcp") return -1;
  const evldt::test_support::LoopbackListener listener = evldt::test_support::listen_on_loopback();
  if (listener.fd < 0) return -1;
  evldt::test_support::write_port_file(listener.port, target);
  return accept(listener.fd, nullptr, nullptr);
}

}  // namespace

int main(int argc, char** argv) {
  const std::vector<std::string> args(argv + 1, argv + argc);
  const std::size_t after_mode = args.size() >= 3 && args[2] == "stdout" ? 3 : 4;
  if (args.size() < after_mode || args.size() > after_mode + 1) {
    std::fprintf(stderr, "usage: raw_pacer FILE SPEED stdout|tcp PORT_FILE|append OUT_FILE [PIECE_BYTES]\n");
    return 1;
  }
  const std::size_t piece_bytes = args.size() > after_mode ? std::stoul(args[after_mode]) : 16 * 1024;
  std::ifstream in(argv[1], std::ios::binary);
  const std::vector<std::uint8_t> bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  const auto format = evldt::EventStreamReader(argv[1]).format();
  const int out = open_output(args[2], after_mode == 4 ? args[3] : "");
  if (out < 0) {
    std::fprintf(stderr, "raw_pacer: cannot open the output\n");
    return 1;
  }
  const auto decoder = evldt::make_decoder(format, argv[1]);
  evldt::Pacer pacer(std::atof(argv[2]));
  const std::atomic<bool> never{false};
  evldt::EventBatch events;
  for (std::size_t at = 0; at < bytes.size(); at += piece_bytes) {
    const std::size_t size = std::min(piece_bytes, bytes.size() - at);
    events.clear();
    decoder->decode(std::span(bytes).subspan(at, size), events);
    if (!events.empty()) pacer.wait_until(events.t.back(), never);
    if (!write_all(out, bytes.data() + at, size)) return 1;
  }
  close(out);
  return 0;
}
