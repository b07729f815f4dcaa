// Fuzz target for EventStreamReader: the first input byte picks the file name's extension (.txt, .dat,
// .raw: the format guessed as evldt-offline guesses it, .raw from its header) and the chunk size;
// the rest is the file. Checks: only std::runtime_error (FormatError or a refused file) escapes,
// the reader stops for good after an error, and it never reads more bytes than the file has.

#include <array>
#include <cstdint>
#include <stdexcept>

#include "evldt/events/event_stream_reader.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  static constexpr std::array<const char*, 3> kExtensions = {".txt", ".dat", ".raw"};
  const char* extension = kExtensions[data[0] % kExtensions.size()];
  const std::size_t chunk_bytes = std::size_t{data[0] / 3u} + 1;
  const evldt::fuzz::TempFile file({data + 1, size - 1}, extension);
  using evldt::fuzz::require;
  try {
    evldt::EventStreamReader reader(file.path(), {}, chunk_bytes);
    evldt::EventBatch batch;
    evldt::fuzz::read_to_the_end(reader, batch);
    require(reader.bytes_read() <= size - 1, "read more bytes than the file has");
  } catch (const std::runtime_error&) {
    // A file the reader refuses: the error names it; that is the expected outcome for most inputs.
  }
  return 0;
}
