#pragma once
// An AEDAT 4.0 file as DV's network output streams it: the size-prefixed IOHeader and the packets,
// without the version line and the data table. Needs the generated IOHeader reader
// (evldt_flatbuffers of libs/containers/schemas/aedat4_header.fbs).

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string_view>
#include <utility>
#include <vector>

#include "aedat4_header_generated.h"

namespace evldt::test_support {

class DvFraming {
 public:
  explicit DvFraming(const std::filesystem::path& path) {
    std::ifstream in(path, std::ios::binary);
    bytes_.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    const std::size_t at = std::string_view("#!AER-DAT4.0\r\n").size();
    if (bytes_.size() < at + 4) return;
    const std::uint32_t size = load_le32(bytes_.data() + at);
    header_.assign(bytes_.begin() + static_cast<std::ptrdiff_t>(at),
                   bytes_.begin() + static_cast<std::ptrdiff_t>(at + 4 + size));
    const auto* io = aedat4::GetSizePrefixedIOHeader(header_.data());
    const auto end = io->dataTablePosition() >= 0 ? static_cast<std::size_t>(io->dataTablePosition()) : bytes_.size();
    for (std::size_t packet = at + 4 + size; packet + 8 <= end;) {
      const std::size_t length = 8 + load_le32(bytes_.data() + packet + 4);
      packets_.emplace_back(packet, length);
      packet += length;
    }
  }
  [[nodiscard]] std::size_t packets() const { return packets_.size(); }
  /// The header, then packets [first, last): what one connection of the server sends.
  [[nodiscard]] std::vector<std::uint8_t> stream(std::size_t first, std::size_t last) const {
    std::vector<std::uint8_t> out = header_;
    for (std::size_t i = first; i < last; ++i) {
      const auto [offset, length] = packets_[i];
      out.insert(out.end(), bytes_.begin() + static_cast<std::ptrdiff_t>(offset),
                 bytes_.begin() + static_cast<std::ptrdiff_t>(offset + length));
    }
    return out;
  }

 private:
  static std::uint32_t load_le32(const std::uint8_t* p) {
    return static_cast<std::uint32_t>(p[0]) | static_cast<std::uint32_t>(p[1]) << 8 |
           static_cast<std::uint32_t>(p[2]) << 16 | static_cast<std::uint32_t>(p[3]) << 24;
  }

  std::vector<std::uint8_t> bytes_;
  std::vector<std::uint8_t> header_;                          // size prefix and IOHeader
  std::vector<std::pair<std::size_t, std::size_t>> packets_;  // offset and length of each, its header included
};

}  // namespace evldt::test_support
