// mcap_channel_dump FILE TOPIC: reads one channel of an MCAP file with evldt's own reader
// (read_mcap_channel) and prints "SCHEMA_NAME SCHEMA_ENCODING MESSAGE_ENCODING COUNT", then the
// schema on one line, then each message on a line of its own (JSON messages are one line each).
#include <cstdio>
#include <exception>

#include "evldt/containers/mcap.hpp"

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: mcap_channel_dump FILE TOPIC\n");
    return 2;
  }
  try {
    const evldt::McapChannelMessages channel = evldt::read_mcap_channel(argv[1], argv[2]);
    std::printf("%s %s %s %zu\n%s\n", channel.schema_name.c_str(), channel.schema_encoding.c_str(),
                channel.message_encoding.c_str(), channel.messages.size(), channel.schema.c_str());
    for (const auto& message : channel.messages) std::printf("%s\n", message.data.c_str());
  } catch (const std::exception& error) {
    std::fprintf(stderr, "mcap_channel_dump: %s\n", error.what());
    return 1;
  }
  return 0;
}
