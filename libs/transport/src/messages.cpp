#include "evldt/transport/messages.hpp"

#include <cmath>
#include <stdexcept>

namespace evldt {
namespace {

// Walks an encoded LCM message (big-endian) without allocating, refusing any read past the end.
class WireWalker {
 public:
  explicit WireWalker(std::span<const std::uint8_t> bytes) : bytes_(bytes) {}

  bool skip(std::size_t n) {
    if (n > remaining()) return false;
    pos_ += n;
    return true;
  }
  bool read_i32(std::int32_t& value) {
    if (remaining() < 4) return false;
    std::uint32_t v = 0;
    for (int i = 0; i < 4; ++i) v = (v << 8) | bytes_[pos_++];
    value = static_cast<std::int32_t>(v);
    return true;
  }
  bool read_i64(std::int64_t& value) {
    if (remaining() < 8) return false;
    std::uint64_t v = 0;
    for (int i = 0; i < 8; ++i) v = (v << 8) | bytes_[pos_++];
    value = static_cast<std::int64_t>(v);
    return true;
  }
  /// An LCM string: int32 length including the terminating NUL, then the bytes.
  bool skip_string() {
    std::int32_t length = 0;
    if (!read_i32(length) || length < 1 || static_cast<std::size_t>(length) > remaining()) return false;
    if (bytes_[pos_ + static_cast<std::size_t>(length) - 1] != 0) return false;
    pos_ += static_cast<std::size_t>(length);
    return true;
  }
  /// A count field followed by exactly count records of `record_bytes` and nothing else.
  bool counted_tail(std::size_t record_bytes) {
    std::int32_t count = 0;
    return read_i32(count) && count >= 0 && remaining() == static_cast<std::size_t>(count) * record_bytes;
  }
  [[nodiscard]] std::size_t remaining() const { return bytes_.size() - pos_; }

 private:
  std::span<const std::uint8_t> bytes_;
  std::size_t pos_ = 0;
};

// Encoded sizes of the fixed parts (see the .lcm files).
constexpr std::size_t kSegmentWireBytes = 8 + 5 * 4 + 1 + 4 + 8 + 8;
constexpr std::size_t kStatsTailBytes = 8 + 6 * 8 + 2 * 8 + 4 + 8 + 4 + 2 * 4;

template <typename Message>
WireError check_hash(WireWalker& walker) {
  std::int64_t hash = 0;
  if (!walker.read_i64(hash)) return WireError::Malformed;
  return hash == Message::getHash() ? WireError::None : WireError::WrongType;
}

template <typename Message>
WireError decode_checked(std::span<const std::uint8_t> bytes, Message& out, bool well_formed) {
  if (!well_formed) return WireError::Malformed;
  const int size = static_cast<int>(bytes.size());
  return out.decode(bytes.data(), 0, size) == size ? WireError::None : WireError::Malformed;
}

// Messages above this size are refused before anything else (LCM itself caps at 256 MiB).
constexpr std::size_t kMaxMessageBytes = 64u << 20;

}  // namespace

std::string_view wire_error_name(WireError error) {
  switch (error) {
    case WireError::None: return "none";
    case WireError::WrongType: return "wrong message type";
    case WireError::Malformed: return "malformed";
  }
  return "?";
}

WireError decode_message(std::span<const std::uint8_t> bytes, event_batch_t& out) {
  if (bytes.size() > kMaxMessageBytes) return WireError::Malformed;
  WireWalker walker(bytes);
  if (const auto hash = check_hash<event_batch_t>(walker); hash != WireError::None) return hash;
  const bool well_formed = walker.skip(3 * 8) && walker.skip_string() && walker.skip(2 * 2 + 8) &&
                           walker.counted_tail(kEventWireBytes);
  return decode_checked(bytes, out, well_formed);
}

WireError decode_message(std::span<const std::uint8_t> bytes, segment_list_t& out) {
  if (bytes.size() > kMaxMessageBytes) return WireError::Malformed;
  WireWalker walker(bytes);
  if (const auto hash = check_hash<segment_list_t>(walker); hash != WireError::None) return hash;
  const bool well_formed = walker.skip(3 * 8) && walker.skip_string() && walker.skip(2 * 2 + 3 * 8) &&
                           walker.counted_tail(kSegmentWireBytes);
  return decode_checked(bytes, out, well_formed);
}

WireError decode_message(std::span<const std::uint8_t> bytes, stats_t& out) {
  if (bytes.size() > kMaxMessageBytes) return WireError::Malformed;
  WireWalker walker(bytes);
  if (const auto hash = check_hash<stats_t>(walker); hash != WireError::None) return hash;
  const bool well_formed =
      walker.skip(2 * 8) && walker.skip_string() && walker.skip_string() && walker.remaining() == kStatsTailBytes;
  return decode_checked(bytes, out, well_formed);
}

void fill_event_batch(const EventBatch& events, event_batch_t& msg) {
  const std::size_t n = events.size();
  msg.t_base_us = n ? events.t.front() : 0;
  msg.num_events = static_cast<std::int32_t>(n);
  msg.dt_us.resize(n);
  msg.x.resize(n);
  msg.y.resize(n);
  msg.polarity.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Timestamp dt = events.t[i] - msg.t_base_us;
    if (dt > kMaxBatchSpanUs || dt < -kMaxBatchSpanUs) {
      throw std::invalid_argument("the events of one batch must lie within 2^31 us of its first");
    }
    msg.dt_us[i] = static_cast<std::int32_t>(dt);
    msg.x[i] = static_cast<std::int16_t>(events.x[i]);
    msg.y[i] = static_cast<std::int16_t>(events.y[i]);
    msg.polarity[i] = events.p[i] > 0 ? 1 : 0;
  }
}

