#include "container_file.hpp"

#include <fstream>
#include <span>
#include <stdexcept>
#include <vector>

#include "evldt/events/event_format.hpp"

namespace evldt::detail {

ContainerFile::ContainerFile(const std::filesystem::path& path, const std::string& kind)
    : stream_(path, std::ios::binary) {
  path_ = path.string();
  if (!stream_) throw std::runtime_error("cannot open " + kind + " file '" + path_ + "'");
  std::error_code size_error;
  size_ = std::filesystem::file_size(path, size_error);
}

void ContainerFile::read_exactly(void* out, std::size_t size, const char* what) {
  if (!read_exactly_or_end(out, size, what))
    throw FormatError(path_, position_, std::string("file ends inside ") + what);
}

bool ContainerFile::read_exactly_or_end(void* out, std::size_t size, const char* what) {
  stream_.read(static_cast<char*>(out), static_cast<std::streamsize>(size));
  const auto got = static_cast<std::size_t>(stream_.gcount());
  if (got == 0 && size > 0) return false;
  if (got != size) throw FormatError(path_, position_ + got, std::string("file ends inside ") + what);
  position_ += size;
  return true;
}

void ContainerFile::skip(std::uint64_t size) {
  stream_.seekg(static_cast<std::streamoff>(size), std::ios::cur);
  position_ += size;
}

ContainerStream::ContainerStream(std::unique_ptr<ByteSource> bytes) : bytes_(std::move(bytes)) {
  path_ = bytes_->name();
}

void ContainerStream::read_exactly(void* out, std::size_t size, const char* what) {
  if (!read_exactly_or_end(out, size, what))
    throw FormatError(path_, position_, std::string("stream ends inside ") + what);
}

bool ContainerStream::read_exactly_or_end(void* out, std::size_t size, const char* what) {
  auto* const into = static_cast<std::uint8_t*>(out);
  std::size_t got = 0;
  while (got < size) {
    const std::size_t n = bytes_->read(std::span(into + got, size - got));
    if (n == 0) {
      if (got == 0) return false;
      throw FormatError(path_, position_ + got, std::string("stream ends inside ") + what);
    }
    got += n;
  }
  position_ += size;
  return true;
}

void ContainerStream::skip(std::uint64_t size) {
  std::vector<std::uint8_t> discarded(static_cast<std::size_t>(std::min<std::uint64_t>(size, 1 << 16)));
  for (std::uint64_t left = size; left > 0;) {
    const auto part = static_cast<std::size_t>(std::min<std::uint64_t>(left, discarded.size()));
    read_exactly(discarded.data(), part, "a skipped packet");
    left -= part;
  }
}

std::optional<std::string> container_magic(const std::filesystem::path& path) {
  std::ifstream file(path, std::ios::binary);
  if (!file) return std::nullopt;
  std::string magic(16, '\0');
  file.read(magic.data(), static_cast<std::streamsize>(magic.size()));
  magic.resize(static_cast<std::size_t>(file.gcount()));
  return magic;
}

}  // namespace evldt::detail
