// Fuzz target for one recording decoder (EVLDT_FUZZ_FORMAT: EcdText, Evt2, Evt3 or Dat). The first
// input byte sets a chunk size; the rest is the recording. Checks: only FormatError ever escapes,
// and decoding the bytes whole or cut into chunks gives the same events, sensor size and error
// (the decoder's contract: a chunk boundary may fall anywhere).

#include <cstdint>
#include <optional>
#include <span>
#include <string>

#include "evldt/events/event_decoder.hpp"
#include "fuzz_support.hpp"

namespace {

struct Outcome {
  evldt::EventBatch events;
  std::optional<evldt::SensorSize> geometry;
  std::optional<std::uint64_t> error_offset;
  std::string error;
};

Outcome decode_in_chunks(std::span<const std::uint8_t> bytes, std::size_t chunk_bytes) {
  Outcome outcome;
  const auto decoder = evldt::make_decoder(evldt::EventFormat::EVLDT_FUZZ_FORMAT, "fuzz");
  try {
    for (std::size_t at = 0; at < bytes.size(); at += chunk_bytes) {
      decoder->decode(bytes.subspan(at, std::min(chunk_bytes, bytes.size() - at)), outcome.events);
    }
    decoder->finish(outcome.events);
  } catch (const evldt::FormatError& error) {
    outcome.error_offset = error.byte_offset();
    outcome.error = error.what();
  }
  outcome.geometry = decoder->geometry();
  return outcome;
}

bool same_events(const evldt::EventBatch& a, const evldt::EventBatch& b) {
  return a.t == b.t && a.x == b.x && a.y == b.y && a.p == b.p;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::size_t chunk_bytes = std::size_t{data[0]} + 1;
  const std::span<const std::uint8_t> recording(data + 1, size - 1);
  const Outcome whole = decode_in_chunks(recording, recording.size() + 1);
  const Outcome chunked = decode_in_chunks(recording, chunk_bytes);
  using evldt::fuzz::require;
  require(same_events(whole.events, chunked.events), "events depend on the chunk size");
  require(whole.geometry == chunked.geometry, "sensor size depends on the chunk size");
  require(whole.error_offset == chunked.error_offset, "error offset depends on the chunk size");
  require(whole.error == chunked.error, "error message depends on the chunk size");
  for (const std::int8_t polarity : whole.events.p) require(polarity == 1 || polarity == -1, "polarity not +-1");
  return 0;
}
