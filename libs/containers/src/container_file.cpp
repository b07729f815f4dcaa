#include "container_file.hpp"

#include <stdexcept>

#include "evldt/events/event_format.hpp"

namespace evldt::detail {

ContainerFile::ContainerFile(const std::filesystem::path& path, const std::string& kind)
    : path_(path.string()), stream_(path, std::ios::binary) {
  if (!stream_) throw std::runtime_error("cannot open " + kind + " file '" + path_ + "'");
  std::error_code size_error;
  size_ = std::filesystem::file_size(path, size_error);
}

void ContainerFile::read_exactly(void* out, std::size_t size, const char* what) {
  stream_.read(static_cast<char*>(out), static_cast<std::streamsize>(size));
  if (static_cast<std::size_t>(stream_.gcount()) != size) {
    throw FormatError(path_, position_ + static_cast<std::uint64_t>(stream_.gcount()), std::string("file ends inside ") + what);
  }
  position_ += size;
}

void ContainerFile::skip(std::uint64_t size) {
  stream_.seekg(static_cast<std::streamoff>(size), std::ios::cur);
  position_ += size;
}

}  // namespace evldt::detail
