#include "evldt/events/csv_file.hpp"

#include <algorithm>
#include <fstream>
#include <stdexcept>

namespace evldt {

CsvOutput::CsvOutput(const std::filesystem::path& path, std::string_view header) : path_(path) {
  file_ = std::fopen(path.c_str(), "w");
  if (file_ == nullptr) throw std::runtime_error("cannot create " + path.string());
  std::fprintf(file_, "%.*s\n", static_cast<int>(header.size()), header.data());
}

CsvOutput::~CsvOutput() {
  if (file_ != nullptr) std::fclose(file_);
}

std::FILE* CsvOutput::file() const {
  if (file_ == nullptr) throw std::logic_error("write to " + path_.string() + " after it was closed");
  return file_;
}

void CsvOutput::close() {
  if (file_ == nullptr) return;
  const bool failed = std::ferror(file_) != 0;
  const bool close_failed = std::fclose(file_) != 0;
  file_ = nullptr;
  if (failed || close_failed) throw std::runtime_error("error writing " + path_.string());
}

void read_csv_rows(const std::filesystem::path& path, std::string_view header,
                   const std::function<void(const std::string& row)>& parse_row) {
  const std::string_view headers[] = {header};
  read_csv_rows(path, headers, [&](std::size_t, const std::string& row) { parse_row(row); });
}

void read_csv_rows(const std::filesystem::path& path, std::span<const std::string_view> headers,
                   const std::function<void(std::size_t header, const std::string& row)>& parse_row) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot open " + path.string());
  std::string line;
  std::size_t number = 0, header = 0;
  while (std::getline(in, line)) {
    ++number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (number == 1) {
      header = static_cast<std::size_t>(std::find(headers.begin(), headers.end(), line) - headers.begin());
      if (header == headers.size()) {
        std::string message = path.string() + ":1: expected the header";
        for (std::size_t i = 0; i < headers.size(); ++i) {
          message.append(i == 0 ? " '" : " or '").append(headers[i]).append("'");
        }
        throw std::runtime_error(message);
      }
      continue;
    }
    if (line.empty()) continue;
    try {
      parse_row(header, line);
    } catch (const std::exception& e) {
      throw std::runtime_error(path.string() + ":" + std::to_string(number) + ": " + e.what());
    }
  }
}

}  // namespace evldt
