// Fuzz target for the checked decoding of camera information from raw LCM payload bytes. Checks: an
// accepted payload is one lcm-gen encodes back to the same bytes.

#include <algorithm>
#include <cstdint>
#include <vector>

#include "evldt/transport/messages.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  evldt::camera_info_t info;
  if (evldt::decode_message({data, size}, info) != evldt::WireError::None) return 0;
  std::vector<std::uint8_t> encoded(static_cast<std::size_t>(info.getEncodedSize()));
  evldt::fuzz::require(info.encode(encoded.data(), 0, static_cast<int>(encoded.size())) == static_cast<int>(size) &&
                           std::equal(encoded.begin(), encoded.end(), data),
                       "accepted camera information do not encode back to their bytes");
  return 0;
}
