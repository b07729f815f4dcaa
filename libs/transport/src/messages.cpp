#include "evldt/transport/messages.hpp"

#include <bit>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>
#include <type_traits>

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
  bool read_i16(std::int16_t& value) {
    if (remaining() < 2) return false;
    value = static_cast<std::int16_t>((bytes_[pos_] << 8) | bytes_[pos_ + 1]);
    pos_ += 2;
    return true;
  }
  bool read_string(std::string& value) {
    const std::size_t start = pos_;
    if (!skip_string()) return false;
    value.assign(reinterpret_cast<const char*>(bytes_.data()) + start + 4, pos_ - start - 5);
    return true;
  }
  [[nodiscard]] const std::uint8_t* here() const { return bytes_.data() + pos_; }
  /// An LCM string: int32 length including the terminating NUL, then the bytes. A NUL before the
  /// end is refused: lcm-gen's encoder stops at the first NUL, so no evldt publisher sends one.
  bool skip_string() {
    std::int32_t length = 0;
    if (!read_i32(length) || length < 1 || static_cast<std::size_t>(length) > remaining()) return false;
    const auto text = static_cast<std::size_t>(length) - 1;
    if (std::memchr(bytes_.data() + pos_, 0, text + 1) != bytes_.data() + pos_ + text) return false;
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
constexpr std::size_t kSegmentWireBytes = 8 + 5 * 4 + 1 + 4 + 8 + 8 + 2 * 4;
constexpr std::size_t kStatsMiddleBytes =
    8 + 6 * 8 + 2 * 8 + 4 + 8 + 4 + 2 * 4 + 1 + 8 + 4 + 2 * 8 + 2 * 8 + 8 + 4 + 2 * 4 + 8;  // period_s .. reconnects

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
    case WireError::None:
      return "none";
    case WireError::WrongType:
      return "wrong message type";
    case WireError::Malformed:
      return "malformed";
  }
  return "?";
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
  const bool well_formed = walker.skip(2 * 8) && walker.skip_string() && walker.skip_string() &&
                           walker.skip(kStatsMiddleBytes) && walker.skip_string() && walker.skip(4 * 8) &&
                           walker.counted_tail(4);
  return decode_checked(bytes, out, well_formed);
}

WireError decode_message(std::span<const std::uint8_t> bytes, camera_info_t& out) {
  if (bytes.size() > kMaxMessageBytes) return WireError::Malformed;
  WireWalker walker(bytes);
  if (const auto hash = check_hash<camera_info_t>(walker); hash != WireError::None) return hash;
  const bool well_formed = walker.skip(2 * 8) && walker.skip_string() && walker.skip(2 * 2 + 4 * 8) &&
                           walker.skip_string() && walker.skip_string() && walker.counted_tail(8);
  return decode_checked(bytes, out, well_formed);
}

void fill_camera_info(const RectificationTable& table, camera_info_t& msg) {
  const LensDescription& lens = table.lens;
  msg.width = static_cast<std::int16_t>(table.sensor.width);
  msg.height = static_cast<std::int16_t>(table.sensor.height);
  msg.fx = lens.fx;
  msg.fy = lens.fy;
  msg.cx = lens.cx;
  msg.cy = lens.cy;
  msg.sensor_distortion = lens.distortion;
  msg.calibration = lens.calibration;
  msg.num_coefficients = static_cast<std::int32_t>(lens.coefficients.size());
  msg.coefficients = lens.coefficients;
}

namespace {

void put_be(std::uint8_t*& out, std::uint64_t value, int bytes) {
  for (int i = bytes - 1; i >= 0; --i) *out++ = static_cast<std::uint8_t>(value >> (8 * i));
}

std::uint32_t get_be32(const std::uint8_t* in) {
  std::uint32_t value;
  std::memcpy(&value, in, 4);
  return __builtin_bswap32(value);
}

std::uint16_t get_be16(const std::uint8_t* in) {
  std::uint16_t value;
  std::memcpy(&value, in, 2);
  return __builtin_bswap16(value);
}

// Keeps t_base + dt far from overflow; negative times are no camera's.
constexpr std::int64_t kMaxTimeBase = std::int64_t{1} << 62;

}  // namespace

// The column loops below byte-swap in registers and store host order: big-endian on the wire only
// on a little-endian host (x86-64, AArch64 as Linux runs it).
static_assert(std::endian::native == std::endian::little, "the event batch encoder assumes a little-endian host");

