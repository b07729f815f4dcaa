#include "evldt/containers/image_source.hpp"

#include <array>
#include <fstream>
#include <string_view>

#include "evldt/containers/hdf5_events.hpp"
#include "evldt/containers/hdf5_images.hpp"
#include "evldt/containers/mcap.hpp"
#include "evldt/containers/rosbag1.hpp"
#include "evldt/containers/rosbag2.hpp"

namespace evldt {

std::unique_ptr<ImageSource> open_image_container(const std::filesystem::path& path, const std::string& stream) {
  std::ifstream file(path, std::ios::binary);
  if (!file) return nullptr;
  std::array<char, 16> magic{};
  file.read(magic.data(), magic.size());
  const std::string_view start(magic.data(), static_cast<std::size_t>(file.gcount()));
  if (start.starts_with(kRosbag1Magic)) return open_rosbag1_images(path, stream);
  if (start.starts_with(kSqliteMagic)) return open_rosbag2_images(path, stream);
  if (start.starts_with(kHdf5Magic)) return open_hdf5_images(path, stream);
  if (start.starts_with(kMcapMagic)) return open_mcap_images(path, stream);
  return nullptr;
}

}  // namespace evldt
