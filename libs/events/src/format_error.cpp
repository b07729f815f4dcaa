#include "evldt/events/event_format.hpp"

namespace evldt {

FormatError::FormatError(std::string source, std::uint64_t byte_offset, const std::string& reason)
    : std::runtime_error(source + ": byte " + std::to_string(byte_offset) + ": " + reason),
      source_(std::move(source)),
      byte_offset_(byte_offset) {}

}  // namespace evldt
