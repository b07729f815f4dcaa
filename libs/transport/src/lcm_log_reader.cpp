#include "evldt/transport/lcm_log_reader.hpp"

#include <spdlog/spdlog.h>
#include <algorithm>
#include <array>
#include <stdexcept>

namespace evldt {
namespace {

std::uint64_t load_be(const std::uint8_t* p, int bytes) {
  std::uint64_t value = 0;
  for (int i = 0; i < bytes; ++i) value = (value << 8) | p[i];
  return value;
}

}  // namespace

LcmLogReader::LcmLogReader(const std::filesystem::path& path) : path_(path), in_(path, std::ios::binary) {
  std::error_code error;
  size_ = std::filesystem::file_size(path, error);
  if (!in_ || error) throw std::runtime_error("cannot open LCM log " + path.string());
}

bool LcmLogReader::read_at(std::uint64_t at, void* out, std::size_t bytes) {
  if (at > size_ || bytes > size_ - at) return false;
  in_.clear();
  in_.seekg(static_cast<std::streamoff>(at));
  return static_cast<bool>(in_.read(static_cast<char*>(out), static_cast<std::streamsize>(bytes)));
}

std::uint64_t LcmLogReader::find_sync(std::uint64_t from) {
  constexpr std::size_t kChunk = 1 << 16;
  std::vector<std::uint8_t> chunk(kChunk + 3);
  for (std::uint64_t at = from; at + 4 <= size_; at += kChunk) {
    const std::size_t bytes = static_cast<std::size_t>(std::min<std::uint64_t>(kChunk + 3, size_ - at));
    if (!read_at(at, chunk.data(), bytes)) break;
    for (std::size_t i = 0; i + 4 <= bytes; ++i) {
      if (load_be(chunk.data() + i, 4) == kSync) return at + i;
    }
  }
  return size_;
}

void LcmLogReader::skip_to(std::uint64_t from, std::uint64_t to) {
  if (damage_.regions == 0) damage_.first_at = from;
  ++damage_.regions;
  damage_.skipped_bytes += to - from;
  position_ = to;
}

bool LcmLogReader::next(Record& record) {
  while (position_ < size_) {
    const std::uint64_t at = position_;
    std::array<std::uint8_t, kHeaderBytes> header{};
    const auto header_bytes = static_cast<std::size_t>(std::min<std::uint64_t>(kHeaderBytes, size_ - at));
    read_at(at, header.data(), header_bytes);
    // A few bytes at the end that begin a sync word begin a record cut short.
    const std::uint64_t sync_prefix = kSync >> (8 * (4 - std::min<std::size_t>(header_bytes, 4)));
    const bool synced = load_be(header.data(), static_cast<int>(std::min<std::size_t>(header_bytes, 4))) == sync_prefix;
    if (!synced) {
      skip_to(at, find_sync(at + 1));
      continue;
    }
    if (header_bytes < kHeaderBytes) {  // a header cut short by the end of the file
      damage_.cut = true;
      damage_.cut_at = at;
      position_ = size_;
      return false;
    }
    const auto channel_bytes = static_cast<std::int32_t>(load_be(header.data() + 20, 4));
    const auto data_bytes = static_cast<std::int32_t>(load_be(header.data() + 24, 4));
    if (channel_bytes <= 0 || channel_bytes >= kMaxChannelBytes || data_bytes < 0) {
      skip_to(at, find_sync(at + 1));  // a damaged header, or a sync word inside other bytes
      continue;
    }
    const std::uint64_t end =
        at + kHeaderBytes + static_cast<std::uint64_t>(channel_bytes) + static_cast<std::uint64_t>(data_bytes);
    std::uint8_t after[4] = {};
    const bool followed =
        end == size_ || (end < size_ && size_ - end >= 4 && read_at(end, after, 4) && load_be(after, 4) == kSync);
    if (!followed) {
      // Lengths that run past the next record's start, or past the end of the file, are damaged when
      // a record starts inside them; otherwise the record is whole (the bytes after it are read, and
      // counted, next) or, past the end, the last one cut short.
      const std::uint64_t inner = find_sync(at + 1);
      if (inner < std::min(end, size_)) {
        skip_to(at, inner);
        continue;
      }
      if (end > size_) {
        damage_.cut = true;
        damage_.cut_at = at;
        position_ = size_;
        return false;
      }
    }
    record.at = at;
    record.number = static_cast<std::int64_t>(load_be(header.data() + 4, 8));
    record.t_us = static_cast<Timestamp>(load_be(header.data() + 12, 8));
    record.channel.resize(static_cast<std::size_t>(channel_bytes));
    record.data.resize(static_cast<std::size_t>(data_bytes));
    read_at(at + kHeaderBytes, record.channel.data(), record.channel.size());
    read_at(at + kHeaderBytes + static_cast<std::uint64_t>(channel_bytes), record.data.data(), record.data.size());
    position_ = end;
    return true;
  }
  return false;
}

double LcmLogReader::progress() const {
  return size_ > 0 ? static_cast<double>(position_) / static_cast<double>(size_) : 1.0;
}

void LcmLogReader::report() const {
  if (damage_.regions > 0) {
    spdlog::warn("{}: {} damaged bytes skipped in {} place(s), the first at byte {}: the records there are lost",
                 path_.string(), damage_.skipped_bytes, damage_.regions, damage_.first_at);
  }
  if (damage_.cut) {
    spdlog::warn("{}: the last record (at byte {}) is cut short by the end of the file: it is lost", path_.string(),
                 damage_.cut_at);
  }
}

}  // namespace evldt
