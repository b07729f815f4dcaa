#include "evldt/events/event_stream_reader.hpp"

#include <algorithm>
#include <stdexcept>
#include <utility>

namespace evldt {

std::unique_ptr<EventDecoder> make_decoder(EventFormat format, std::string source_name) {
  switch (format) {
    case EventFormat::EcdText:
      return detail::make_ecd_text_decoder(std::move(source_name));
    case EventFormat::Evt2:
      return detail::make_evt2_decoder(std::move(source_name), RawFraming::WithHeader);
    case EventFormat::Evt3:
      return detail::make_evt3_decoder(std::move(source_name), RawFraming::WithHeader);
    case EventFormat::Evt21:
      return detail::make_evt21_decoder(std::move(source_name));
    case EventFormat::Dat:
      return detail::make_dat_decoder(std::move(source_name));
    case EventFormat::Aedat2:
      return detail::make_aedat2_decoder(std::move(source_name));
    case EventFormat::Aedat31:
      return detail::make_aedat31_decoder(std::move(source_name));
    case EventFormat::Aedat31Network:
      return detail::make_aedat31_network_decoder(std::move(source_name));
    case EventFormat::EventStream:
      return detail::make_event_stream_decoder(std::move(source_name));
  }
  throw std::invalid_argument("unknown event format");
}

std::unique_ptr<EventDecoder> make_packet_decoder(std::string_view encoding, std::string source_name) {
  if (encoding == "evt3") return detail::make_evt3_decoder(std::move(source_name), RawFraming::BareWords);
  if (encoding == "evt2") return detail::make_evt2_decoder(std::move(source_name), RawFraming::BareWords);
  if (encoding == "libcaer") return detail::make_libcaer_decoder(std::move(source_name));
  if (encoding == "libcaer_cmp") return detail::make_libcaer_compressed_decoder(std::move(source_name));
  if (encoding == "dv_events") return detail::make_dv_events_decoder(std::move(source_name));
  if (encoding == "dvs_events") return detail::make_dvs_events_decoder(std::move(source_name));
  if (encoding == "mono") return detail::make_mono_decoder(std::move(source_name));
  return nullptr;
}

namespace {

std::string lowercase(std::string text) {
  std::ranges::transform(text, text.begin(),
                         [](char c) { return (c >= 'A' && c <= 'Z') ? static_cast<char>(c - 'A' + 'a') : c; });
  return text;
}

}  // namespace

EventStreamReader::EventStreamReader(const std::filesystem::path& path, std::optional<EventFormat> format,
                                     std::size_t chunk_bytes)
    : EventStreamReader(std::make_unique<FileBytes>(path), format, path.extension().string(), chunk_bytes) {}

EventStreamReader::EventStreamReader(std::unique_ptr<ByteSource> bytes, std::optional<EventFormat> format,
                                     std::string_view extension, std::size_t chunk_bytes)
    : bytes_(std::move(bytes)), chunk_(std::max<std::size_t>(chunk_bytes, 1)) {
  const std::string& source = bytes_->name();
  // The first bytes, kept: a stream cannot be read twice.
  constexpr std::size_t kMagicBytes = 20;  // also where an Event Stream header's sensor size ends
  std::vector<std::uint8_t> header_bytes;
  const auto read_more = [&] {
    const std::size_t size = read_chunk();
    header_bytes.insert(header_bytes.end(), chunk_.begin(), chunk_.begin() + static_cast<std::ptrdiff_t>(size));
    return size;
  };
  while (header_bytes.size() < kMagicBytes && read_more() > 0) {
  }
  // AEDAT and Event Stream files say what they are in their first bytes, whatever their name.
  if (!format) {
    const std::string_view start(reinterpret_cast<const char*>(header_bytes.data()), header_bytes.size());
    if (start.starts_with("#!AER-DAT2")) format = EventFormat::Aedat2;
    if (start.starts_with("#!AER-DAT3")) format = EventFormat::Aedat31;
    if (start.starts_with("Event Stream")) format = EventFormat::EventStream;
    if (detail::starts_as_aedat31_network(header_bytes)) format = EventFormat::Aedat31Network;
  }
  const std::string lower_extension = lowercase(std::string(extension));
  const bool format_from_header = !format && (lower_extension == ".raw" || lower_extension.empty());
  if (!format && !format_from_header) {
    if (lower_extension == ".txt") {
      format = EventFormat::EcdText;
    } else if (lower_extension == ".dat") {
      format = EventFormat::Dat;
    } else {
      throw std::runtime_error("cannot tell the format of '" + source +
                               "' from its name: give it (ecd, evt2, evt3, evt21, dat)");
    }
  }

  // Read the text header now so that format() and geometry() are known before the first read().
  if (format != EventFormat::EcdText && format != EventFormat::EventStream && format != EventFormat::Aedat31Network) {
    detail::TextHeader header(format == EventFormat::Aedat2 || format == EventFormat::Aedat31 ? '#' : '%');
    std::size_t consumed = 0;
    for (;;) {
      consumed += header.consume(std::span(header_bytes).subspan(consumed), source);
      if (header.complete() || read_more() == 0) break;
    }
    if (format_from_header) {
      const auto encoding = header.encoding();
      if (!encoding)
        throw FormatError(source, 0, "no '% evt' or '% format' header line tells the EVT version; give the format");
      format = detail::raw_format_from_encoding(*encoding);
      if (!format)
        throw FormatError(source, 0, "the header names the encoding " + *encoding + ", not EVT2, EVT21 or EVT3");
    }
  }
  format_ = *format;
  decoder_ = make_decoder(format_, source);
  // The chunk(s) read with the header may hold events (and faults): keep them for read().
  try {
    decoder_->decode(header_bytes, pending_);
  } catch (const FormatError&) {
    pending_error_ = std::current_exception();
  }
}

bool EventStreamReader::read(EventBatch& out) {
  out.clear();
  if (!pending_.empty()) {
    std::swap(out, pending_);
    return true;
  }
  while (out.empty() && !pending_error_ && !at_end_) {
    const std::size_t size = read_chunk();
    try {
      if (size > 0) {
        decoder_->decode({chunk_.data(), size}, out);
      } else {
        at_end_ = true;
        decoder_->finish(out);
      }
    } catch (const FormatError&) {
      pending_error_ = std::current_exception();
    }
  }
  if (!out.empty()) return true;  // a fault waits for the next call, after these events
  if (pending_error_) {
    at_end_ = true;
    std::rethrow_exception(std::exchange(pending_error_, nullptr));
  }
  return false;
}

std::size_t EventStreamReader::read_chunk() {
  const std::size_t size = bytes_->read(chunk_);
  bytes_read_ += size;
  return size;
}

}  // namespace evldt
