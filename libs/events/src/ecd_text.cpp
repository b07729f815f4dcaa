// Event Camera Dataset events.txt: one "t x y p" line per event, t in seconds as decimal text.

#include <algorithm>
#include <charconv>
#include <cstring>
#include <string_view>

#include "evldt/events/event_decoder.hpp"
#include "evldt/events/event_writer.hpp"

namespace evldt::detail {
namespace {

// A real line is under 50 bytes; the cap keeps a binary file read as text from growing the carry-over.
constexpr std::size_t kMaxLineBytes = 4096;
constexpr std::uint32_t kMaxCoordinate = 65535;
constexpr Timestamp kMicrosecondsPerSecond = 1'000'000;
// 12 digits of seconds keep the microseconds well inside int64.
constexpr std::size_t kMaxSecondsDigits = 12;

bool is_blank(char c) { return c == ' ' || c == '\t'; }

bool all_digits(std::string_view text) {
  for (char c : text) {
    if (c < '0' || c > '9') return false;
  }
  return true;
}

/// Decimal seconds -> microseconds, exactly: the digits are read as an integer, never as a double.
/// The seventh fraction digit rounds half up; later digits cannot change a half-up rounding.
std::optional<Timestamp> parse_seconds_as_us(std::string_view text) {
  const auto dot = text.find('.');
  const std::string_view whole = text.substr(0, dot);
  const std::string_view fraction = dot == std::string_view::npos ? std::string_view{} : text.substr(dot + 1);
  if (whole.empty() || whole.size() > kMaxSecondsDigits || !all_digits(whole)) return std::nullopt;
  if (dot != std::string_view::npos && (fraction.empty() || !all_digits(fraction))) return std::nullopt;
  Timestamp us = 0;
  for (char digit : whole) us = us * 10 + (digit - '0');
  for (std::size_t i = 0; i < 6; ++i) us = us * 10 + (i < fraction.size() ? fraction[i] - '0' : 0);
  if (fraction.size() > 6 && fraction[6] >= '5') ++us;
  return us;
}

std::optional<std::uint16_t> parse_coordinate(std::string_view text) {
  std::uint32_t value = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc() || end != text.data() + text.size() || value > kMaxCoordinate) return std::nullopt;
  return static_cast<std::uint16_t>(value);
}

bool is_digit(char c) { return c >= '0' && c <= '9'; }

/// The common line, "SECONDS[.FRACTION] X Y P" with single blanks or runs of them, read in one pass
/// (a third of the time of the general path, which reads whole files of these): false, with nothing
/// read, for any other line, which the general path then reads or reports.
bool parse_plain_line(const char* s, const char* end, Timestamp& t, std::uint16_t& x, std::uint16_t& y,
                      std::int8_t& p) {
  const char* const whole_begin = s;
  const char* const whole_limit = s + std::min<std::ptrdiff_t>(end - s, static_cast<std::ptrdiff_t>(kMaxSecondsDigits));
  Timestamp us = 0;
  while (s < whole_limit && is_digit(*s)) us = us * 10 + (*s++ - '0');
  if (s == whole_begin || (s < end && is_digit(*s))) return false;  // none, or more than the general path takes
  std::size_t fraction_digits = 0;
  bool round_up = false;
  if (s < end && *s == '.') {
    for (++s; s < end && is_digit(*s); ++s, ++fraction_digits) {
      if (fraction_digits < 6) us = us * 10 + (*s - '0');
      if (fraction_digits == 6) round_up = *s >= '5';
    }
    if (fraction_digits == 0) return false;
  }
  for (std::size_t i = fraction_digits; i < 6; ++i) us *= 10;
  if (round_up) ++us;
  const auto blanks = [&] {
    const char* const begin = s;
    while (s < end && is_blank(*s)) ++s;
    return s != begin;
  };
  const auto coordinate = [&](std::uint16_t& out) {
    const char* const begin = s;
    std::uint32_t value = 0;
    while (s < end && is_digit(*s) && s - begin < 9) value = value * 10 + static_cast<std::uint32_t>(*s++ - '0');
    if (s == begin || value > kMaxCoordinate || (s < end && is_digit(*s))) return false;
    out = static_cast<std::uint16_t>(value);
    return true;
  };
  if (!blanks() || !coordinate(x) || !blanks() || !coordinate(y) || !blanks()) return false;
  if (s == end || (*s != '0' && *s != '1')) return false;
  p = *s++ == '1' ? std::int8_t{1} : std::int8_t{-1};
  blanks();
  if (s != end) return false;
  t = us;
  return true;
}

/// Hands out the blank-separated fields of a line.
class FieldCursor {
 public:
  explicit FieldCursor(std::string_view line) : rest_(line) {}
  /// The next field, empty at the end of the line.
  std::string_view next() {
    std::size_t start = 0;
    while (start < rest_.size() && is_blank(rest_[start])) ++start;
    std::size_t end = start;
    while (end < rest_.size() && !is_blank(rest_[end])) ++end;
    const std::string_view field = rest_.substr(start, end - start);
    rest_.remove_prefix(end);
    return field;
  }

