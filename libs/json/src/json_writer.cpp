#include "evldt/json/json_writer.hpp"

#include <charconv>
#include <cmath>
#include <stdexcept>
#include <string>

namespace evldt {

std::string json_quoted(std::string_view text) {
  static constexpr char kHex[] = "0123456789abcdef";
  std::string out;
  out.reserve(text.size() + 2);
  out += '"';
  for (const char c : text) {
    switch (c) {
      case '"':
        out += "\\\"";
        break;
      case '\\':
        out += "\\\\";
        break;
      case '\n':
        out += "\\n";
        break;
      case '\r':
        out += "\\r";
        break;
      case '\t':
        out += "\\t";
        break;
      default:
        if (static_cast<unsigned char>(c) < 0x20) {
          out += "\\u00";
          out += kHex[(c >> 4) & 0xf];
          out += kHex[c & 0xf];
        } else {
          out += c;  // UTF-8 passes through unchanged
        }
    }
  }
  out += '"';
  return out;
}

JsonWriter& JsonWriter::begin_object() {
  before_value();
  out_ << '{';
  open_.push_back({true});
  return *this;
}

JsonWriter& JsonWriter::begin_array() {
  before_value();
  out_ << '[';
  open_.push_back({false});
  return *this;
}

JsonWriter& JsonWriter::end_object() { return close(true); }
JsonWriter& JsonWriter::end_array() { return close(false); }

JsonWriter& JsonWriter::close(bool object) {
  if (open_.empty() || open_.back().object != object || open_.back().key_pending) {
    throw std::logic_error(object ? "JSON: unbalanced end_object" : "JSON: unbalanced end_array");
  }
  const bool empty = open_.back().empty;
  open_.pop_back();
  if (!empty) newline_and_indent();
  out_ << (object ? '}' : ']');
  if (open_.empty()) out_ << '\n';
  return *this;
}

JsonWriter& JsonWriter::key(std::string_view name) {
  if (open_.empty() || !open_.back().object || open_.back().key_pending) {
    throw std::logic_error("JSON: key \"" + std::string(name) + "\" outside an object or after another key");
  }
  Level& level = open_.back();
  if (!level.empty) out_ << ',';
  level.empty = false;
  newline_and_indent();
  write_string(name);
  out_ << ": ";
  level.key_pending = true;
  return *this;
}

JsonWriter& JsonWriter::value(double number) {
  if (!std::isfinite(number)) return null();
  before_value();
  char text[32];
  const auto end = std::to_chars(text, text + sizeof text, number).ptr;
  out_.write(text, end - text);
  return *this;
}

JsonWriter& JsonWriter::value(std::string_view text) {
  before_value();
  write_string(text);
  return *this;
}

JsonWriter& JsonWriter::value(bool flag) {
  before_value();
  out_ << (flag ? "true" : "false");
  return *this;
}

JsonWriter& JsonWriter::null() {
  before_value();
  out_ << "null";
  return *this;
}

JsonWriter& JsonWriter::write_integer(std::int64_t number) {
  before_value();
  out_ << number;
  return *this;
}

JsonWriter& JsonWriter::write_unsigned(std::uint64_t number) {
  before_value();
  out_ << number;
  return *this;
}

void JsonWriter::before_value() {
  if (open_.empty()) {
    if (started_) throw std::logic_error("JSON: a second top-level value");
    started_ = true;
    return;
  }
  Level& level = open_.back();
  if (level.object) {
    if (!level.key_pending) throw std::logic_error("JSON: object member without a key");
    level.key_pending = false;
    return;
  }
  if (!level.empty) out_ << ',';
  level.empty = false;
  newline_and_indent();
}

void JsonWriter::newline_and_indent() {
  out_ << '\n';
  for (std::size_t i = 0; i < open_.size(); ++i) out_ << "  ";
}

void JsonWriter::write_string(std::string_view text) { out_ << json_quoted(text); }

}  // namespace evldt
