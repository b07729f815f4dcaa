#pragma once
// evldt's consumer SDK: a program of one's own receives a camera's segments and whole lines
// from a running evldt-lines as plain structs, with nothing of evldt but the message types. Header
// only; installed with the message types (find_package(evldt): evldt::client; pkg-config: evldt).
//
//   lcm::LCM bus;                                   // LCM_DEFAULT_URL, or a URL
//   evldt::client::LineSubscriber lines(bus, "cam0", [](const evldt::client::LineList& list) {
//     for (const auto& line : list.lines) std::printf("%lld ...\n", (long long)line.id);
//   });
//   while (bus.handle() == 0) {}
//
// Lists that do not decode (another type on the channel, damaged bytes) are counted, never handed on.

#include <cctype>
#include <cstdint>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include <lcm/lcm-cpp.hpp>

#include "evldt/segment_list_t.hpp"

namespace evldt::client {

/// How well the events support a line (line_segment_t's STATUS_*).
enum class LineStatus : std::int8_t { Detected = 0, GoodTrack = 1, BadTrack = 2 };

/// One line in pixels of the camera's sensor (continuous coordinates: pixel x covers [x, x + 1)).
struct Line {
  std::int64_t id = 0;  ///< the same line keeps its id from list to list
  float x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  float score = 0;  ///< fitting score
  LineStatus status = LineStatus::Detected;
  /// px/s across itself, along (-(y1 - y0), x1 - x0) / length (for a line drawn left to right,
  /// positive is down the image), and the standard deviation of that estimate.
  float normal_velocity = 0, normal_velocity_std = 0;
};

/// The lines of one camera at one lattice state.
struct LineList {
  bool whole_lines = false;  ///< WHOLE_LINES_<CAMERA> (edges across blocks) or LINES_<CAMERA> (segments)
  std::string camera;
  int width = 0, height = 0;            ///< the sensor
  std::int64_t t_us = 0;                ///< event time of the lattice state
  std::int64_t utime = 0;               ///< wall clock at publication, us since the Unix epoch
  std::int64_t newest_batch_utime = 0;  ///< utime - this: the end-to-end latency
  std::vector<Line> lines;
};

class LineSubscriber {
 public:
  using Handler = std::function<void(const LineList&)>;

  /// Subscribes to LINES_<CAMERA> and WHOLE_LINES_<CAMERA> on `bus` (camera names are matched in
  /// upper case, as evldt names its channels); `handler` runs in bus.handle().
  LineSubscriber(lcm::LCM& bus, const std::string& camera, Handler handler) : bus_(bus), handler_(std::move(handler)) {
    std::string upper = camera;
    for (char& c : upper) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    subscriptions_.push_back(bus_.subscribe("LINES_" + upper, &LineSubscriber::on_message, this));
    subscriptions_.push_back(bus_.subscribe("WHOLE_LINES_" + upper, &LineSubscriber::on_message, this));
  }
  ~LineSubscriber() {
    for (lcm::Subscription* subscription : subscriptions_) bus_.unsubscribe(subscription);
  }
  LineSubscriber(const LineSubscriber&) = delete;
  LineSubscriber& operator=(const LineSubscriber&) = delete;

  /// Messages on the channels that did not decode as segment lists.
  [[nodiscard]] std::uint64_t undecodable() const { return undecodable_; }

 private:
  void on_message(const lcm::ReceiveBuffer* buffer, const std::string& channel) {
    segment_list_t message;
    if (message.decode(buffer->data, 0, static_cast<int>(buffer->data_size)) < 0) {
      ++undecodable_;
      return;
    }
    LineList list;
    list.whole_lines = channel.rfind("WHOLE_LINES_", 0) == 0;
    list.camera = message.source;
    list.width = message.width;
    list.height = message.height;
    list.t_us = message.t_us;
    list.utime = message.utime;
    list.newest_batch_utime = message.newest_batch_utime;
    list.lines.reserve(message.segments.size());
    for (const line_segment_t& s : message.segments) {
      list.lines.push_back({s.id, s.x0, s.y0, s.x1, s.y1, s.score, static_cast<LineStatus>(s.status), s.normal_velocity,
                            s.normal_velocity_std});
    }
    handler_(list);
  }

  lcm::LCM& bus_;
  Handler handler_;
  std::vector<lcm::Subscription*> subscriptions_;
  std::uint64_t undecodable_ = 0;
};

}  // namespace evldt::client
