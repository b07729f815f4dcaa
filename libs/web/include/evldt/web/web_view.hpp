#pragma once
// A live view in a browser, for robots without a display: an HTTP server (cpp-httplib, on threads of
// its own) serving a page that shows the newest picture, the status text, and buttons for the
// picture's layers.
//
// The drawing thread never waits for a browser: publish() copies the picture (only while a browser
// is looking) and returns. Each browser asks for a picture newer than its last when it has shown
// that one, so a slow browser gets fewer pictures and a browser that goes away costs nothing; a
// picture is JPEG-encoded once, by the first browser's request, for all of them.
//
// Endpoints: GET / (the page), GET /picture.jpg[?after=N] (the newest picture, or 204 No Content
// when picture N is still the newest; header X-Picture: its number), GET /status.json (picture
// number, status lines, layers), POST /key/K (a layer's key, as pressed in a window).

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <mutex>
#include <opencv2/core.hpp>
#include <string>
#include <thread>
#include <vector>

#include "evldt/web/http_address.hpp"

namespace httplib {
class Server;
}

namespace evldt {

/// A layer of the picture a button shows or hides.
struct WebLayer {
  char key;
  std::string name;
  bool shown;
};

struct WebViewOptions {
  HttpAddress address;
  std::string title = "evldt";
  int jpeg_quality = 80;
};

struct WebViewCounts {
  std::uint64_t pages = 0;     ///< the page served
  std::uint64_t pictures = 0;  ///< pictures sent (several browsers: each counts)
  std::uint64_t encoded = 0;   ///< pictures JPEG-encoded
  std::uint64_t keys = 0;      ///< layer keys pressed in browsers

  /// The web line of the viz's exit summary.
  void print(std::FILE* out) const;
};

class WebView {
 public:
  /// Binds the address and starts serving; throws std::runtime_error naming the address when it
  /// cannot be bound (in use, not this host's).
  explicit WebView(WebViewOptions options);
  ~WebView();
  WebView(const WebView&) = delete;
  WebView& operator=(const WebView&) = delete;

  /// The port bound (the one asked for, or the free one picked for port 0).
  [[nodiscard]] int port() const { return port_; }
  /// "http://HOST:PORT/" as a browser on this host reaches it.
  [[nodiscard]] std::string url() const;
  /// A browser asked for a picture in the last kWatchedFor.
  [[nodiscard]] bool watched() const;
  /// The newest picture (BGR, 8 bits; copied only while watched()) with its status lines and
  /// layers (always kept: they are small).
  void publish(const cv::Mat& picture, std::vector<std::string> status, std::vector<WebLayer> layers);
  /// The layer keys pressed in browsers since the last call, oldest first.
  [[nodiscard]] std::vector<char> take_keys();
  [[nodiscard]] WebViewCounts counts() const;

  static constexpr std::chrono::seconds kWatchedFor{2};
  /// Keys waiting beyond this many are dropped (a browser clicking faster than the viz draws).
  static constexpr std::size_t kMaxQueuedKeys = 64;

 private:
  struct Picture {
    std::uint64_t number = 0;
    cv::Mat bgr;
    std::vector<std::string> status;
    std::vector<WebLayer> layers;
  };
  using Clock = std::chrono::steady_clock;
  void add_routes();
  /// The newest picture, held by the caller until it drops the pointer (dropped under mutex_).
  [[nodiscard]] std::shared_ptr<const Picture> newest() const;
  /// The JPEG of `picture`, encoded once.
  [[nodiscard]] std::shared_ptr<const std::string> jpeg_of(const Picture& picture);
  [[nodiscard]] std::string status_json() const;

  WebViewOptions options_;
  std::unique_ptr<httplib::Server> server_;
  int port_ = 0;
  std::atomic<bool> listen_returned_{false};
  std::thread thread_;

  mutable std::mutex mutex_;  // guards what follows up to encode_mutex_
  std::shared_ptr<Picture> newest_;
  std::shared_ptr<Picture> spare_;  // the one before, reused once no browser holds it
  std::uint64_t published_ = 0;
  std::vector<char> keys_;
  Clock::time_point watched_until_{};
  WebViewCounts counts_;

  std::mutex encode_mutex_;  // one encoder at a time; guards what follows
  std::uint64_t encoded_number_ = 0;
  std::shared_ptr<const std::string> encoded_;
};

}  // namespace evldt