 private:
  std::string_view rest_;
};

class EcdTextDecoder final : public EventDecoder {
 public:
  explicit EcdTextDecoder(std::string source) : source_(std::move(source)) {}

  void decode(std::span<const std::uint8_t> chunk, EventBatch& batch) override {
    EventBatch::Appender out(batch);
    const char* const text = reinterpret_cast<const char*>(chunk.data());
    std::size_t pos = 0;
    if (!partial_.empty()) {
      const auto* newline = static_cast<const char*>(std::memchr(text, '\n', chunk.size()));
      const std::size_t line_end = newline != nullptr ? static_cast<std::size_t>(newline - text) : chunk.size();
      partial_.append(text, line_end);
      check_line_length(partial_.size(), partial_offset_);
      if (newline == nullptr) {
        consumed_ += chunk.size();
        return;
      }
      parse_line(partial_, partial_offset_, out);
      partial_.clear();
      pos = line_end + 1;
    }
    while (pos < chunk.size()) {
      const auto* newline = static_cast<const char*>(std::memchr(text + pos, '\n', chunk.size() - pos));
      if (newline == nullptr) break;
      const auto line_end = static_cast<std::size_t>(newline - text);
      parse_line({text + pos, line_end - pos}, consumed_ + pos, out);
      pos = line_end + 1;
    }
    if (pos < chunk.size()) {
      partial_offset_ = consumed_ + pos;
      partial_.assign(text + pos, chunk.size() - pos);
      check_line_length(partial_.size(), partial_offset_);
    }
    consumed_ += chunk.size();
  }

  void finish(EventBatch& batch) override {
    EventBatch::Appender out(batch);
    // A last line without '\n' is fine if it is complete; a cut one fails to parse and reports itself.
    if (partial_.empty()) return;
    parse_line(partial_, partial_offset_, out);
    partial_.clear();
  }

  [[nodiscard]] std::optional<SensorSize> geometry() const override { return std::nullopt; }

