#include "evldt/web/web_view.hpp"

#include <fmt/core.h>
#include <sys/socket.h>
#include <unistd.h>

#include <httplib.h>
#include <atomic>
#include <charconv>
#include <opencv2/imgcodecs.hpp>  // its constants; the calls go through evldt::media
#include <stdexcept>

#include "evldt/json/json_writer.hpp"
#include "evldt/media/media.hpp"

namespace evldt {

void WebViewCounts::print(std::FILE* out) const {
  fmt::print(out, "  web       {} pages, {} pictures sent ({} encoded), {} layer keys\n", pages, pictures, encoded,
             keys);
}
namespace {

std::string escape_html(const std::string& text) {
  std::string out;
  for (const char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

// The page: the picture, fetched again as soon as the last one is shown (a newer one, or 204 and a
// short pause); the status and the layer buttons, every half second.
constexpr const char* kPage = R"(<!doctype html>
<html lang="en"><head><meta charset="utf-8"><meta name="viewport" content="width=device-width">
<title>@TITLE@</title>
<style>
body { margin: 0; background: #15171a; color: #d8dde3; font: 14px/1.4 system-ui, sans-serif; }
header { display: flex; flex-wrap: wrap; gap: 6px; align-items: center; padding: 8px; }
h1 { font-size: 16px; margin: 0 12px 0 0; }
button { font: inherit; padding: 3px 10px; border: 1px solid #556; border-radius: 4px; background: #23262b; color: #99a; cursor: pointer; }
button.on { background: #2d6a4f; color: #fff; border-color: #40916c; }
#picture { display: block; max-width: 100%; height: auto; background: #000; }
#status { margin: 8px; white-space: pre-wrap; font-family: monospace; }
</style></head>
<body>
<header><h1>@TITLE@</h1><span id="layers"></span></header>
<img id="picture" alt="the live picture">
<div id="status">waiting for the first picture</div>
<script>
"use strict";
const picture = document.getElementById("picture");
const pause = ms => new Promise(done => setTimeout(done, ms));
async function showPictures() {
  let number = 0, shown = null;
  for (;;) {
    try {
      const response = await fetch("/picture.jpg?after=" + number, {cache: "no-store"});
      if (response.status !== 200) { await pause(30); continue; }
      number = Number(response.headers.get("X-Picture"));
      const url = URL.createObjectURL(await response.blob());
      await new Promise(done => { picture.onload = picture.onerror = done; picture.src = url; });
      if (shown) URL.revokeObjectURL(shown);
      shown = url;
    } catch (error) {
      await pause(1000);  // the viz stopped or the network went away: try again
    }
  }
}
let layerText = "";
async function showStatus() {
  try {
    const status = await (await fetch("/status.json", {cache: "no-store"})).json();
    document.getElementById("status").textContent = status.status.join("\n");
    const text = JSON.stringify(status.layers);
    if (text !== layerText) {
      layerText = text;
      const bar = document.getElementById("layers");
      bar.replaceChildren(...status.layers.map(layer => {
        const button = document.createElement("button");
        button.textContent = layer.key + " " + layer.name;
        button.className = layer.shown ? "on" : "";
        button.onclick = () => fetch("/key/" + layer.key, {method: "POST"}).then(showStatus);
        return button;
      }));
    }
  } catch (error) {
    document.getElementById("status").textContent = "evldt-viz does not answer";
  }
}
showPictures();
showStatus();
setInterval(showStatus, 500);
</script>
</body></html>
)";

std::string page_for(const std::string& title) {
  std::string page = kPage;
  const std::string escaped = escape_html(title);
  for (std::size_t at = page.find("@TITLE@"); at != std::string::npos; at = page.find("@TITLE@", at + escaped.size())) {
    page.replace(at, 7, escaped);
  }
  return page;
}

}  // namespace

WebView::WebView(WebViewOptions options) : options_(std::move(options)), server_(std::make_unique<httplib::Server>()) {
  if (options_.jpeg_quality < 1 || options_.jpeg_quality > 100)
    throw std::invalid_argument("JPEG quality must be in 1..100");
  server_->set_keep_alive_timeout(2);  // an idle browser's connection is closed soon, and at a stop
  // SO_REUSEADDR only: httplib's default SO_REUSEPORT lets a second viz bind the same port and
  // take half of the browsers' connections.
  server_->set_socket_options([](int socket) {
    const int yes = 1;
    setsockopt(socket, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
  });
  add_routes();
  const HttpAddress& address = options_.address;
  port_ = address.port == 0 ? server_->bind_to_any_port(address.host)
                            : (server_->bind_to_port(address.host, address.port) ? address.port : -1);
  if (port_ <= 0) {
    throw std::runtime_error("cannot serve HTTP on " + address.host + ":" + std::to_string(address.port) +
                             " (port in use, or not an address of this host)");
  }
  thread_ = std::thread([this] {
    server_->listen_after_bind();
    listen_returned_ = true;
  });
  // stop() stops only a server that runs: one stopped before its thread started would run on.
  while (!server_->is_running() && !listen_returned_) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  if (!server_->is_running()) {
    thread_.join();
    throw std::runtime_error("cannot serve HTTP on " + address.host + ":" + std::to_string(port_));
  }
}

WebView::~WebView() {
  server_->stop();
  thread_.join();
}

std::string WebView::url() const {
  std::string host = options_.address.host;
  if (host == "0.0.0.0" || host == "::") {
    char name[256] = {};
    host = gethostname(name, sizeof name - 1) == 0 ? name : "localhost";
  } else if (host.find(':') != std::string::npos) {
    host = "[" + host + "]";
  }
  return "http://" + host + ":" + std::to_string(port_) + "/";
}

bool WebView::watched() const {
  std::lock_guard lock(mutex_);
  return Clock::now() < watched_until_;
}

void WebView::publish(const cv::Mat& picture, std::vector<std::string> status, std::vector<WebLayer> layers) {
  std::shared_ptr<Picture> next;
  bool copy = false;
  {
    std::lock_guard lock(mutex_);
    copy = Clock::now() < watched_until_;
    // Browsers get copies of newest_ only, under the lock: once none holds the spare, none will.
    if (spare_ && spare_.use_count() == 1) next = std::move(spare_);
  }
  if (!next) next = std::make_shared<Picture>();
  if (copy) {
    picture.copyTo(next->bgr);  // into the spare's buffer: no allocation once warm
  } else {
    next->bgr.release();
  }
  next->status = std::move(status);
  next->layers = std::move(layers);
  std::lock_guard lock(mutex_);
  next->number = ++published_;
  spare_ = std::move(newest_);
  newest_ = std::move(next);
}

std::vector<char> WebView::take_keys() {
  std::lock_guard lock(mutex_);
  std::vector<char> keys;
  keys.swap(keys_);
  return keys;
}

WebViewCounts WebView::counts() const {
  std::lock_guard lock(mutex_);
  return counts_;
}

std::shared_ptr<const WebView::Picture> WebView::newest() const {
  std::shared_ptr<Picture> held;
  {
    std::lock_guard lock(mutex_);
    held = newest_;
  }
  if (!held) return nullptr;
  // A browser gives its hold up under the lock: publish() reuses a picture once no browser holds
  // it, and only a release under the same lock orders the browser's reads of it before that reuse's
  // writes (seeing a reference count drop to one does not; ThreadSanitizer caught it).
  const Picture* const picture = held.get();
  return {picture, [this, held = std::move(held)](const Picture*) mutable {
            std::lock_guard lock(mutex_);
            held.reset();
          }};
}

std::shared_ptr<const std::string> WebView::jpeg_of(const Picture& picture) {
  std::lock_guard lock(encode_mutex_);
  if (encoded_number_ != picture.number || !encoded_) {
    std::vector<std::uint8_t> bytes;
    media::encode_image(".jpg", picture.bgr, bytes, {cv::IMWRITE_JPEG_QUALITY, options_.jpeg_quality});
    encoded_ = std::make_shared<const std::string>(bytes.begin(), bytes.end());
    encoded_number_ = picture.number;
    std::lock_guard counts_lock(mutex_);
    ++counts_.encoded;
  }
  return encoded_;
}

std::string WebView::status_json() const {
  const auto picture = newest();
  std::string json = "{\"picture\": " + std::to_string(picture ? picture->number : 0) + ", \"status\": [";
  if (picture) {
    for (std::size_t i = 0; i < picture->status.size(); ++i) json += (i ? ", " : "") + json_quoted(picture->status[i]);
  }
  json += "], \"layers\": [";
  if (picture) {
    for (std::size_t i = 0; i < picture->layers.size(); ++i) {
      const WebLayer& layer = picture->layers[i];
      json += std::string(i ? ", " : "") + "{\"key\": " + json_quoted(std::string(1, layer.key)) +
              ", \"name\": " + json_quoted(layer.name) + ", \"shown\": " + (layer.shown ? "true" : "false") + "}";
    }
  }
  return json + "]}";
}

void WebView::add_routes() {
  server_->Get("/", [this](const httplib::Request&, httplib::Response& response) {
    response.set_content(page_for(options_.title), "text/html; charset=utf-8");
    std::lock_guard lock(mutex_);
    ++counts_.pages;
  });
  server_->Get("/picture.jpg", [this](const httplib::Request& request, httplib::Response& response) {
    std::uint64_t after = 0;
    if (request.has_param("after")) {
      const std::string text = request.get_param_value("after");
      const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), after);
      if (error != std::errc() || end != text.data() + text.size()) {
        response.status = 400;
        response.set_content("after: a picture number expected\n", "text/plain");
        return;
      }
    }
    {
      std::lock_guard lock(mutex_);
      watched_until_ = Clock::now() + kWatchedFor;
    }
    const auto picture = newest();
    // Not yet drawn, drawn while nobody looked (not copied), or the one the browser shows.
    if (!picture || picture->bgr.empty() || picture->number == after) {
      response.status = 204;
      return;
    }
    const auto jpeg = jpeg_of(*picture);
    response.set_header("X-Picture", std::to_string(picture->number));
    response.set_header("Cache-Control", "no-store");
    response.set_content(*jpeg, "image/jpeg");
    std::lock_guard lock(mutex_);
    ++counts_.pictures;
  });
  server_->Get("/status.json", [this](const httplib::Request&, httplib::Response& response) {
    response.set_header("Cache-Control", "no-store");
    response.set_content(status_json(), "application/json");
  });
  server_->Post(R"(/key/(.))", [this](const httplib::Request& request, httplib::Response& response) {
    const char key = request.matches[1].str().front();
    const auto picture = newest();
    const bool known =
        picture && std::ranges::any_of(picture->layers, [&](const WebLayer& layer) { return layer.key == key; });
    if (!known) {
      response.status = 404;
      response.set_content(std::string("no layer has the key '") + key + "'\n", "text/plain");
      return;
    }
    std::lock_guard lock(mutex_);
    if (keys_.size() >= kMaxQueuedKeys) {
      response.status = 503;
      response.set_content("too many keys waiting for the viz\n", "text/plain");
      return;
    }
    keys_.push_back(key);
    ++counts_.keys;
    response.status = 204;
  });
}

}  // namespace evldt
