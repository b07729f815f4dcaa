#pragma once
// What the HDF5 readers share: identifiers released by scope, HDF5's own reason for a failure, and
// the reading of a time from a file's untrusted values.

#include <hdf5.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

#include "evldt/events/event.hpp"

namespace evldt::hdf5 {

/// An HDF5 identifier released when it goes out of scope.
class Handle {
 public:
  Handle() = default;
  explicit Handle(hid_t id) : id_(id) {}
  ~Handle() { reset(); }
  Handle(Handle&& other) noexcept : id_(std::exchange(other.id_, H5I_INVALID_HID)) {}
  Handle& operator=(Handle&& other) noexcept {
    if (this != &other) {
      reset();
      id_ = std::exchange(other.id_, H5I_INVALID_HID);
    }
    return *this;
  }
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
  [[nodiscard]] hid_t get() const { return id_; }
  [[nodiscard]] bool valid() const { return id_ >= 0; }

 private:
  void reset() {
    if (id_ >= 0) H5Idec_ref(id_);
    id_ = H5I_INVALID_HID;
  }
  hid_t id_ = H5I_INVALID_HID;
};

/// The innermost message of HDF5's error stack (the cause), for error messages of our own.
inline std::string hdf5_error() {
  std::string message;
  H5Ewalk2(
      H5E_DEFAULT, H5E_WALK_UPWARD,
      [](unsigned, const H5E_error2_t* error, void* out) -> herr_t {
        if (error->desc && static_cast<std::string*>(out)->empty()) *static_cast<std::string*>(out) = error->desc;
        return 0;
      },
      &message);
  H5Eclear2(H5E_DEFAULT);
  return message.empty() ? "HDF5 error" : message;
}

/// Whether `path` names an object, without HDF5 errors for missing intermediate groups.
inline bool exists(hid_t file, const std::string& path) {
  std::string prefix;
  for (std::size_t at = 1; at <= path.size(); ++at) {
    if (at == path.size() || path[at] == '/') {
      prefix = path.substr(0, at);
      if (H5Lexists(file, prefix.c_str(), H5P_DEFAULT) <= 0) return false;
    }
  }
  return !path.empty();
}

/// A time in us: saturates instead of overflowing, NaN becomes 0.
inline Timestamp saturated(double us) {
  constexpr double kLimit = 9.2e18;  // inside the int64 range
  if (std::isnan(us)) return 0;
  return static_cast<Timestamp>(std::clamp(std::round(us), -kLimit, kLimit));
}

/// Integer times are us, floating-point times seconds.
inline Timestamp time_us(double value, bool seconds) { return saturated(seconds ? value * 1e6 : value); }

}  // namespace evldt::hdf5
