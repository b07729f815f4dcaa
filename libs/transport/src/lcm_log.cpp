#include "evldt/transport/lcm_log.hpp"

#include <spdlog/spdlog.h>
#include <algorithm>
#include <fstream>
#include <stdexcept>

#include "evldt/transport/messages.hpp"

namespace evldt {
namespace {

bool channel_matches(const std::string& wanted, std::string_view prefix, const std::string& channel) {
  return wanted.empty() ? channel.starts_with(prefix) : channel == wanted;
}

}  // namespace

bool is_lcm_log(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  unsigned char magic[4] = {};
  return in.read(reinterpret_cast<char*>(magic), 4) && magic[0] == 0xED && magic[1] == 0xA1 && magic[2] == 0xDA &&
         magic[3] == 0x01;
}

LcmLogEventReader::LcmLogEventReader(const std::filesystem::path& path, std::string channel,
                                     Timestamp backwards_slack_us)
    : channel_(std::move(channel)), log_(path), receiver_(std::nullopt, backwards_slack_us) {
  if (!next_batch(first_)) {
    throw std::runtime_error("no valid event batch on " +
                             (channel_.empty() ? std::string("an EVENTS_* channel") : channel_) + " in LCM log " +
                             log_.path().string());
  }
  first_pending_ = true;
}

LcmLogEventReader::~LcmLogEventReader() = default;

bool LcmLogEventReader::next_batch(EventBatch& out) {
  while (log_.next(record_)) {
    if (!channel_matches(channel_, "EVENTS_", record_.channel)) continue;
    if (!receiver_.receive(record_.data, out)) continue;
    if (channel_.empty()) channel_ = record_.channel;
    return true;
  }
  log_.report();
  return false;
}

bool LcmLogEventReader::read(EventBatch& out) {
  if (first_pending_) {
    first_pending_ = false;
    out = first_;
    return true;
  }
  return next_batch(out);
}

double LcmLogEventReader::progress() const { return log_.progress(); }

std::vector<SegmentRow> read_segment_log(const std::filesystem::path& path, std::string channel) {
  LcmLogReader log(path);
  LcmLogReader::Record record;
  std::vector<SegmentRow> rows;
  std::uint64_t invalid = 0;
  segment_list_t msg;
  std::vector<TrackedLine> lines;
  std::size_t step_begin = 0;
  Timestamp step_t = INT64_MIN;
  bool any_list = false;
  while (log.next(record)) {
    if (!channel_matches(channel, "LINES_", record.channel)) continue;
    if (decode_message(record.data, msg) != WireError::None || !read_segment_list(msg, lines)) {
      ++invalid;
      continue;
    }
    if (channel.empty()) channel = record.channel;
    any_list = true;
    // Lists are published at a fixed rate: one of the same lattice time as the previous replaces it.
    if (msg.t_us == step_t) {
      rows.resize(step_begin);
    } else if (msg.t_us < step_t) {
      ++invalid;  // back in time (a restarted lines service): steps must stay ordered
      continue;
    }
    step_begin = rows.size();
    step_t = msg.t_us;
    std::sort(lines.begin(), lines.end(), [](const TrackedLine& a, const TrackedLine& b) { return a.id < b.id; });
    for (const TrackedLine& line : lines) {
      rows.push_back(
          {msg.t_us, line.id, line.segment, line.score, line.status, line.normal_velocity, line.normal_velocity_std});
    }
  }
  log.report();
  if (invalid) spdlog::warn("{}: {} invalid segment lists skipped", path.string(), invalid);
  if (!any_list) {
    throw std::runtime_error("no valid segment list on " +
                             (channel.empty() ? std::string("a LINES_* channel") : channel) + " in LCM log " +
                             path.string());
  }
  return rows;
}

}  // namespace evldt
