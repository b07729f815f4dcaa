#include "evldt/app/lcm_options.hpp"

#include <spdlog/spdlog.h>
#include <systemd/sd-daemon.h>
#include <csignal>
#include <cstdlib>
#include <stdexcept>

#include "evldt/transport/channels.hpp"

namespace evldt {
namespace {
std::atomic<bool> g_stop{false};
static_assert(std::atomic<bool>::is_always_lock_free, "set from a signal handler");
extern "C" void request_stop(int) { g_stop.store(true); }
}  // namespace

void LcmOptions::add_to(CLI::App& app) {
  const char* env_url = std::getenv("LCM_DEFAULT_URL");
  url_ = env_url && *env_url ? env_url : std::string(kDefaultLcmUrl);
  app.add_option("--lcm-url", url_, "LCM URL (default: $LCM_DEFAULT_URL, else this host only)")->capture_default_str();
  app.add_option("--camera", camera_, "Camera name: channels EVENTS_<CAMERA> and LINES_<CAMERA>")
      ->capture_default_str()
      ->check([](const std::string& name) {
        try {
          check_camera_name(name);
          return std::string();
        } catch (const std::invalid_argument& error) {
          return std::string(error.what());
        }
      });
}

std::string LcmOptions::effective_url() const {
  // A large socket buffer rides out scheduling hiccups at kHz batch rates; the kernel caps it at
  // net.core.rmem_max (see deploy/README.md).
  if (!url_.starts_with("udpm://") || url_.find("recv_buf_size") != std::string::npos) return url_;
  return url_ + (url_.find('?') == std::string::npos ? "?" : "&") +
         "recv_buf_size=" + std::to_string(kReceiveBufferBytes);
}

std::unique_ptr<lcm::LCM> LcmOptions::connect() const {
  auto lcm = std::make_unique<lcm::LCM>(effective_url());
  if (!lcm->good()) {
    throw std::runtime_error("cannot start LCM on " + url_ +
                             " (a multicast URL needs a multicast route: on one host, "
                             "'ip route add 224.0.0.0/4 dev lo'; see deploy/README.md)");
  }
  return lcm;
}

void announce_ready(std::string_view service, std::string_view what) {
  spdlog::info("{} ready: {}", service, what);
  const std::string status = fmt::format("READY=1\nSTATUS={}", what);
  if (sd_notify(0, status.c_str()) < 0) spdlog::warn("could not tell systemd that {} is ready", service);
}

const std::atomic<bool>& stop_on_signals() {
  std::signal(SIGINT, request_stop);
  std::signal(SIGTERM, request_stop);
  return g_stop;
}

std::int64_t process_epoch_us() {
  static const std::int64_t epoch = wall_clock_us();
  return epoch;
}

}  // namespace evldt
