#pragma once
// The MCAP record types evldt reads and writes (MCAP specification, major version 0), shared by the
// reader (mcap.cpp), which skips the others, and the writer (mcap_writer.cpp).

#include <cstdint>

namespace evldt::detail {

enum McapOpcode : std::uint8_t {
  kMcapHeader = 0x01,
  kMcapFooter = 0x02,
  kMcapSchema = 0x03,
  kMcapChannel = 0x04,
  kMcapMessage = 0x05,
  kMcapChunk = 0x06,
  kMcapDataEnd = 0x0F
};

}  // namespace evldt::detail
