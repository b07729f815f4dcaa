#pragma once
// One compressed frame (LZ4 frame format, Zstandard) into a buffer, for the containers whose
// packets or chunks are compressed (AEDAT 4.0 packets, MCAP chunks).

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace evldt::detail {

// Output larger than this is refused: no recorder writes such a packet or chunk, and a forged size
// must not make a reader allocate without bound.
inline constexpr std::size_t kMaxDecompressedBytes = std::size_t{256} << 20;

/// Replaces `out` with the content of the LZ4 frame `in`. Throws std::runtime_error ("LZ4: reason")
/// for a frame that is corrupt, cut short or larger than kMaxDecompressedBytes.
void decompress_lz4_frame(std::span<const std::uint8_t> in, std::vector<std::uint8_t>& out);
/// The same for a Zstandard frame ("Zstandard: reason").
void decompress_zstd_frame(std::span<const std::uint8_t> in, std::vector<std::uint8_t>& out);

}  // namespace evldt::detail
