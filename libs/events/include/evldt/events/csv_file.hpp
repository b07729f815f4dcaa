#pragma once
// The plumbing shared by evldt's CSV outputs (segments, ground truth): a file that starts with a
// fixed header, and reading one back row by row with errors that name the file and line.

#include <cstdio>
#include <filesystem>
#include <functional>
#include <span>
#include <string>
#include <string_view>

namespace evldt {

class CsvOutput {
 public:
  /// Creates the file and writes the header line; throws std::runtime_error naming the path.
  CsvOutput(const std::filesystem::path& path, std::string_view header);
  ~CsvOutput();
  CsvOutput(const CsvOutput&) = delete;
  CsvOutput& operator=(const CsvOutput&) = delete;
  /// The open file; throws std::logic_error after close() instead of handing out a null stream.
  [[nodiscard]] std::FILE* file() const;
  /// Flushes and checks for write errors (throws std::runtime_error); idempotent.
  void close();

 private:
  std::filesystem::path path_;
  std::FILE* file_ = nullptr;
};

/// Calls parse_row for each non-empty data row after checking the header line. An exception from
/// parse_row, or a wrong header, becomes std::runtime_error "path:line: what".
void read_csv_rows(const std::filesystem::path& path, std::string_view header,
                   const std::function<void(const std::string& row)>& parse_row);
/// As above for a file that may have any of `headers` (a format that grew columns); parse_row is
/// told which one the file has (its index).
void read_csv_rows(const std::filesystem::path& path, std::span<const std::string_view> headers,
                   const std::function<void(std::size_t header, const std::string& row)>& parse_row);

}  // namespace evldt
