// Live inputs: a recording followed while it is written, standard input's kind of pipe,
// and a TCP stream, each read in pieces of random size; the events must be exactly those of the
// finished file, waiting must cost no CPU, and a cut or a replaced file must say so.

#include <gtest/gtest.h>

#include <fcntl.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <fstream>
#include <random>
#include <thread>
#include <vector>

#include "evldt/events/event_stream_reader.hpp"
#include "evldt/events/event_writer.hpp"
#include "evldt/sim/event_simulator.hpp"
#include "evldt/sim/scenes.hpp"
#include "evldt/sources/event_source.hpp"
#include "evldt/sources/live_bytes.hpp"
#include "support/aedat31_network.hpp"
#include "support/dv_framing.hpp"
#include "support/loopback_server.hpp"
#include "support/temp_dir.hpp"

namespace evldt {
namespace {

using namespace std::chrono_literals;
using test_support::TempDir;

std::vector<std::uint8_t> file_bytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

/// Every event the reader gives; a FormatError ends them, its message in `error` (else it throws).
std::vector<Event> all_events(EventStreamReader& reader, std::string* error = nullptr) {
  std::vector<Event> events;
  EventBatch batch;
  try {
    while (reader.read(batch)) {
      for (std::size_t i = 0; i < batch.size(); ++i) events.push_back(batch[i]);
    }
  } catch (const FormatError& fault) {
    if (error == nullptr) throw;
    *error = fault.what();
  }
  return events;
}

/// A simulated EVT 3.0 recording (always there, unlike ../shared).
std::filesystem::path simulated_recording(const TempDir& dir) {
  const Scene scene = make_scene("boxes-6dof");
  EventSimulator simulator(scene, SimulatorConfig{});
  EventBatch events;
  simulator.run_until(300'000, events);
  const auto path = dir.file("boxes.raw");
  EventWriter writer(path, EventFormat::Evt3, scene.sensor);
  writer.write(events);
  writer.close();
  return path;
}

std::filesystem::path real_recording(const char* name) {
  return std::filesystem::path(EVLDT_SHARED_DIR) / "real" / name;
}

/// Sizes of random pieces (1 byte to 20 KiB), so pieces end inside words and headers.
std::vector<std::size_t> random_pieces(std::size_t total, unsigned seed) {
  std::mt19937 random(seed);
  std::vector<std::size_t> pieces;
  for (std::size_t done = 0; done < total;) {
    const std::size_t size = std::min(total - done, random() % 4 == 0 ? 1 + random() % 16 : 1 + random() % 20'000);
    pieces.push_back(size);
    done += size;
  }
  return pieces;
}

double thread_cpu_seconds() {
  rusage usage{};
  getrusage(RUSAGE_THREAD, &usage);
  return static_cast<double>(usage.ru_utime.tv_sec + usage.ru_stime.tv_sec) +
         static_cast<double>(usage.ru_utime.tv_usec + usage.ru_stime.tv_usec) * 1e-6;
}

void expect_followed_like_finished(const std::filesystem::path& recording) {
  const std::vector<Event> expected = [&] {
    EventStreamReader finished(recording);
    return all_events(finished);
  }();
  ASSERT_FALSE(expected.empty());
  const std::vector<std::uint8_t> bytes = file_bytes(recording);
  TempDir dir;
  const auto growing = dir.file("growing.raw");
  std::ofstream(growing, std::ios::binary).close();
  std::thread recorder([&] {
    std::ofstream out(growing, std::ios::binary | std::ios::app);
    std::size_t at = 0;
    for (const std::size_t piece : random_pieces(bytes.size(), 7)) {
      out.write(reinterpret_cast<const char*>(bytes.data() + at), static_cast<std::streamsize>(piece));
      out.flush();
      at += piece;
      if (at % 3 == 0) std::this_thread::sleep_for(2ms);
    }
  });
  const std::atomic<bool> never{false};
  EventStreamReader followed(std::make_unique<FollowedFileBytes>(growing, 0.5s, never), std::nullopt, ".raw");
  const std::vector<Event> got = all_events(followed);
  recorder.join();
  EXPECT_EQ(got.size(), expected.size());
  EXPECT_TRUE(got == expected);
}

TEST(FollowedFile, GivesTheEventsOfTheFinishedFileWhileItIsWrittenInRandomPieces) {
  TempDir dir;
  expect_followed_like_finished(simulated_recording(dir));
}

TEST(FollowedFile, GivesTheEventsOfARealRecordingWhileItIsWritten) {
  const auto recording = real_recording("gen41_evt3.raw");
  if (!std::filesystem::exists(recording)) GTEST_SKIP() << "no " << recording << " (../shared is absent)";
  expect_followed_like_finished(recording);
}

TEST(FollowedFile, WaitsWithoutCpuAndEndsAfterItsIdleTime) {
  TempDir dir;
  const auto path = dir.file("idle.raw");
  std::ofstream(path) << "partial";
  const std::atomic<bool> never{false};
  FollowedFileBytes bytes(path, 0.6s, never);
  std::vector<std::uint8_t> buffer(64);
  EXPECT_EQ(bytes.read(buffer), 7u);
  const double cpu_before = thread_cpu_seconds();
  const auto started = std::chrono::steady_clock::now();
  EXPECT_EQ(bytes.read(buffer), 0u);  // no growth for 0.6 s: the end
  const auto waited = std::chrono::steady_clock::now() - started;
  EXPECT_GE(waited, 0.6s);
  EXPECT_LT(waited, 2s);
  EXPECT_LT(thread_cpu_seconds() - cpu_before, 0.05) << "waiting must not spin";
}

TEST(FollowedFile, GrowthKeepsItWaitingAndStopEndsIt) {
  TempDir dir;
  const auto path = dir.file("slow.raw");
  std::ofstream(path).close();
  std::atomic<bool> stop{false};
  FollowedFileBytes bytes(path, 0.3s, stop);
  std::thread writer([&] {
    for (int i = 0; i < 4; ++i) {
      std::this_thread::sleep_for(200ms);  // each gap shorter than the idle time
      std::ofstream(path, std::ios::app) << 'x';
    }
    std::this_thread::sleep_for(100ms);
    stop = true;
  });
  std::vector<std::uint8_t> buffer(64);
  std::size_t total = 0;
  while (const std::size_t got = bytes.read(buffer)) total += got;
  writer.join();
  EXPECT_EQ(total, 4u);
}

TEST(FollowedFile, AFileThatShrinksOrIsReplacedIsAnError) {
  TempDir dir;
  const auto path = dir.file("recording.raw");
  std::ofstream(path) << "0123456789";
  const std::atomic<bool> never{false};
  {
    FollowedFileBytes bytes(path, 5s, never);
    std::vector<std::uint8_t> buffer(64);
    EXPECT_EQ(bytes.read(buffer), 10u);
    std::filesystem::resize_file(path, 4);
    try {
      (void)bytes.read(buffer);
      ADD_FAILURE() << "no error for a file that shrank";
    } catch (const std::runtime_error& error) {
      EXPECT_NE(std::string(error.what()).find("shrank"), std::string::npos) << error.what();
    }
  }
  {
    FollowedFileBytes bytes(path, 5s, never);
    std::vector<std::uint8_t> buffer(64);
    EXPECT_EQ(bytes.read(buffer), 4u);
    std::filesystem::remove(path);
    std::ofstream(path) << "a new recording";
    try {
      (void)bytes.read(buffer);
      ADD_FAILURE() << "no error for a replaced file";
    } catch (const std::runtime_error& error) {
      EXPECT_NE(std::string(error.what()).find("replaced"), std::string::npos) << error.what();
    }
  }
}

/// Writes `bytes` to `fd` in random pieces, then closes it.
void write_in_pieces(int fd, const std::vector<std::uint8_t>& bytes, unsigned seed) {
  std::size_t at = 0;
  for (const std::size_t piece : random_pieces(bytes.size(), seed)) {
    for (std::size_t sent = 0; sent < piece;) {
      const ssize_t n = write(fd, bytes.data() + at + sent, piece - sent);
      if (n <= 0) break;
      sent += static_cast<std::size_t>(n);
    }
    at += piece;
    if (at % 5 == 0) std::this_thread::sleep_for(1ms);
  }
  close(fd);
}

TEST(DescriptorBytes, APipeGivesTheEventsOfTheFileAndEndsWhenTheWriterCloses) {
  TempDir dir;
  const auto recording = simulated_recording(dir);
  EventStreamReader finished(recording);
  const std::vector<Event> expected = all_events(finished);
  int pipe_fds[2];
  ASSERT_EQ(pipe(pipe_fds), 0);
  std::thread writer(write_in_pieces, pipe_fds[1], file_bytes(recording), 3u);
  const std::atomic<bool> never{false};
  // The format from the header alone: a pipe has no name.
  EventStreamReader piped(std::make_unique<DescriptorBytes>(pipe_fds[0], "pipe", never, true), std::nullopt, "");
  EXPECT_EQ(piped.format(), EventFormat::Evt3);
  EXPECT_TRUE(all_events(piped) == expected);
  writer.join();
}

TEST(DescriptorBytes, WaitsWithoutCpuAndStopEndsTheWait) {
  int pipe_fds[2];
  ASSERT_EQ(pipe(pipe_fds), 0);
  std::atomic<bool> stop{false};
  DescriptorBytes bytes(pipe_fds[0], "pipe", stop, true);
  std::thread stopper([&] {
    std::this_thread::sleep_for(500ms);
    stop = true;
  });
  std::vector<std::uint8_t> buffer(64);
  const double cpu_before = thread_cpu_seconds();
  EXPECT_EQ(bytes.read(buffer), 0u);
  EXPECT_LT(thread_cpu_seconds() - cpu_before, 0.05) << "waiting must not spin";
  stopper.join();
  close(pipe_fds[1]);
}

/// A TCP server on a loopback port of its own; serve() sends bytes to the first client, then closes.
class TestServer {
 public:
  TestServer() : listener_(test_support::listen_on_loopback()) { EXPECT_GE(listener_.fd, 0); }
  ~TestServer() {
    if (thread_.joinable()) thread_.join();
    close(listener_.fd);
  }
  void serve(std::vector<std::uint8_t> bytes) { serve_each({std::move(bytes)}); }
  /// One stream to each client, in the order they connect.
  void serve_each(std::vector<std::vector<std::uint8_t>> streams) {
    thread_ = std::thread([this, streams = std::move(streams)] {
      for (const auto& bytes : streams) {
        const int client = accept(listener_.fd, nullptr, nullptr);
        if (client >= 0) write_in_pieces(client, bytes, 11u);
      }
    });
  }
  [[nodiscard]] std::string url() const { return "tcp://127.0.0.1:" + std::to_string(listener_.port); }

 private:
  test_support::LoopbackListener listener_;
  std::thread thread_;
};

TEST(TcpBytes, AStreamInRandomPiecesGivesTheEventsOfTheFile) {
  TempDir dir;
  const auto recording = simulated_recording(dir);
  EventStreamReader finished(recording);
  const std::vector<Event> expected = all_events(finished);
  TestServer server;
  server.serve(file_bytes(recording));
  const std::atomic<bool> never{false};
  EventStreamReader streamed(std::make_unique<TcpBytes>(TcpAddress::parse(server.url()), never), std::nullopt, "");
  EXPECT_TRUE(all_events(streamed) == expected);
}

TEST(TcpBytes, AStreamCutInsideAWordKeepsTheEventsBeforeIt) {
  TempDir dir;
  const auto recording = simulated_recording(dir);
  std::vector<std::uint8_t> bytes = file_bytes(recording);
  bytes.resize(bytes.size() / 2 + 1);  // EVT 3.0 words are 2 bytes: the cut is inside one
  std::ofstream(dir.file("cut.raw"), std::ios::binary)
      .write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  EventStreamReader cut_file(dir.file("cut.raw"));
  std::string file_error;
  const std::vector<Event> expected = all_events(cut_file, &file_error);
  EXPECT_FALSE(file_error.empty());
  TestServer server;
  server.serve(bytes);
  const std::atomic<bool> never{false};
  EventStreamReader streamed(std::make_unique<TcpBytes>(TcpAddress::parse(server.url()), never), std::nullopt, "");
  std::string error;
  const std::vector<Event> got = all_events(streamed, &error);
  EXPECT_FALSE(error.empty()) << "a cut inside a word must be reported";
  EXPECT_GT(got.size(), 1000u);
  EXPECT_TRUE(got == expected) << "the events before the cut, as from the same bytes in a file";
}

TEST(TcpBytes, AnAedat31NetworkStreamInRandomPiecesGivesItsEvents) {
  TempDir dir;
  EventStreamReader finished(simulated_recording(dir));
  const std::vector<Event> expected = all_events(finished);
  TestServer server;
  server.serve(test_support::aedat31_network_stream(expected));
  const std::atomic<bool> never{false};
  EventStreamReader streamed(std::make_unique<TcpBytes>(TcpAddress::parse(server.url()), never), std::nullopt, "");
  EXPECT_EQ(streamed.format(), EventFormat::Aedat31Network);  // told by the network header's magic number
  EXPECT_TRUE(all_events(streamed) == expected);
}

TEST(ReconnectingStream, AServerThatRestartsMidStreamDeliversEveryEventOnce) {
  TempDir dir;
  EventStreamReader finished(simulated_recording(dir));
  const std::vector<Event> expected = all_events(finished);
  const std::size_t half = expected.size() / 1000 * 500;  // a packet boundary (500 events a packet)
  TestServer server;
  // The server goes away after the first half and comes back with a stream of its own (its network
  // header again) that goes on from where the first ended.
  server.serve_each({test_support::aedat31_network_stream(std::span(expected).first(half)),
                     test_support::aedat31_network_stream(std::span(expected).subspan(half))});
  std::atomic<bool> stop{false};
  const TcpAddress address = TcpAddress::parse(server.url());
  const auto source =
      open_reconnecting([&] { return open_stream(std::make_unique<TcpBytes>(address, stop), std::nullopt, ""); }, stop);
  EXPECT_TRUE(source->live());
  std::vector<Event> got;
  EventBatch batch;
  while (got.size() < expected.size() && source->read(batch)) {
    for (std::size_t i = 0; i < batch.size(); ++i) got.push_back(batch[i]);
  }
  EXPECT_TRUE(got == expected) << got.size() << " of " << expected.size() << " events";
  EXPECT_GE(source->reconnects(), 1u);
  stop = true;  // the server is gone for good: stopping ends the reading
  const auto stopped = std::chrono::steady_clock::now();
  while (source->read(batch)) {
  }
  EXPECT_LT(std::chrono::steady_clock::now() - stopped, 3s);
}

TEST(ReconnectingStream, WaitsForAServerNotYetUpAndStopEndsTheWait) {
  std::string url;
  {
    TestServer closed;
    url = closed.url();
  }
  std::atomic<bool> stop{false};
  std::thread stopper([&] {
    std::this_thread::sleep_for(600ms);
    stop = true;
  });
  const TcpAddress address = TcpAddress::parse(url);
  const double cpu_before = thread_cpu_seconds();
  EXPECT_THROW((void)open_reconnecting(
                   [&] { return open_stream(std::make_unique<TcpBytes>(address, stop), std::nullopt, ""); }, stop),
               std::runtime_error);
  EXPECT_LT(thread_cpu_seconds() - cpu_before, 0.05) << "waiting between attempts must not spin";
  stopper.join();
}

TEST(DvNetworkStream, ARealRecordingStreamedWithADisconnectArrivesOnceEveryEvent) {
  const auto recording = real_recording("dvxplorer_person.aedat4");
  if (!std::filesystem::exists(recording)) GTEST_SKIP() << "no " << recording << " (../shared is absent)";
  std::vector<Event> expected;
  std::optional<SensorSize> sensor;
  {
    const auto file = open_recording(recording, std::nullopt, "", 1000);
    sensor = file->geometry();
    EventBatch batch;
    while (file->read(batch)) {
      for (std::size_t i = 0; i < batch.size(); ++i) expected.push_back(batch[i]);
    }
  }
  ASSERT_FALSE(expected.empty());
  const test_support::DvFraming file(recording);
  ASSERT_GT(file.packets(), 2u);
  const std::size_t middle = file.packets() / 2;
  TestServer server;
  // The server goes away in the middle and comes back, sending its header again, then the rest.
  server.serve_each({file.stream(0, middle), file.stream(middle, file.packets())});
  std::atomic<bool> stop{false};
  const TcpAddress address = TcpAddress::parse(server.url());
  const auto source =
      open_reconnecting([&] { return open_dv_stream(std::make_unique<TcpBytes>(address, stop)); }, stop);
  EXPECT_EQ(source->geometry(), sensor);  // from the stream's header
  std::vector<Event> got;
  EventBatch batch;
  while (got.size() < expected.size() && source->read(batch)) {
    for (std::size_t i = 0; i < batch.size(); ++i) got.push_back(batch[i]);
  }
  EXPECT_EQ(got.size(), expected.size());
  EXPECT_TRUE(got == expected);
  EXPECT_GE(source->reconnects(), 1u);
  stop = true;
}

TEST(DvNetworkStream, AUnixSocketStreamCutInsideAPacketKeepsTheEventsBeforeIt) {
  const auto recording = real_recording("dvxplorer_person.aedat4");
  if (!std::filesystem::exists(recording)) GTEST_SKIP() << "no " << recording << " (../shared is absent)";
  const test_support::DvFraming file(recording);
  std::vector<std::uint8_t> cut = file.stream(0, file.packets());
  cut.resize(cut.size() - 3);  // inside the last packet
  TempDir dir;
  const std::string path = dir.file("dv.sock").string();
  const int listener = socket(AF_UNIX, SOCK_STREAM, 0);
  sockaddr_un address{};
  address.sun_family = AF_UNIX;
  path.copy(address.sun_path, path.size());
  ASSERT_EQ(bind(listener, reinterpret_cast<sockaddr*>(&address), sizeof address), 0);
  ASSERT_EQ(listen(listener, 1), 0);
  std::thread server([&] {
    const int client = accept(listener, nullptr, nullptr);
    if (client >= 0) write_in_pieces(client, cut, 13u);
  });
  const std::atomic<bool> never{false};
  const auto source = open_dv_stream(std::make_unique<UnixSocketBytes>(path, never));
  std::size_t events = 0;
  std::string error;
  EventBatch batch;
  try {
    while (source->read(batch)) events += batch.size();
  } catch (const FormatError& fault) {
    error = fault.what();
  }
  server.join();
  close(listener);
  EXPECT_GT(events, 0u);
  EXPECT_NE(error.find("stream ends inside a"), std::string::npos) << "error: '" << error << "'";
}

TEST(TcpBytes, BadAddressesAndRefusedConnectionsSaySo) {
  EXPECT_THROW(TcpAddress::parse("tcp://nohost"), std::invalid_argument);
  EXPECT_THROW(TcpAddress::parse("udp://a:1"), std::invalid_argument);
  EXPECT_EQ(TcpAddress::parse("tcp://[::1]:9").host, "::1");
  // A port nobody listens on: bound and closed again.
  std::string url;
  {
    TestServer closed;
    url = closed.url();
  }
  const std::atomic<bool> never{false};
  try {
    TcpBytes bytes(TcpAddress::parse(url), never);
    ADD_FAILURE() << "connected to a closed port";
  } catch (const std::runtime_error& error) {
    EXPECT_NE(std::string(error.what()).find("cannot connect to " + url), std::string::npos) << error.what();
  }
}

}  // namespace
}  // namespace evldt