void encode_event_batch(const event_batch_t& header, const EventBatch& events, std::vector<std::uint8_t>& out) {
  const std::size_t n = events.size();
  // The columns through local pointers: the byte stores below may alias anything, so reading
  // through the vectors would reload their data pointers every event and stop vectorisation.
  const Timestamp* const ts = events.t.data();
  const std::uint16_t* const x = events.x.data();
  const std::uint16_t* const y = events.y.data();
  const std::int8_t* const polarity_in = events.p.data();
  const Timestamp t_base = n ? ts[0] : 0;
  // Every t - t_base in -kMaxBatchSpanUs..kMaxBatchSpanUs (= INT32_MAX): an int32 other than INT32_MIN.
  // Branch-free, without 64-bit compares, so that it vectorises.
  static_assert(kMaxBatchSpanUs == INT32_MAX);
  std::uint64_t outside = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint64_t d = static_cast<std::uint64_t>(ts[i]) - static_cast<std::uint64_t>(t_base);
    outside |= ((d + (std::uint64_t{1} << 31)) >> 32) |
               static_cast<std::uint64_t>(static_cast<std::uint32_t>(d) == 0x80000000u);
  }
  if (outside != 0) throw std::invalid_argument("the events of one batch must lie within 2^31 us of its first");
  out.resize(8 + 3 * 8 + 4 + header.source.size() + 1 + 2 * 2 + 8 + 4 + n * kEventWireBytes);
  std::uint8_t* p = out.data();
  put_be(p, static_cast<std::uint64_t>(event_batch_t::getHash()), 8);
  put_be(p, static_cast<std::uint64_t>(header.utime), 8);
  put_be(p, static_cast<std::uint64_t>(header.epoch), 8);
  put_be(p, static_cast<std::uint64_t>(header.seq), 8);
  put_be(p, header.source.size() + 1, 4);
  p = std::copy(header.source.begin(), header.source.end(), p);
  *p++ = 0;
  put_be(p, static_cast<std::uint16_t>(header.width), 2);
  put_be(p, static_cast<std::uint16_t>(header.height), 2);
  put_be(p, static_cast<std::uint64_t>(t_base), 8);
  put_be(p, n, 4);
  // Four column loops, each a plain byte-swapping copy the compiler can vectorise: 16-bit swaps
  // (SSE2 shifts; a 32-bit byte swap it would do byte by byte without SSSE3's pshufb).
  std::uint8_t* dt = p;
  std::uint8_t* xs = dt + 4 * n;
  std::uint8_t* ys = xs + 2 * n;
  std::uint8_t* polarity = ys + 2 * n;
  const auto swap16 = [](std::uint16_t v) { return static_cast<std::uint16_t>((v >> 8) | (v << 8)); };
  for (std::size_t i = 0; i < n; ++i) {
    const auto d = static_cast<std::uint32_t>(static_cast<std::uint64_t>(ts[i]) - static_cast<std::uint64_t>(t_base));
    const std::uint16_t high = swap16(static_cast<std::uint16_t>(d >> 16)), low = swap16(static_cast<std::uint16_t>(d));
    std::memcpy(dt + 4 * i, &high, 2);
    std::memcpy(dt + 4 * i + 2, &low, 2);
  }
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint16_t v = swap16(x[i]);
    std::memcpy(xs + 2 * i, &v, 2);
  }
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint16_t v = swap16(y[i]);
    std::memcpy(ys + 2 * i, &v, 2);
  }
  for (std::size_t i = 0; i < n; ++i) polarity[i] = polarity_in[i] > 0 ? 1 : 0;
}

