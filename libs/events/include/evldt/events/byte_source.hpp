#pragma once
// Where a recording's bytes come from, apart from how they encode events (the decoders): a finished
// file here; a file that grows while a recorder writes it, standard input and a TCP stream in
// evldt/sources/live_bytes.hpp. EventStreamReader parses a header and decodes from any of them.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <memory>
#include <span>
#include <string>

namespace evldt {

class ByteSource {
 public:
  virtual ~ByteSource() = default;
  /// Fills the front of `into` with the next bytes and returns how many: at least one, or 0 once the
  /// stream has ended (a live source waits, without using the CPU, until bytes come or it ends).
  /// Throws std::runtime_error, naming the source, when it cannot be read.
  virtual std::size_t read(std::span<std::uint8_t> into) = 0;
  /// Bytes in all where known now (a finished file's size), else 0: for progress.
  [[nodiscard]] virtual std::uint64_t size() const { return 0; }
  /// The path or address, for messages.
  [[nodiscard]] const std::string& name() const { return name_; }

 protected:
  std::string name_;
};

/// A finished file. Throws std::runtime_error naming the path if it cannot be opened.
class FileBytes final : public ByteSource {
 public:
  explicit FileBytes(const std::filesystem::path& path);
  std::size_t read(std::span<std::uint8_t> into) override;
  [[nodiscard]] std::uint64_t size() const override { return size_; }

 private:
  std::ifstream file_;
  std::uint64_t size_ = 0;
};

}  // namespace evldt
