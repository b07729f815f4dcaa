#pragma once
// The file under a container read here by hand (AEDAT 4.0, MCAP): exact reads that name the file
// and the offset where it ends early, and the position for progress and error messages.

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

namespace evldt::detail {

class ContainerFile {
 public:
  /// Throws std::runtime_error "cannot open <kind> file '<path>'".
  ContainerFile(const std::filesystem::path& path, const std::string& kind);
  /// Reads exactly `size` bytes; throws FormatError "file ends inside <what>" at the offset it ended.
  void read_exactly(void* out, std::size_t size, const char* what);
  /// Passes over `size` bytes the caller knows are in the file.
  void skip(std::uint64_t size);
  [[nodiscard]] const std::string& path() const { return path_; }
  [[nodiscard]] std::uint64_t size() const { return size_; }
  [[nodiscard]] std::uint64_t position() const { return position_; }

 private:
  std::string path_;
  std::ifstream stream_;
  std::uint64_t size_ = 0;
  std::uint64_t position_ = 0;
};

}  // namespace evldt::detail
