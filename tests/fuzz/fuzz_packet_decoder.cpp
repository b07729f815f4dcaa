// Fuzz target for the packet decoders of container encodings. The first input byte picks the
// encoding (evt2, evt3, libcaer, libcaer_cmp, dv_events, dvs_events, mono) and the chunk size, the next 8 bytes are a
// time base; the rest is one packet, decoded twice. Checks: only FormatError escapes, and for the
// stream encodings the events do not depend on where chunks are cut (dv_events takes a packet whole).

#include <array>
#include <cstring>
#include <string>

#include "evldt/events/event_decoder.hpp"
#include "fuzz_support.hpp"

namespace {

constexpr std::array<const char*, 7> kEncodings = {"evt2",      "evt3",       "libcaer", "libcaer_cmp",
                                                   "dv_events", "dvs_events", "mono"};

struct Outcome {
  evldt::EventBatch events;
  std::string error;
};

Outcome decode(const char* encoding, std::int64_t time_base, std::span<const std::uint8_t> packet,
               std::size_t chunk_bytes) {
  Outcome outcome;
  const auto decoder = evldt::make_packet_decoder(encoding, "fuzz");
  evldt::fuzz::require(decoder != nullptr, "no decoder for a listed encoding");
  try {
    decoder->start_packet(time_base);
    for (std::size_t at = 0; at < packet.size(); at += chunk_bytes) {
      decoder->decode(packet.subspan(at, std::min(chunk_bytes, packet.size() - at)), outcome.events);
    }
    decoder->finish(outcome.events);
  } catch (const evldt::FormatError& error) {
    outcome.error = error.what();
  }
  return outcome;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 9) return 0;
  const char* encoding = kEncodings[data[0] % kEncodings.size()];
  const bool whole_packets = std::string(encoding) == "dv_events";
  std::int64_t time_base = 0;
  std::memcpy(&time_base, data + 1, sizeof(time_base));
  const std::span<const std::uint8_t> packet(data + 9, size - 9);
  const Outcome whole = decode(encoding, time_base, packet, packet.size() + 1);
  using evldt::fuzz::require;
  for (const std::int8_t polarity : whole.events.p) require(polarity == 1 || polarity == -1, "polarity not +-1");
  if (!whole_packets) {
    const Outcome chunked = decode(encoding, time_base, packet, std::size_t{data[0] / kEncodings.size()} + 1);
    require(whole.events.t == chunked.events.t && whole.events.x == chunked.events.x &&
                whole.events.y == chunked.events.y && whole.events.p == chunked.events.p,
            "events depend on the chunk size");
    require(whole.error == chunked.error, "the error depends on the chunk size");
  }
  return 0;
}