bool read_event_batch(const event_batch_t& msg, EventBatch& out) {
  // Keeps t_base + dt far from overflow; negative times are no camera's.
  constexpr std::int64_t kMaxTimeBase = std::int64_t{1} << 62;
  if (msg.t_base_us < 0 || msg.t_base_us > kMaxTimeBase) return false;
  const std::size_t n = static_cast<std::size_t>(std::max(msg.num_events, 0));
  out.reserve(out.size() + n);
  for (std::size_t i = 0; i < n; ++i) {
    // Negative coordinates wrap to 32768..65535: off every sensor, so the validator drops them.
    out.push_back(msg.t_base_us + msg.dt_us[i], static_cast<std::uint16_t>(msg.x[i]),
                  static_cast<std::uint16_t>(msg.y[i]), msg.polarity[i] ? std::int8_t{1} : std::int8_t{-1});
  }
  return true;
}

void fill_segment_list(std::span<const TrackedLine> lines, segment_list_t& msg) {
  msg.num_segments = static_cast<std::int32_t>(lines.size());
  msg.segments.resize(lines.size());
  for (std::size_t i = 0; i < lines.size(); ++i) {
    const TrackedLine& line = lines[i];
    line_segment_t& out = msg.segments[i];
    out.id = static_cast<std::int64_t>(line.id);
    out.x0 = line.segment.q0.x();
    out.y0 = line.segment.q0.y();
    out.x1 = line.segment.q1.x();
    out.y1 = line.segment.q1.y();
    out.score = line.score;
    out.status = static_cast<std::int8_t>(line.status);
    out.admin_block = line.admin_block;
    out.first_seen_us = line.first_seen_us;
    out.last_good_us = line.last_good_us;
  }
}

bool read_segment_list(const segment_list_t& msg, std::vector<TrackedLine>& out) {
  static_assert(static_cast<int>(LineStatus::Detected) == line_segment_t::STATUS_DETECTED &&
                static_cast<int>(LineStatus::GoodTrack) == line_segment_t::STATUS_GOOD_TRACK &&
                static_cast<int>(LineStatus::BadTrack) == line_segment_t::STATUS_BAD_TRACK);
  out.clear();
  for (const line_segment_t& in : msg.segments) {
    const bool finite = std::isfinite(in.x0) && std::isfinite(in.y0) && std::isfinite(in.x1) &&
                        std::isfinite(in.y1) && std::isfinite(in.score);
    if (!finite || in.status < line_segment_t::STATUS_DETECTED || in.status > line_segment_t::STATUS_BAD_TRACK) {
      out.clear();
      return false;
    }
    TrackedLine& line = out.emplace_back();
    line.id = static_cast<std::uint64_t>(in.id);
    line.segment = Segment{Point2(in.x0, in.y0), Point2(in.x1, in.y1)};
    line.score = in.score;
    line.status = static_cast<LineStatus>(in.status);
    line.admin_block = in.admin_block;
    line.first_seen_us = in.first_seen_us;
    line.last_good_us = in.last_good_us;
  }
  return true;
}

}  // namespace evldt
