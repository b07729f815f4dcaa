#pragma once
// The bytes under a container read here by hand (AEDAT 4.0, MCAP): a file, or a live stream (a DV
// network output): exact reads that name the source and the offset where it ends early, and the
// position for progress and error messages.

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <string>

#include "evldt/events/byte_source.hpp"

namespace evldt::detail {

class ContainerInput {
 public:
  virtual ~ContainerInput() = default;
  /// Reads exactly `size` bytes; throws FormatError "<source> ends inside <what>" at the offset it ended.
  virtual void read_exactly(void* out, std::size_t size, const char* what) = 0;
  /// The same, except that an end before the first byte is the clean end of the stream: false.
  virtual bool read_exactly_or_end(void* out, std::size_t size, const char* what) = 0;
  /// Passes over `size` bytes the caller knows are there.
  virtual void skip(std::uint64_t size) = 0;
  [[nodiscard]] const std::string& path() const { return path_; }
  /// Bytes in all: a file's size; 0 for a stream (no end known).
  [[nodiscard]] virtual std::uint64_t size() const = 0;
  [[nodiscard]] std::uint64_t position() const { return position_; }

 protected:
  std::string path_;
  std::uint64_t position_ = 0;
};

class ContainerFile final : public ContainerInput {
 public:
  /// Throws std::runtime_error "cannot open <kind> file '<path>'".
  ContainerFile(const std::filesystem::path& path, const std::string& kind);
  void read_exactly(void* out, std::size_t size, const char* what) override;
  bool read_exactly_or_end(void* out, std::size_t size, const char* what) override;
  void skip(std::uint64_t size) override;
  [[nodiscard]] std::uint64_t size() const override { return size_; }

 private:
  std::ifstream stream_;
  std::uint64_t size_ = 0;
};

/// A live stream of a container's bytes.
class ContainerStream final : public ContainerInput {
 public:
  explicit ContainerStream(std::unique_ptr<ByteSource> bytes);
  void read_exactly(void* out, std::size_t size, const char* what) override;
  bool read_exactly_or_end(void* out, std::size_t size, const char* what) override;
  void skip(std::uint64_t size) override;
  [[nodiscard]] std::uint64_t size() const override { return 0; }

 private:
  std::unique_ptr<ByteSource> bytes_;
};

/// The first 16 bytes of `path` (fewer in a shorter file), by which a container is recognised;
/// nullopt when it cannot be opened.
std::optional<std::string> container_magic(const std::filesystem::path& path);

}  // namespace evldt::detail
