#include "decompress.hpp"

#include <lz4frame.h>
#include <zstd.h>

#include <algorithm>
#include <memory>
#include <stdexcept>
#include <string>

namespace evldt::detail {
namespace {

// The content size in a frame header is optional, so the output starts at a guess and grows.
void start_output(std::span<const std::uint8_t> in, std::vector<std::uint8_t>& out) {
  out.resize(std::clamp<std::size_t>(in.size() * 4, 1024, kMaxDecompressedBytes));
}

void grow(std::vector<std::uint8_t>& out) {
  if (out.size() >= kMaxDecompressedBytes) throw std::runtime_error("decompresses to more than 256 MiB");
  out.resize(std::min(out.size() * 2, kMaxDecompressedBytes));
}

}  // namespace

void decompress_lz4_frame(std::span<const std::uint8_t> in, std::vector<std::uint8_t>& out) {
  LZ4F_dctx* context = nullptr;
  if (LZ4F_isError(LZ4F_createDecompressionContext(&context, LZ4F_VERSION)))
    throw std::runtime_error("LZ4: out of memory");
  const std::unique_ptr<LZ4F_dctx, decltype(&LZ4F_freeDecompressionContext)> owner(context,
                                                                                   LZ4F_freeDecompressionContext);
  start_output(in, out);
  std::size_t in_at = 0, out_at = 0;
  while (true) {
    std::size_t in_size = in.size() - in_at, out_size = out.size() - out_at;
    const std::size_t hint =
        LZ4F_decompress(context, out.data() + out_at, &out_size, in.data() + in_at, &in_size, nullptr);
    if (LZ4F_isError(hint)) throw std::runtime_error(std::string("LZ4: ") + LZ4F_getErrorName(hint));
    in_at += in_size;
    out_at += out_size;
    if (hint == 0) break;  // the frame is complete
    if (in_at == in.size() && out_size == 0 && in_size == 0) throw std::runtime_error("LZ4: the frame is cut short");
    if (out_at == out.size()) grow(out);
  }
  out.resize(out_at);
}

void decompress_zstd_frame(std::span<const std::uint8_t> in, std::vector<std::uint8_t>& out) {
  const std::unique_ptr<ZSTD_DCtx, decltype(&ZSTD_freeDCtx)> context(ZSTD_createDCtx(), ZSTD_freeDCtx);
  if (!context) throw std::runtime_error("Zstandard: out of memory");
  start_output(in, out);
  ZSTD_inBuffer input{in.data(), in.size(), 0};
  std::size_t out_at = 0;
  while (true) {
    ZSTD_outBuffer output{out.data() + out_at, out.size() - out_at, 0};
    const std::size_t hint = ZSTD_decompressStream(context.get(), &output, &input);
    if (ZSTD_isError(hint)) throw std::runtime_error(std::string("Zstandard: ") + ZSTD_getErrorName(hint));
    out_at += output.pos;
    if (hint == 0) break;  // the frame is complete
    if (input.pos == input.size && output.pos < output.size)
      throw std::runtime_error("Zstandard: the frame is cut short");
    if (out_at == out.size()) grow(out);
  }
  out.resize(out_at);
}

}  // namespace evldt::detail
