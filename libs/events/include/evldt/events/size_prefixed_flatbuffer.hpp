#pragma once
// A FlatBuffer with its size (uint32, little-endian) in front, as AEDAT 4.0 stores its header and
// every packet. Writers align the fields from different origins: DV finishes the buffer size-prefixed,
// so its 8-byte fields are aligned from the prefix; the aedat library (Python/Rust) finishes a plain
// buffer and puts the size in front, so they are aligned from the FlatBuffer's own first byte. A
// builder pads what it finishes to a multiple of its largest alignment, so the origin is where the
// rest of the bytes is a multiple of 8. flatbuffers' Verifier checks a table's 8-byte fields from the
// start of what it is given (not those of a vector of structs, such as DV's events), so each buffer
// is verified from that origin first, the other second, and read from a copy aligned to 8 where the
// origin is not.

#include <flatbuffers/flatbuffers.h>

#include <cstdint>
#include <cstring>
#include <span>
#include <vector>

namespace evldt {

/// The root table of type T of the size-prefixed FlatBuffer `bytes`, verified in either writer's
/// layout; nullptr if it is neither. The root may point into `scratch` (an aligned copy), which must
/// outlive its use and is reused by the next call.
template <typename T>
const T* verified_size_prefixed_root(std::span<const std::uint8_t> bytes, std::vector<std::uint64_t>& scratch) {
  constexpr std::size_t kPrefix = sizeof(flatbuffers::uoffset_t);
  // The size and at least a root offset: anything shorter holds no table (and an empty copy has no data).
  if (bytes.size() < 2 * kPrefix) return nullptr;
  std::uint32_t size = 0;
  std::memcpy(&size, bytes.data(), kPrefix);
  const bool sized_right = flatbuffers::EndianScalar(size) == bytes.size() - kPrefix;
  const auto from_origin = [&](bool at_prefix) -> const T* {
    const std::span<const std::uint8_t> from = at_prefix ? bytes : bytes.subspan(kPrefix);
    const std::uint8_t* data = from.data();
    if (reinterpret_cast<std::uintptr_t>(data) % alignof(std::uint64_t) != 0) {
      scratch.resize((from.size() + sizeof(std::uint64_t) - 1) / sizeof(std::uint64_t));
      std::memcpy(scratch.data(), from.data(), from.size());
      data = reinterpret_cast<const std::uint8_t*>(scratch.data());
    }
    flatbuffers::Verifier verifier(data, from.size());
    if (at_prefix)
      return verifier.VerifySizePrefixedBuffer<T>(nullptr) ? flatbuffers::GetSizePrefixedRoot<T>(data) : nullptr;
    return sized_right && verifier.VerifyBuffer<T>(nullptr) ? flatbuffers::GetRoot<T>(data) : nullptr;
  };
  const bool prefix_first = bytes.size() % alignof(std::uint64_t) == 0;
  if (const T* root = from_origin(prefix_first)) return root;
  return from_origin(!prefix_first);
}

}  // namespace evldt
