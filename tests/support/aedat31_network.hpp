#pragma once
// Events as cAER / libcaer's AEDAT 3.1 network output carries them: libcaer's 20-byte network
// header (network.h: magic, sequence number, version 1, format, source id), then AEDAT 3.1
// polarity packets of at most 500 events (iniVation's AEDAT 3.1 description), a packet never
// spanning a change of the time's high bits (its overflow field holds them).

#include <cstdint>
#include <span>
#include <vector>

#include "evldt/events/event.hpp"

namespace evldt::test_support {

inline void append_le(std::vector<std::uint8_t>& bytes, std::uint64_t value, int size) {
  for (int i = 0; i < size; ++i) bytes.push_back(static_cast<std::uint8_t>(value >> (8 * i)));
}

inline std::vector<std::uint8_t> aedat31_network_stream(std::span<const Event> events) {
  std::vector<std::uint8_t> bytes;
  append_le(bytes, 0x1D378BC90B9A6658, 8);  // magic number
  append_le(bytes, 0, 8);                   // sequence number
  bytes.push_back(1);                       // version
  bytes.push_back(0);                       // format
  append_le(bytes, 1, 2);                   // source id
  for (std::size_t begin = 0; begin < events.size();) {
    std::size_t end = begin;
    while (end < events.size() && end - begin < 500 && (events[end].t >> 31) == (events[begin].t >> 31)) ++end;
    const auto count = static_cast<std::uint32_t>(end - begin);
    append_le(bytes, 1, 2);  // polarity events
    append_le(bytes, 1, 2);  // source id
    // event size, timestamp offset, overflow, capacity, number, valid
    for (const std::uint64_t field :
         {std::uint64_t{8}, std::uint64_t{4}, static_cast<std::uint64_t>(events[begin].t >> 31), std::uint64_t{count},
          std::uint64_t{count}, std::uint64_t{count}}) {
      append_le(bytes, field, 4);
    }
    for (std::size_t i = begin; i < end; ++i) {
      const Event& e = events[i];
      append_le(bytes, std::uint64_t{e.x} << 17 | std::uint64_t{e.y} << 2 | (e.p > 0 ? 2u : 0u) | 1u, 4);
      append_le(bytes, static_cast<std::uint64_t>(e.t) & 0x7FFFFFFFu, 4);
    }
    begin = end;
  }
  return bytes;
}

}  // namespace evldt::test_support
