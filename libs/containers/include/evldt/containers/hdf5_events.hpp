#pragma once
// HDF5 event files: event tables read in slabs, in any of the layouts public datasets use:
//   columns: a group of 1-D datasets x, y, t (integer us), p; a root dataset t_offset (us) is added
//            to t (DSEC: /events, often blosc-compressed, with /ms_to_idx);
//   rows:    an N x 4 dataset of x, y, t (s), p (MVSEC: /davis/left/events, /davis/right/events);
//   records: a 1-D dataset of compound {x, y, p, t (us)} (Prophesee Metavision: /CD/events, whose
//            ECF compression needs Prophesee's HDF5 plugin, which Debian does not package).
// Compression filters come from HDF5's plugins (Debian's hdf5-filter-plugin-blosc-serial for blosc).

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "evldt/events/event.hpp"

namespace evldt {

inline constexpr std::string_view kHdf5Magic{"\x89HDF\r\n\x1a\n", 8};

class Hdf5EventReader {
 public:
  /// Opens `path` and its event table: `table` (a group or dataset path) or, if empty, the first of
  /// /events, /davis/left/events, /CD/events. Throws std::runtime_error naming the file for a file
  /// HDF5 cannot open, no event table, or a compression filter that is not installed.
  Hdf5EventReader(const std::filesystem::path& path, const std::string& table);
  ~Hdf5EventReader();
  Hdf5EventReader(const Hdf5EventReader&) = delete;
  Hdf5EventReader& operator=(const Hdf5EventReader&) = delete;

  /// Clears `out` and fills it with the next slab of events; false at the end. Throws FormatError
  /// (naming the file and the event index) for a slab HDF5 cannot read, after the slabs before it.
  /// Coordinates outside 0..65535 become 65535 (off every sensor: the validator drops them).
  bool read(EventBatch& out);
  /// From the table's or the file's attributes (width/height, sensor_resolution [h, w], geometry
  /// "WxH"), else the camera of the dataset the layout belongs to (DSEC 640x480, MVSEC 346x260).
  [[nodiscard]] std::optional<SensorSize> geometry() const { return geometry_; }
  /// e.g. "HDF5, /events (columns x, y, t, p; 640x480 as DSEC's cameras: not in the file)".
  [[nodiscard]] const std::string& description() const { return description_; }
  [[nodiscard]] double progress() const;

 private:
  struct Table;
  std::unique_ptr<Table> table_;
  std::string path_;
  std::optional<SensorSize> geometry_;
  std::string description_;
};

/// Whether the file starts with the HDF5 signature.
bool is_hdf5(const std::filesystem::path& path);

}  // namespace evldt
