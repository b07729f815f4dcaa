#pragma once
// Command-line plumbing shared by the services: the LCM URL and camera name, and a stop flag that
// SIGINT/SIGTERM set so every service ends cleanly.

#include <CLI/CLI.hpp>
#include <atomic>
#include <lcm/lcm-cpp.hpp>
#include <memory>
#include <string>
#include <string_view>

namespace evldt {

class LcmOptions {
 public:
  /// Adds --lcm-url (default: $LCM_DEFAULT_URL, else multicast on this host with ttl=0) and --camera.
  void add_to(CLI::App& app);
  [[nodiscard]] const std::string& url() const { return url_; }
  /// The URL connected to: a udpm URL without recv_buf_size gets kReceiveBufferBytes.
  [[nodiscard]] std::string effective_url() const;
  static constexpr int kReceiveBufferBytes = 8 << 20;
  [[nodiscard]] const std::string& camera() const { return camera_; }
  /// Connects; throws std::runtime_error with the likely cause (multicast route) if LCM cannot start.
  [[nodiscard]] std::unique_ptr<lcm::LCM> connect() const;

 private:
  std::string url_;
  std::string camera_ = "cam0";
};

/// Says that a service is ready: subscribed, so every message published from now on reaches it. Logs
/// "<service> ready: <what>" at info level (tests and operators wait for that line) and tells
/// systemd (READY=1, for Type=notify units; a no-op outside systemd).
void announce_ready(std::string_view service, std::string_view what);

/// Installs SIGINT and SIGTERM handlers that set the returned flag (once; later calls return it).
const std::atomic<bool>& stop_on_signals();

/// Microseconds since the Unix epoch at the first call: the process's epoch in its messages.
std::int64_t process_epoch_us();

}  // namespace evldt