namespace {

// Checks a whole event batch's framing and reads its scalar fields; `events` points at its columns.
WireError decode_event_batch_header_at(std::span<const std::uint8_t> bytes, event_batch_t& header,
                                       const std::uint8_t*& events) {
  if (bytes.size() > kMaxMessageBytes) return WireError::Malformed;
  WireWalker walker(bytes);
  if (const auto hash = check_hash<event_batch_t>(walker); hash != WireError::None) return hash;
  std::int32_t count = 0;
  const bool header_ok = walker.read_i64(header.utime) && walker.read_i64(header.epoch) &&
                         walker.read_i64(header.seq) && walker.read_string(header.source) &&
                         walker.read_i16(header.width) && walker.read_i16(header.height) &&
                         walker.read_i64(header.t_base_us) && walker.read_i32(count);
  if (!header_ok || count < 0 || walker.remaining() != static_cast<std::size_t>(count) * kEventWireBytes) {
    return WireError::Malformed;
  }
  if (header.t_base_us < 0 || header.t_base_us > kMaxTimeBase) return WireError::Malformed;
  header.num_events = count;
  header.dt_us.clear();
  header.x.clear();
  header.y.clear();
  header.polarity.clear();
  events = walker.here();
  return WireError::None;
}

WireError decode_event_batch_into(std::span<const std::uint8_t> bytes, event_batch_t& header, EventBatch& events,
                                  std::size_t stride) {
  const std::uint8_t* dt = nullptr;
  if (const WireError error = decode_event_batch_header_at(bytes, header, dt); error != WireError::None) return error;
  const auto n = static_cast<std::size_t>(header.num_events);
  const std::uint8_t* xs = dt + 4 * n;
  const std::uint8_t* ys = xs + 2 * n;
  const std::uint8_t* polarity = ys + 2 * n;
  // Events first, first + stride, ..., n - 1: the last is always kept, so event time moves on alike.
  const std::size_t kept = n == 0 ? 0 : (n - 1) / stride + 1;
  const std::size_t first = n == 0 ? 0 : (n - 1) % stride;
  events.t.resize(kept);
  events.x.resize(kept);
  events.y.resize(kept);
  events.p.resize(kept);
  const Timestamp t_base = header.t_base_us;
  // The columns as plain pointers: a store through the vectors' own (of int8_t, which may alias
  // anything) would make the compiler reload their pointers at every event and not vectorise.
  Timestamp* const out_t = events.t.data();
  std::uint16_t* const out_x = events.x.data();
  std::uint16_t* const out_y = events.y.data();
  std::int8_t* const out_p = events.p.data();
  const auto decode = [&](auto step) {  // a constant step of 1 keeps the loops vectorised
    for (std::size_t k = 0; k < kept; ++k)
      out_t[k] = t_base + static_cast<std::int32_t>(get_be32(dt + 4 * (first + k * step)));
    // Negative coordinates arrive as 32768..65535: off every sensor, so the validator drops them.
    for (std::size_t k = 0; k < kept; ++k) out_x[k] = get_be16(xs + 2 * (first + k * step));
    for (std::size_t k = 0; k < kept; ++k) out_y[k] = get_be16(ys + 2 * (first + k * step));
    for (std::size_t k = 0; k < kept; ++k) out_p[k] = polarity[first + k * step] ? std::int8_t{1} : std::int8_t{-1};
  };
  if (stride == 1) {
    decode(std::integral_constant<std::size_t, 1>{});
  } else {
    decode(stride);
  }
  return WireError::None;
}

}  // namespace

WireError decode_event_batch_header(std::span<const std::uint8_t> bytes, event_batch_t& header,
                                    Timestamp& last_event_us) {
  const std::uint8_t* dt = nullptr;
  if (const WireError error = decode_event_batch_header_at(bytes, header, dt); error != WireError::None) return error;
  last_event_us = header.t_base_us;
  if (header.num_events > 0) {
    last_event_us += static_cast<std::int32_t>(get_be32(dt + 4 * (static_cast<std::size_t>(header.num_events) - 1)));
  }
  return WireError::None;
}

WireError decode_event_batch(std::span<const std::uint8_t> bytes, event_batch_t& header, EventBatch& events,
                             std::size_t stride) {
  if (stride == 0) throw std::invalid_argument("decode_event_batch: stride 0");
  // `events` is resized, not cleared first: the columns keep their size from the last batch, so
  // only growth beyond it pays for value-initialisation.
  const WireError error = decode_event_batch_into(bytes, header, events, stride);
  if (error != WireError::None) events.clear();
  return error;
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
    out.normal_velocity = line.normal_velocity;
    out.normal_velocity_std = line.normal_velocity_std;
  }
}

bool read_segment_list(const segment_list_t& msg, std::vector<TrackedLine>& out) {
  static_assert(static_cast<int>(LineStatus::Detected) == line_segment_t::STATUS_DETECTED &&
                static_cast<int>(LineStatus::GoodTrack) == line_segment_t::STATUS_GOOD_TRACK &&
                static_cast<int>(LineStatus::BadTrack) == line_segment_t::STATUS_BAD_TRACK);
  out.clear();
  for (const line_segment_t& in : msg.segments) {
    const bool finite = std::isfinite(in.x0) && std::isfinite(in.y0) && std::isfinite(in.x1) && std::isfinite(in.y1) &&
                        std::isfinite(in.score) && std::isfinite(in.normal_velocity) &&
                        std::isfinite(in.normal_velocity_std) && in.normal_velocity_std >= 0;
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
    line.normal_velocity = in.normal_velocity;
    line.normal_velocity_std = in.normal_velocity_std;
  }
  return true;
}

}  // namespace evldt