 private:
  void parse_line(std::string_view line, std::uint64_t offset, EventBatch::Appender& out) {
    ++line_number_;
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    Timestamp t_plain = 0;
    std::uint16_t x_plain = 0, y_plain = 0;
    std::int8_t p_plain = 0;
    if (parse_plain_line(line.data(), line.data() + line.size(), t_plain, x_plain, y_plain, p_plain)) {
      out.push_back(t_plain, x_plain, y_plain, p_plain);
      return;
    }
    FieldCursor fields(line);
    const std::string_view t_text = fields.next();
    if (t_text.empty() || t_text.front() == '#') return;  // blank line or comment
    const std::string_view x_text = fields.next();
    const std::string_view y_text = fields.next();
    const std::string_view p_text = fields.next();
    if (p_text.empty()) fail(offset, "expected 't x y p', found only " + std::string(line));
    const std::string_view junk = fields.next();
    if (!junk.empty()) fail(offset, "unexpected '" + std::string(junk) + "' after 't x y p'");

    const auto t = parse_seconds_as_us(t_text);
    if (!t) fail(offset, "time '" + std::string(t_text) + "' is not a non-negative decimal number of seconds");
    const auto x = parse_coordinate(x_text);
    if (!x) fail(offset, "x '" + std::string(x_text) + "' is not an integer in 0..65535");
    const auto y = parse_coordinate(y_text);
    if (!y) fail(offset, "y '" + std::string(y_text) + "' is not an integer in 0..65535");
    if (p_text != "0" && p_text != "1") fail(offset, "polarity '" + std::string(p_text) + "' is not 0 or 1");
    out.push_back(*t, *x, *y, p_text == "1" ? std::int8_t{1} : std::int8_t{-1});
  }

  void check_line_length(std::size_t length, std::uint64_t offset) const {
    if (length > kMaxLineBytes) {
      throw FormatError(source_, offset,
                        "line " + std::to_string(line_number_ + 1) + " is longer than " +
                            std::to_string(kMaxLineBytes) + " bytes (not ECD text?)");
    }
  }

  [[noreturn]] void fail(std::uint64_t offset, const std::string& what) const {
    throw FormatError(source_, offset, "line " + std::to_string(line_number_) + ": " + what);
  }

  std::string source_;
  std::string partial_;  // a line split across chunks, without its '\n' yet
  std::uint64_t partial_offset_ = 0;
  std::uint64_t consumed_ = 0;  // bytes in the chunks before the current one
  std::uint64_t line_number_ = 0;
};

void append_decimal(std::uint64_t value, std::vector<std::uint8_t>& out) {
  char digits[20];
  const char* const end = std::to_chars(digits, digits + sizeof(digits), value).ptr;
  out.insert(out.end(), static_cast<const char*>(digits), end);
}

class EcdTextEncoder final : public EventEncoder {
 public:
  void write_header(std::vector<std::uint8_t>& /*out*/) const override {}

  void encode(const EventBatch& batch, std::vector<std::uint8_t>& out) override {
    check_encodable(batch, last_time_, static_cast<int>(kMaxCoordinate), "ECD text");
    for (std::size_t i = 0; i < batch.size(); ++i) {
      // Seconds with nine fraction digits, from integers: 3811 us -> "0.003811000".
      append_decimal(static_cast<std::uint64_t>(batch.t[i] / kMicrosecondsPerSecond), out);
      out.push_back('.');
      Timestamp micros = batch.t[i] % kMicrosecondsPerSecond;
      const std::size_t fraction_start = out.size();
      out.resize(fraction_start + 6);
      for (std::size_t digit = 6; digit-- > 0; micros /= 10)
        out[fraction_start + digit] = static_cast<std::uint8_t>('0' + micros % 10);
      for (const char c : std::string_view("000 ")) out.push_back(static_cast<std::uint8_t>(c));
      append_decimal(batch.x[i], out);
      out.push_back(' ');
      append_decimal(batch.y[i], out);
      out.push_back(' ');
      out.push_back(batch.p[i] > 0 ? '1' : '0');
      out.push_back('\n');
    }
    if (!batch.empty()) last_time_ = batch.t.back();
  }

 private:
  Timestamp last_time_ = 0;
};

}  // namespace

std::unique_ptr<EventDecoder> make_ecd_text_decoder(std::string source_name) {
  return std::make_unique<EcdTextDecoder>(std::move(source_name));
}

std::unique_ptr<EventEncoder> make_ecd_text_encoder() { return std::make_unique<EcdTextEncoder>(); }

}  // namespace evldt::detail
