#pragma once
// Between the core's types and the LCM messages. Decoding from the wire is checked first: the code
// lcm-gen writes trusts length fields (a forged count makes it allocate gigabytes before it notices
// the bytes are missing), so every length is checked against the bytes actually received. The
// generated types share the namespace evldt (the LCM package) with the core.

#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include "evldt/calibration/rectifier.hpp"
#include "evldt/camera_info_t.hpp"
#include "evldt/event_batch_t.hpp"
#include "evldt/events/event.hpp"
#include "evldt/lines/line_types.hpp"
#include "evldt/segment_list_t.hpp"
#include "evldt/stats_t.hpp"

namespace evldt {

/// Bytes of one event in an event_batch_t (int32 dt, int16 x, int16 y, int8 polarity).
inline constexpr std::size_t kEventWireBytes = 9;
/// Largest event-time span of one batch (dt is int32).
inline constexpr Timestamp kMaxBatchSpanUs = INT32_MAX;

/// Why a payload was refused.
enum class WireError : std::uint8_t { None, WrongType, Malformed };
std::string_view wire_error_name(WireError error);

/// Decodes `bytes` into `out` if, and only if, it is a complete, well-formed message of that type
/// (event batches: decode_event_batch).
WireError decode_message(std::span<const std::uint8_t> bytes, segment_list_t& out);
WireError decode_message(std::span<const std::uint8_t> bytes, stats_t& out);
WireError decode_message(std::span<const std::uint8_t> bytes, camera_info_t& out);

/// Encodes an event batch straight from `events` into `out` (resized): the bytes lcm-gen's encoder
/// writes for `header` with its arrays and time base filled from `events` (the header's own arrays
/// and t_base_us/num_events are ignored), without building those arrays first. Throws
/// std::invalid_argument if an event lies more than kMaxBatchSpanUs from the first.
void encode_event_batch(const event_batch_t& header, const EventBatch& events, std::vector<std::uint8_t>& out);
/// Decodes an event batch straight into `events` (emptied on an error): checks `bytes` as decode_message does,
/// sets the scalar fields of `header` (its arrays are left empty) and appends the events, without
/// building lcm-gen's arrays first. Coordinates and times are not judged here (the event validator
/// drops and counts those); a time base out of range (negative or above 2^62) is Malformed.
/// `stride` > 1 decodes every stride-th event only, ending with the last (a batch thinned under load:
/// the events kept span its whole time), at the cost of those kept.
WireError decode_event_batch(std::span<const std::uint8_t> bytes, event_batch_t& header, EventBatch& events,
                             std::size_t stride = 1);

/// Checks `bytes` as decode_event_batch does and sets the scalar fields of `header`, without decoding
/// the events: `last_event_us` is the time of the batch's last event (its time base if it has none).
/// What a subscriber needs to account a batch it sheds unread.
WireError decode_event_batch_header(std::span<const std::uint8_t> bytes, event_batch_t& header,
                                    Timestamp& last_event_us);

/// Fills the segments of `msg` (header fields are the caller's).
void fill_segment_list(std::span<const TrackedLine> lines, segment_list_t& msg);
/// The camera fields of a CAMERA_INFO message (utime, epoch and source are the caller's).
void fill_camera_info(const RectificationTable& table, camera_info_t& msg);
/// Replaces `out` with the segments of `msg`; false if any has an unknown status, a non-finite value
/// or a negative velocity deviation.
bool read_segment_list(const segment_list_t& msg, std::vector<TrackedLine>& out);

}  // namespace evldt
