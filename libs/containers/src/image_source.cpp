#include "evldt/containers/image_source.hpp"

#include <string_view>

#include "container_file.hpp"
#include "evldt/containers/aedat4.hpp"
#include "evldt/containers/aedat_images.hpp"
#include "evldt/containers/hdf5_events.hpp"
#include "evldt/containers/hdf5_images.hpp"
#include "evldt/containers/mcap.hpp"
#include "evldt/containers/rosbag1.hpp"
#include "evldt/containers/rosbag2.hpp"

namespace evldt {

std::unique_ptr<ImageSource> open_image_container(const std::filesystem::path& path, const std::string& stream) {
  const auto magic = detail::container_magic(path);
  if (!magic) return nullptr;
  const std::string_view start = *magic;
  if (start.starts_with(kRosbag1Magic)) return open_rosbag1_images(path, stream);
  if (start.starts_with(kSqliteMagic)) return open_rosbag2_images(path, stream);
  if (start.starts_with(kHdf5Magic)) return open_hdf5_images(path, stream);
  if (start.starts_with(kMcapMagic)) return open_mcap_images(path, stream);
  if (start.starts_with(kAedat4Magic)) return open_aedat4_images(path);
  if (start.starts_with(kAedat31Magic)) return open_aedat31_images(path);
  if (start.starts_with(kAedat2Magic)) return open_aedat2_images(path);
  return nullptr;
}

}  // namespace evldt
