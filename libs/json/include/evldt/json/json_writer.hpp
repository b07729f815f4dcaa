#pragma once
// JSON text: a minimal streaming writer (objects, arrays, numbers, strings) for reports, and the
// one way evldt quotes a string in JSON, for the few messages built by hand.

#include <concepts>
#include <cstdint>
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

namespace evldt {

/// `text` as a JSON string, in quotes: '"', '\\' and control characters escaped, UTF-8 unchanged.
std::string json_quoted(std::string_view text);

/// Writes indented JSON to a stream. Inside an object every value is preceded by key(); misuse
/// (a key outside an object, a value without a key, unbalanced ends) throws std::logic_error.
/// Non-finite numbers, which JSON cannot express, are written as null. Numbers use the shortest
/// text that reads back to the same double.
class JsonWriter {
 public:
  explicit JsonWriter(std::ostream& out) : out_(out) {}

  JsonWriter& begin_object();
  JsonWriter& end_object();
  JsonWriter& begin_array();
  JsonWriter& end_array();
  JsonWriter& key(std::string_view name);

  JsonWriter& value(double number);
  JsonWriter& value(std::string_view text);
  JsonWriter& value(const char* text) { return value(std::string_view(text)); }
  JsonWriter& value(bool flag);  // preferred over the template for bool, being no template
  template <std::integral T>
  JsonWriter& value(T number) {
    if constexpr (std::signed_integral<T>) {
      return write_integer(static_cast<std::int64_t>(number));
    } else {
      return write_unsigned(static_cast<std::uint64_t>(number));
    }
  }
  JsonWriter& null();

  /// Shorthand for key(name).value(v).
  template <typename T>
  JsonWriter& field(std::string_view name, const T& v) {
    return key(name).value(v);
  }

  /// True once the outermost value is complete.
  [[nodiscard]] bool done() const { return started_ && open_.empty(); }

 private:
  struct Level {
    bool object = false;
    bool empty = true;
    bool key_pending = false;
  };
  void before_value();
  void newline_and_indent();
  void write_string(std::string_view text);
  JsonWriter& write_integer(std::int64_t number);
  JsonWriter& write_unsigned(std::uint64_t number);
  JsonWriter& close(bool object);

  std::ostream& out_;
  std::vector<Level> open_;
  bool started_ = false;
};

}  // namespace evldt
