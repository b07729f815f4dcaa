#include "evldt/events/byte_source.hpp"

#include <stdexcept>

namespace evldt {

FileBytes::FileBytes(const std::filesystem::path& path) : file_(path, std::ios::binary) {
  name_ = path.string();
  if (!file_) throw std::runtime_error("cannot open event file '" + name_ + "'");
  std::error_code size_error;
  size_ = std::filesystem::file_size(path, size_error);
  if (size_error) size_ = 0;
}

std::size_t FileBytes::read(std::span<std::uint8_t> into) {
  file_.read(reinterpret_cast<char*>(into.data()), static_cast<std::streamsize>(into.size()));
  if (file_.bad()) throw std::runtime_error("cannot read event file '" + name_ + "'");
  return static_cast<std::size_t>(file_.gcount());
}

}  // namespace evldt
