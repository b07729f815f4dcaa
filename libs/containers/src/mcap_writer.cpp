#include "evldt/containers/mcap_writer.hpp"

#include <spdlog/spdlog.h>

#include <stdexcept>

#include "evldt/containers/mcap.hpp"
#include "mcap_records.hpp"

namespace evldt {
namespace {

void put_le(std::string& out, std::uint64_t value, int bytes) {
  for (int i = 0; i < bytes; ++i) out += static_cast<char>(value >> (8 * i));
}

/// A string or byte array: uint32 length, then the bytes.
void put_bytes(std::string& out, std::string_view bytes) {
  if (bytes.size() > UINT32_MAX) throw std::invalid_argument("MCAP field longer than 4 GiB");
  put_le(out, bytes.size(), 4);
  out += bytes;
}

}  // namespace

McapWriter::McapWriter(const std::filesystem::path& path, const std::string& profile)
    : path_(path), out_(path, std::ios::binary | std::ios::trunc) {
  if (!out_) throw std::runtime_error("cannot create '" + path.string() + "'");
  out_.write(kMcapMagic.data(), static_cast<std::streamsize>(kMcapMagic.size()));
  std::string header;
  put_bytes(header, profile);
  put_bytes(header, "evldt");
  record(detail::kMcapHeader, header);
}

McapWriter::~McapWriter() {
  if (closed_) return;
  try {
    close();
  } catch (const std::exception& error) {
    spdlog::error("{}", error.what());
  }
}

std::uint16_t McapWriter::add_schema(const std::string& name, const std::string& encoding, std::string_view data) {
  if (schemas_ == UINT16_MAX) throw std::length_error("MCAP: too many schemas");
  const std::uint16_t id = ++schemas_;
  scratch_.clear();
  put_le(scratch_, id, 2);
  put_bytes(scratch_, name);
  put_bytes(scratch_, encoding);
  put_bytes(scratch_, data);
  record(detail::kMcapSchema, scratch_);
  return id;
}

std::uint16_t McapWriter::add_channel(std::uint16_t schema, const std::string& topic,
                                      const std::string& message_encoding) {
  if (schema > schemas_) throw std::invalid_argument("MCAP: channel " + topic + " of a schema not added");
  if (channels_ == UINT16_MAX) throw std::length_error("MCAP: too many channels");
  const std::uint16_t id = channels_++;
  scratch_.clear();
  put_le(scratch_, id, 2);
  put_le(scratch_, schema, 2);
  put_bytes(scratch_, topic);
  put_bytes(scratch_, message_encoding);
  put_le(scratch_, 0, 4);  // metadata: an empty map
  record(detail::kMcapChannel, scratch_);
  return id;
}

void McapWriter::write(std::uint16_t channel, std::uint64_t time_ns, std::string_view data) {
  if (channel >= channels_) throw std::invalid_argument("MCAP: message on a channel not added");
  scratch_.clear();
  put_le(scratch_, channel, 2);
  put_le(scratch_, sequence_[channel]++, 4);
  put_le(scratch_, time_ns, 8);  // log time
  put_le(scratch_, time_ns, 8);  // publish time
  scratch_ += data;
  record(detail::kMcapMessage, scratch_);
  ++messages_;
}

void McapWriter::close() {
  if (closed_) return;
  closed_ = true;
  std::string content;
  put_le(content, 0, 4);  // data section CRC: not computed
  record(detail::kMcapDataEnd, content);
  content.clear();
  put_le(content, 0, 8);  // no summary section
  put_le(content, 0, 8);  // no summary offsets
  put_le(content, 0, 4);  // summary CRC: none
  record(detail::kMcapFooter, content);
  out_.write(kMcapMagic.data(), static_cast<std::streamsize>(kMcapMagic.size()));
  out_.close();
  if (!out_) throw std::runtime_error("could not write '" + path_.string() + "' (disk full?)");
}

void McapWriter::record(std::uint8_t opcode, const std::string& content) {
  std::string header(1, static_cast<char>(opcode));
  put_le(header, content.size(), 8);
  out_.write(header.data(), static_cast<std::streamsize>(header.size()));
  out_.write(content.data(), static_cast<std::streamsize>(content.size()));
}

}  // namespace evldt
