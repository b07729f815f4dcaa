#include <algorithm>
#include <charconv>
#include <cstring>
#include <utility>

#include "evldt/events/event_decoder.hpp"
#include "evldt/events/event_format.hpp"

namespace evldt {

std::optional<EventFormat> parse_event_format(std::string_view name) {
  if (name == "ecd") return EventFormat::EcdText;
  if (name == "evt2") return EventFormat::Evt2;
  if (name == "evt3") return EventFormat::Evt3;
  if (name == "evt21") return EventFormat::Evt21;
  if (name == "dat") return EventFormat::Dat;
  if (name == "aedat2") return EventFormat::Aedat2;
  if (name == "aedat31") return EventFormat::Aedat31;
  if (name == "aedat31-net") return EventFormat::Aedat31Network;
  if (name == "es") return EventFormat::EventStream;
  return std::nullopt;
}

std::string_view format_name(EventFormat format) {
  switch (format) {
    case EventFormat::EcdText:
      return "ecd";
    case EventFormat::Evt2:
      return "evt2";
    case EventFormat::Evt3:
      return "evt3";
    case EventFormat::Evt21:
      return "evt21";
    case EventFormat::Dat:
      return "dat";
    case EventFormat::Aedat2:
      return "aedat2";
    case EventFormat::Aedat31:
      return "aedat31";
    case EventFormat::Aedat31Network:
      return "aedat31-net";
    case EventFormat::EventStream:
      return "es";
  }
  return "unknown";
}

namespace detail {
namespace {

// Real header lines are short; a longer one is binary data that happens to start with '%'.
constexpr std::size_t kMaxHeaderLineBytes = 64 * 1024;

std::string_view trim(std::string_view text) {
  const auto first = text.find_first_not_of(" \t");
  if (first == std::string_view::npos) return {};
  const auto last = text.find_last_not_of(" \t");
  return text.substr(first, last - first + 1);
}

bool equals_ignoring_case(std::string_view a, std::string_view b) {
  return std::ranges::equal(a, b, [](char ca, char cb) {
    const auto lower = [](char c) { return (c >= 'A' && c <= 'Z') ? static_cast<char>(c - 'A' + 'a') : c; };
    return lower(ca) == lower(cb);
  });
}

/// "% key value words" -> {"key", "value words"}.
std::pair<std::string_view, std::string_view> split_header_line(std::string_view line) {
  line = trim(line.substr(1));
  const auto space = line.find_first_of(" \t");
  if (space == std::string_view::npos) return {line, {}};
  return {line.substr(0, space), trim(line.substr(space + 1))};
}

std::optional<int> parse_positive_int(std::string_view text) {
  int value = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc() || end != text.data() + text.size() || value <= 0) return std::nullopt;
  return value;
}

/// "640x480" -> {640, 480}.
std::optional<SensorSize> parse_geometry_value(std::string_view value) {
  const auto x = value.find('x');
  if (x == std::string_view::npos) return std::nullopt;
  const auto width = parse_positive_int(trim(value.substr(0, x)));
  const auto height = parse_positive_int(trim(value.substr(x + 1)));
  if (!width || !height) return std::nullopt;
  return SensorSize{*width, *height};
}

/// "EVT3;height=720;width=1280" -> {1280, 720}.
std::optional<SensorSize> parse_format_value(std::string_view value) {
  std::optional<int> width;
  std::optional<int> height;
  while (!value.empty()) {
    const auto semicolon = value.find(';');
    const std::string_view item = value.substr(0, semicolon);
    value = semicolon == std::string_view::npos ? std::string_view{} : value.substr(semicolon + 1);
    const auto equals = item.find('=');
    if (equals == std::string_view::npos) continue;
    const std::string_view key = trim(item.substr(0, equals));
    if (key == "width") width = parse_positive_int(trim(item.substr(equals + 1)));
    if (key == "height") height = parse_positive_int(trim(item.substr(equals + 1)));
  }
  if (!width || !height) return std::nullopt;
  return SensorSize{*width, *height};
}

}  // namespace

std::size_t TextHeader::consume(std::span<const std::uint8_t> bytes, const std::string& source) {
  std::size_t used = 0;
  while (used < bytes.size() && !complete_) {
    if (!in_line_) {
      if (bytes[used] != static_cast<unsigned char>(marker_)) {
        complete_ = true;
        break;
      }
      in_line_ = true;
      line_start_ = size_ + used;
    }
    const std::uint8_t* begin = bytes.data() + used;
    const auto* newline = static_cast<const std::uint8_t*>(std::memchr(begin, '\n', bytes.size() - used));
    const std::uint8_t* end = newline != nullptr ? newline : bytes.data() + bytes.size();
    line_.append(begin, end);
    used = static_cast<std::size_t>(end - bytes.data());
    if (line_.size() > kMaxHeaderLineBytes) {
      throw FormatError(source, line_start_,
                        "header line longer than " + std::to_string(kMaxHeaderLineBytes) + " bytes");
    }
    if (newline == nullptr) break;
    ++used;  // the '\n'
    if (!line_.empty() && line_.back() == '\r') line_.pop_back();
    in_line_ = false;
    complete_ = is_end_line(line_);
    lines_.push_back(std::move(line_));
    line_.clear();
  }
  size_ += used;
  return used;
}

bool TextHeader::is_end_line(std::string_view line) const {
  line = trim(line);
  return line == "% end" || line == "#!END-HEADER" || equals_ignoring_case(line, "#End Of ASCII Header");
}

void TextHeader::finish(const std::string& source) const {
  if (in_line_) throw FormatError(source, line_start_, "file ends inside a header line");
}

namespace {

// Prophesee cameras whose RAW headers (2020-era SDK) name no geometry or format: the vendor tools
// know the sensor from "% system_ID" (decimal), as OpenEB's device_system_id.h and raw file header
// do, and older tools from "% plugin_name".
struct KnownSystem {
  int system_id;
  const char* encoding;
  SensorSize sensor;
};
constexpr SensorSize kVga{640, 480};
constexpr SensorSize kHd{1280, 720};
constexpr KnownSystem kKnownSystems[] = {
    {0x15, "EVT2", kVga}, {0x17, "EVT2", kVga}, {0x97, "EVT2", kVga}, {0x19, "EVT2", kVga},  // Gen3.0
    {0x99, "EVT2", kVga}, {0x1D, "EVT2", kVga}, {0x21, "EVT2", kVga}, {0xA1, "EVT2", kVga},
    {0x1C, "EVT2", kVga}, {0x22, "EVT2", kVga}, {0xA2, "EVT2", kVga}, {0x23, "EVT2", kVga},  // Gen3.1
    {0x29, "EVT2", kVga}, {0x28, "EVT3", kVga}, {0x1A, "EVT2", kHd},  {0x1F, "EVT2", kHd},
    {0x1E, "EVT3", kHd},  {0x2E, "EVT3", kHd},  // Gen4.0
    {0x27, "EVT2", kHd},  {0x30, "EVT3", kHd},  // Gen4.1
    {0x31, "EVT3", kHd},  {0x32, "EVT3", kHd},  // IMX636
};
struct KnownPlugin {
  const char* name;
  SensorSize sensor;
};
constexpr KnownPlugin kKnownPlugins[] = {
    {"hal_plugin_gen3_fx3", kVga},   {"hal_plugin_gen31_fx3", kVga}, {"hal_plugin_gen31_evk2", kVga},
    {"hal_plugin_gen31_evk3", kVga}, {"hal_plugin_gen4_fx3", kHd},   {"hal_plugin_gen4_evk2", kHd},
    {"hal_plugin_gen41_evk2", kHd},  {"hal_plugin_gen41_evk3", kHd},
};

const KnownSystem* known_system(const std::vector<std::string>& lines) {
  for (const std::string& line : lines) {
    const auto [key, value] = split_header_line(line);
    if (!equals_ignoring_case(key, "system_ID")) continue;
    const auto id = parse_positive_int(value);
    for (const KnownSystem& system : kKnownSystems) {
      if (id && system.system_id == *id) return &system;
    }
  }
  return nullptr;
}

std::optional<SensorSize> known_plugin_sensor(const std::vector<std::string>& lines) {
  for (const std::string& line : lines) {
    const auto [key, value] = split_header_line(line);
    if (!equals_ignoring_case(key, "plugin_name")) continue;
    for (const KnownPlugin& plugin : kKnownPlugins) {
      if (equals_ignoring_case(trim(value), plugin.name)) return plugin.sensor;
    }
  }
  return std::nullopt;
}

}  // namespace

std::optional<SensorSize> TextHeader::geometry() const {
  std::optional<SensorSize> from_geometry;
  std::optional<SensorSize> from_format;
  std::optional<int> width;
  std::optional<int> height;
  for (const std::string& line : lines_) {
    const auto [key, value] = split_header_line(line);
    if (equals_ignoring_case(key, "geometry")) {
      from_geometry = parse_geometry_value(value);
    } else if (equals_ignoring_case(key, "format")) {
      from_format = parse_format_value(value);
    } else if (equals_ignoring_case(key, "width")) {
      width = parse_positive_int(value);
    } else if (equals_ignoring_case(key, "height")) {
      height = parse_positive_int(value);
    }
  }
  if (from_geometry) return from_geometry;
  if (from_format) return from_format;
  if (width && height) return SensorSize{*width, *height};
  if (const KnownSystem* system = known_system(lines_)) return system->sensor;
  return known_plugin_sensor(lines_);
}

std::optional<std::string> TextHeader::encoding() const {
  std::optional<std::string> from_evt_line;
  for (const std::string& line : lines_) {
    const auto [key, value] = split_header_line(line);
    if (equals_ignoring_case(key, "format")) return std::string(trim(value.substr(0, value.find(';'))));
    if (equals_ignoring_case(key, "evt") && !value.empty()) {
      // "3.0" -> "EVT3", "2.1" -> "EVT21": the names "% format" uses.
      std::string version(value);
      if (version.ends_with(".0")) version.resize(version.size() - 2);
      std::erase(version, '.');
      from_evt_line = "EVT" + version;
    }
  }
  if (from_evt_line) return from_evt_line;
  if (const KnownSystem* system = known_system(lines_)) return std::string(system->encoding);
  return std::nullopt;
}

std::optional<std::string> TextHeader::option(std::string_view key) const {
  for (const std::string& line : lines_) {
    const auto [line_key, value] = split_header_line(line);
    if (equals_ignoring_case(line_key, key)) return std::string(value);
    if (!equals_ignoring_case(line_key, "format")) continue;
    for (std::string_view rest = value; !rest.empty();) {  // "EVT21;endianness=little;height=320"
      const auto end = rest.find(';');
      const std::string_view item = trim(rest.substr(0, end));
      const auto equals = item.find('=');
      if (equals != std::string_view::npos && equals_ignoring_case(trim(item.substr(0, equals)), key)) {
        return std::string(trim(item.substr(equals + 1)));
      }
      rest = end == std::string_view::npos ? std::string_view() : rest.substr(end + 1);
    }
  }
  return std::nullopt;
}

std::optional<int> TextHeader::system_id() const {
  const auto value = option("system_ID");
  return value ? parse_positive_int(*value) : std::nullopt;
}

std::optional<EventFormat> raw_format_from_encoding(std::string_view encoding) {
  if (equals_ignoring_case(encoding, "EVT2")) return EventFormat::Evt2;
  if (equals_ignoring_case(encoding, "EVT3")) return EventFormat::Evt3;
  if (equals_ignoring_case(encoding, "EVT21")) return EventFormat::Evt21;
  return std::nullopt;
}

}  // namespace detail
}  // namespace evldt
