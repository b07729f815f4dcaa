#pragma once
// An lcm-logger file, read record by record, with every damage counted and said. LCM's own LogFile
// skips bytes it cannot read and takes a cut last record for the end without a word, so a log with
// a damaged stretch read as a whole one. The format (LCM's event log): each record is a
// big-endian header - sync word 0xEDA1DA01, event number (int64), time (int64, us), channel length
// (int32), data length (int32) - then the channel name and the data.

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "evldt/events/event.hpp"

namespace evldt {

/// What a log reader could not read.
struct LogDamage {
  std::uint64_t regions = 0;        ///< stretches of bytes skipped to find the next record
  std::uint64_t skipped_bytes = 0;  ///< in those stretches
  std::uint64_t first_at = 0;       ///< byte where the first stretch starts
  std::uint64_t cut_at = 0;         ///< byte where a record cut short by the end of the file starts
  bool cut = false;                 ///< the last record is cut short (a log still being written, or cut)
  [[nodiscard]] bool any() const { return regions > 0 || cut; }
};

class LcmLogReader {
 public:
  struct Record {
    std::int64_t number = 0;
    Timestamp t_us = 0;  ///< when the logger received it
    std::string channel;
    std::vector<std::uint8_t> data;
    std::uint64_t at = 0;  ///< byte where the record starts
  };

  /// Throws std::runtime_error naming the file if it cannot be opened.
  explicit LcmLogReader(const std::filesystem::path& path);

  /// The next whole record (one followed by another's sync word or by the end of the file); false
  /// at the end. Bytes that are no record are skipped to the next sync word and counted.
  bool next(Record& record);

  [[nodiscard]] const LogDamage& damage() const { return damage_; }
  [[nodiscard]] const std::filesystem::path& path() const { return path_; }
  /// Fraction of the file read.
  [[nodiscard]] double progress() const;
  /// Once reading is done: a warning of what was skipped (nothing when the log was whole).
  void report() const;

  static constexpr std::uint32_t kSync = 0xEDA1DA01;
  static constexpr std::size_t kHeaderBytes = 28;
  static constexpr std::int32_t kMaxChannelBytes = 1000;  ///< LCM's own reader refuses longer names

 private:
  bool read_at(std::uint64_t at, void* out, std::size_t bytes);
  /// The next byte at or after `from` where a sync word starts, or the file's size.
  std::uint64_t find_sync(std::uint64_t from);
  void skip_to(std::uint64_t from, std::uint64_t to);

  std::filesystem::path path_;
  std::ifstream in_;
  std::uint64_t size_ = 0;
  std::uint64_t position_ = 0;
  LogDamage damage_;
};

}  // namespace evldt
