#pragma once
// What every fuzz target shares: a check that aborts (so libFuzzer records the input as a crash,
// and the corpus replay in ctest fails), and a private temporary file for readers that take a path.

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <span>
#include <string>

#include "evldt/events/event_format.hpp"

namespace evldt::fuzz {

inline void require(bool condition, const char* what) {
  if (!condition) {
    std::fprintf(stderr, "fuzz check failed: %s\n", what);
    std::abort();
  }
}

/// Reads everything a recording reader gives, checking that it returns events whenever it says it
/// did and that it stops for good after a FormatError.
template <typename Reader, typename Batch>
void read_to_the_end(Reader& reader, Batch& batch) {
  bool failed = false;
  try {
    while (reader.read(batch)) require(!batch.empty(), "read() returned true with no events");
  } catch (const FormatError&) {
    failed = true;
  }
  if (failed) require(!reader.read(batch) && batch.empty(), "the reader went on after its error");
}

/// A file in the temporary directory holding the bytes under test, removed on destruction.
class TempFile {
 public:
  TempFile(std::span<const std::uint8_t> bytes, const std::string& extension)
      : path_(std::filesystem::temp_directory_path() / ("evldt-fuzz-" + std::to_string(::getpid()) + extension)) {
    std::ofstream out(path_, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
    require(static_cast<bool>(out), "cannot write the temporary file");
  }
  ~TempFile() {
    std::error_code ignored;
    std::filesystem::remove(path_, ignored);
  }
  TempFile(const TempFile&) = delete;
  TempFile& operator=(const TempFile&) = delete;

  [[nodiscard]] const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

}  // namespace evldt::fuzz
