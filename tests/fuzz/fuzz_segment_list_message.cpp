// Fuzz target for the checked decoding of segment lists from raw LCM payload bytes. Checks: an
// accepted payload is one lcm-gen encodes back to the same bytes; segments read from it are finite
// and of a known status, or the list is refused whole.

#include <cmath>
#include <cstdint>
#include <vector>

#include "evldt/transport/messages.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using evldt::fuzz::require;
  evldt::segment_list_t list;
  if (evldt::decode_message({data, size}, list) != evldt::WireError::None) return 0;
  require(list.num_segments == static_cast<std::int32_t>(list.segments.size()), "segment count differs");
  std::vector<std::uint8_t> encoded(static_cast<std::size_t>(list.getEncodedSize()));
  require(list.encode(encoded.data(), 0, static_cast<int>(encoded.size())) == static_cast<int>(size) &&
              std::equal(encoded.begin(), encoded.end(), data),
          "an accepted list does not encode back to its bytes");
  std::vector<evldt::TrackedLine> lines;
  if (!evldt::read_segment_list(list, lines)) {
    require(lines.empty(), "a refused list left segments behind");
    return 0;
  }
  require(lines.size() == list.segments.size(), "segments went missing");
  for (const evldt::TrackedLine& line : lines) {
    require(line.segment.q0.allFinite() && line.segment.q1.allFinite() && std::isfinite(line.score),
            "a non-finite segment was accepted");
  }
  return 0;
}
