#include "evldt/containers/hdf5_events.hpp"

#include <hdf5.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <stdexcept>
#include <utility>
#include <vector>

#include "evldt/events/event_format.hpp"
#include "hdf5_handle.hpp"

namespace evldt {
namespace {

using hdf5::exists;
using hdf5::Handle;
using hdf5::hdf5_error;
using hdf5::time_us;

constexpr std::size_t kSlabEvents = std::size_t{1} << 16;
constexpr H5Z_filter_t kBloscFilter = 32001;
constexpr H5Z_filter_t kEcfFilter = 0x8ECF;  // Prophesee's Event Compression Format

bool is_float(hid_t dataset) {
  const Handle type(H5Dget_type(dataset));
  return H5Tget_class(type.get()) == H5T_FLOAT;
}

/// Rows in a dataset's first dimension (and the second dimension's size, 1 for a 1-D dataset).
std::array<hsize_t, 2> shape(hid_t dataset) {
  const Handle space(H5Dget_space(dataset));
  std::array<hsize_t, 2> dims{0, 1};
  const int rank = H5Sget_simple_extent_ndims(space.get());
  if (rank < 1 || rank > 2) throw std::runtime_error("a table of rank " + std::to_string(rank));
  H5Sget_simple_extent_dims(space.get(), dims.data(), nullptr);
  return dims;
}

/// Refuses a dataset whose compression filter is not installed, with what to install.
void require_filters(hid_t dataset, const std::string& name) {
  const Handle plist(H5Dget_create_plist(dataset));
  const int count = H5Pget_nfilters(plist.get());
  for (int i = 0; i < count; ++i) {
    unsigned flags = 0;
    std::size_t values = 0;
    std::array<char, 64> filter_name{};
    const H5Z_filter_t filter = H5Pget_filter2(plist.get(), static_cast<unsigned>(i), &flags, &values, nullptr,
                                               filter_name.size(), filter_name.data(), nullptr);
    if (filter < 0 || H5Zfilter_avail(filter) > 0) continue;
    H5Eclear2(H5E_DEFAULT);
    std::string hint;
    if (filter == kBloscFilter) hint = ": install Debian's hdf5-filter-plugin-blosc-serial";
    if (filter == kEcfFilter)
      hint =
          ": Prophesee's ECF plugin (hdf5_ecf) is not packaged by Debian; install it and set HDF5_PLUGIN_PATH, or "
          "convert the file to RAW";
    throw std::runtime_error(name + " is compressed with HDF5 filter " + std::to_string(filter) + " (" +
                             filter_name.data() + "), which is not installed" + hint);
  }
}

std::optional<std::int64_t> read_integer_attribute(hid_t object, const char* name) {
  if (H5Aexists(object, name) <= 0) return std::nullopt;
  const Handle attribute(H5Aopen(object, name, H5P_DEFAULT));
  std::int64_t value = 0;
  const Handle space(H5Aget_space(attribute.get()));
  if (H5Sget_simple_extent_npoints(space.get()) != 1 || H5Aread(attribute.get(), H5T_NATIVE_INT64, &value) < 0) {
    H5Eclear2(H5E_DEFAULT);
    return std::nullopt;
  }
  return value;
}

/// The sensor size from attributes of `object`: width and height, sensor_resolution [height, width]
/// (as event_utils writes it), or a "WxH" geometry string (as Prophesee's tools write it).
std::optional<SensorSize> sensor_from_attributes(hid_t object) {
  const auto width = read_integer_attribute(object, "width"), height = read_integer_attribute(object, "height");
  if (width && height) return SensorSize{static_cast<int>(*width), static_cast<int>(*height)};
  if (H5Aexists(object, "sensor_resolution") > 0) {
    const Handle attribute(H5Aopen(object, "sensor_resolution", H5P_DEFAULT));
    const Handle space(H5Aget_space(attribute.get()));
    std::array<std::int64_t, 2> resolution{};
    if (H5Sget_simple_extent_npoints(space.get()) == 2 &&
        H5Aread(attribute.get(), H5T_NATIVE_INT64, resolution.data()) >= 0) {
      return SensorSize{static_cast<int>(resolution[1]), static_cast<int>(resolution[0])};
    }
  }
  if (H5Aexists(object, "geometry") > 0) {
    const Handle attribute(H5Aopen(object, "geometry", H5P_DEFAULT));
    const Handle type(H5Aget_type(attribute.get()));
    if (H5Tget_class(type.get()) == H5T_STRING && !H5Tis_variable_str(type.get())) {
      std::string text(H5Tget_size(type.get()), '\0');
      if (H5Aread(attribute.get(), type.get(), text.data()) >= 0) {
        int w = 0, h = 0;
        if (std::sscanf(text.c_str(), "%dx%d", &w, &h) == 2) return SensorSize{w, h};
      }
    }
  }
  H5Eclear2(H5E_DEFAULT);
  return std::nullopt;
}

// The file's values are untrusted: conversions saturate instead of overflowing, and a coordinate
// outside 0..65535 (or NaN) becomes 65535, off every sensor, for the validator to drop and count.
std::uint16_t coordinate(double value) {
  return value >= 0 && value <= 65535 ? static_cast<std::uint16_t>(std::lround(value)) : 65535;
}

Timestamp saturated_sum(Timestamp a, Timestamp b) {
  Timestamp sum = 0;
  if (__builtin_add_overflow(a, b, &sum))
    return b > 0 ? std::numeric_limits<Timestamp>::max() : std::numeric_limits<Timestamp>::min();
  return sum;
}

}  // namespace

/// The event table of one layout and its read buffers.
struct Hdf5EventReader::Table {
  enum class Layout { Columns, Rows, Records };
  // The compound that a records table is read into; HDF5 converts the file's members by name.
  struct Record {
    std::int32_t x, y, p;
    double t;
  };

  Handle file;
  Layout layout = Layout::Columns;
  std::string name;
  std::array<Handle, 4> columns;  // x, y, t, p (columns); [0] the rows or records dataset
  bool float_time = false;
  std::int64_t time_offset_us = 0;
  hsize_t rows = 0, at = 0;
  std::vector<std::int32_t> x, y, p;
  std::vector<std::int64_t> t;
  std::vector<double> values;  // rows: N x 4; columns with float time: t
  std::vector<Record> records;
  Handle record_type;

  void select(hid_t dataset, std::size_t count, const Handle& memory, auto&& read) const {
    const Handle space(H5Dget_space(dataset));
    const std::array<hsize_t, 2> start{at, 0}, size{count, layout == Layout::Rows ? hsize_t{4} : hsize_t{1}};
    if (H5Sselect_hyperslab(space.get(), H5S_SELECT_SET, start.data(), nullptr, size.data(), nullptr) < 0 ||
        read(memory.get(), space.get()) < 0) {
      throw std::runtime_error(hdf5_error());
    }
  }

  void read_column(int column, hid_t type, void* out, std::size_t count) const {
    const hsize_t size = count;
    const Handle memory(H5Screate_simple(1, &size, nullptr));
    select(columns[column].get(), count, memory,
           [&](hid_t m, hid_t f) { return H5Dread(columns[column].get(), type, m, f, H5P_DEFAULT, out); });
  }

  void read_slab(std::size_t count, EventBatch& out) {
    switch (layout) {
      case Layout::Columns: {
        read_column(0, H5T_NATIVE_INT32, x.data(), count);
        read_column(1, H5T_NATIVE_INT32, y.data(), count);
        read_column(3, H5T_NATIVE_INT32, p.data(), count);
        if (float_time) {
          read_column(2, H5T_NATIVE_DOUBLE, values.data(), count);
          for (std::size_t i = 0; i < count; ++i) t[i] = time_us(values[i], true);
        } else {
          read_column(2, H5T_NATIVE_INT64, t.data(), count);
        }
        for (std::size_t i = 0; i < count; ++i) {
          out.push_back(saturated_sum(time_offset_us, t[i]), coordinate(x[i]), coordinate(y[i]),
                        p[i] > 0 ? std::int8_t{1} : std::int8_t{-1});
        }
        return;
      }
      case Layout::Rows: {
        const std::array<hsize_t, 2> size{count, 4};
        const Handle memory(H5Screate_simple(2, size.data(), nullptr));
        select(columns[0].get(), count, memory, [&](hid_t m, hid_t f) {
          return H5Dread(columns[0].get(), H5T_NATIVE_DOUBLE, m, f, H5P_DEFAULT, values.data());
        });
        for (std::size_t i = 0; i < count; ++i) {
          const double* row = values.data() + 4 * i;
          out.push_back(time_us(row[2], float_time), coordinate(row[0]), coordinate(row[1]),
                        row[3] > 0 ? std::int8_t{1} : std::int8_t{-1});
        }
        return;
      }
      case Layout::Records: {
        const hsize_t size = count;
        const Handle memory(H5Screate_simple(1, &size, nullptr));
        select(columns[0].get(), count, memory, [&](hid_t m, hid_t f) {
          return H5Dread(columns[0].get(), record_type.get(), m, f, H5P_DEFAULT, records.data());
        });
        for (std::size_t i = 0; i < count; ++i) {
          const Record& record = records[i];
          out.push_back(time_us(record.t, float_time), coordinate(record.x), coordinate(record.y),
                        record.p > 0 ? std::int8_t{1} : std::int8_t{-1});
        }
        return;
      }
    }
  }
};

Hdf5EventReader::Hdf5EventReader(const std::filesystem::path& path, const std::string& table)
    : table_(std::make_unique<Table>()), path_(path.string()) {
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);  // errors are reported by the exceptions thrown here
  Table& events = *table_;
  try {
    events.file = Handle(H5Fopen(path_.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT));
    if (!events.file.valid()) throw std::runtime_error("HDF5 cannot open it: " + hdf5_error());
    const hid_t file = events.file.get();
    std::string name = table.empty() ? "" : (table.front() == '/' ? table : "/" + table);
    if (name.empty()) {
      for (const char* candidate : {"/events", "/davis/left/events", "/CD/events"}) {
        if (exists(file, candidate)) {
          name = candidate;
          break;
        }
      }
      if (name.empty())
        throw std::runtime_error("no event table (/events, /davis/left/events or /CD/events); name one with --topic");
    } else if (!exists(file, name)) {
      throw std::runtime_error("no object " + name);
    }
    events.name = name;
    const Handle object(H5Oopen(file, name.c_str(), H5P_DEFAULT));
    std::string what;
    std::optional<SensorSize> dataset_camera;
    if (H5Iget_type(object.get()) == H5I_GROUP) {
      events.layout = Table::Layout::Columns;
      const std::array<const char*, 4> column_names{"x", "y", "t", "p"};
      for (std::size_t i = 0; i < column_names.size(); ++i) {
        const std::string column = name + "/" + column_names[i];
        if (!exists(file, column))
          throw std::runtime_error(name + " is a group without the dataset " + column_names[i]);
        events.columns[i] = Handle(H5Dopen2(file, column.c_str(), H5P_DEFAULT));
        require_filters(events.columns[i].get(), column);
        const auto dims = shape(events.columns[i].get());
        if (dims[1] != 1) throw std::runtime_error(column + " is not one column");
        if (i > 0 && dims[0] != events.rows) throw std::runtime_error("the columns of " + name + " differ in length");
        events.rows = dims[0];
      }
      events.float_time = is_float(events.columns[2].get());
      if (exists(file, "/t_offset")) {
        const Handle offset(H5Dopen2(file, "/t_offset", H5P_DEFAULT));
        if (H5Dread(offset.get(), H5T_NATIVE_INT64, H5S_ALL, H5S_ALL, H5P_DEFAULT, &events.time_offset_us) < 0) {
          throw std::runtime_error("cannot read /t_offset: " + hdf5_error());
        }
      }
      what = "columns x, y, t, p";
      if (exists(file, "/ms_to_idx")) dataset_camera = SensorSize{640, 480};  // DSEC's event cameras
    } else {
      events.columns[0] = Handle(H5Dopen2(file, name.c_str(), H5P_DEFAULT));
      const hid_t dataset = events.columns[0].get();
      require_filters(dataset, name);
      const auto dims = shape(dataset);
      events.rows = dims[0];
      const Handle type(H5Dget_type(dataset));
      if (H5Tget_class(type.get()) == H5T_COMPOUND) {
        events.layout = Table::Layout::Records;
        for (const char* member : {"x", "y", "p", "t"}) {
          if (H5Tget_member_index(type.get(), member) < 0)
            throw std::runtime_error(name + " has records without the field " + member);
        }
        const Handle t_type(
            H5Tget_member_type(type.get(), static_cast<unsigned>(H5Tget_member_index(type.get(), "t"))));
        events.float_time = H5Tget_class(t_type.get()) == H5T_FLOAT;
        events.record_type = Handle(H5Tcreate(H5T_COMPOUND, sizeof(Table::Record)));
        H5Tinsert(events.record_type.get(), "x", HOFFSET(Table::Record, x), H5T_NATIVE_INT32);
        H5Tinsert(events.record_type.get(), "y", HOFFSET(Table::Record, y), H5T_NATIVE_INT32);
        H5Tinsert(events.record_type.get(), "p", HOFFSET(Table::Record, p), H5T_NATIVE_INT32);
        H5Tinsert(events.record_type.get(), "t", HOFFSET(Table::Record, t), H5T_NATIVE_DOUBLE);
        events.records.resize(kSlabEvents);
        what = "records x, y, p, t";
      } else {
        if (dims[1] != 4)
          throw std::runtime_error(name + " is not a table of 4 columns (x, y, t, p) but of " +
                                   std::to_string(dims[1]));
        events.layout = Table::Layout::Rows;
        events.float_time = H5Tget_class(type.get()) == H5T_FLOAT;
        what = "rows x, y, t, p";
        if (name.starts_with("/davis/")) dataset_camera = SensorSize{346, 260};  // MVSEC's DAVIS m346
      }
    }
    events.x.resize(kSlabEvents);
    events.y.resize(kSlabEvents);
    events.p.resize(kSlabEvents);
    events.t.resize(kSlabEvents);
    events.values.resize(kSlabEvents * 4);

    geometry_ = sensor_from_attributes(object.get());
    if (!geometry_) geometry_ = sensor_from_attributes(file);
    std::string size_note;
    if (!geometry_ && dataset_camera) {
      geometry_ = dataset_camera;
      size_note = std::string("; ") + std::to_string(dataset_camera->width) + "x" +
                  std::to_string(dataset_camera->height) + " as " +
                  (dataset_camera->width == 640 ? "DSEC's" : "MVSEC's") + " cameras: not in the file";
    }
    if (geometry_ && !geometry_->valid()) geometry_.reset();
    description_ = "HDF5, " + name + " (" + what + (events.float_time ? ", t in s" : ", t in us") + size_note + ")";
  } catch (const std::runtime_error& error) {
    throw std::runtime_error("'" + path_ + "': " + error.what());
  }
}

Hdf5EventReader::~Hdf5EventReader() = default;

bool Hdf5EventReader::read(EventBatch& out) {
  out.clear();
  Table& events = *table_;
  if (events.at >= events.rows) return false;
  const auto count = static_cast<std::size_t>(std::min<hsize_t>(kSlabEvents, events.rows - events.at));
  try {
    events.read_slab(count, out);
  } catch (const std::runtime_error& error) {
    out.clear();
    const std::string where = events.name + " events from " + std::to_string(events.at);
    events.at = events.rows;  // nothing more after a fault
    throw FormatError(path_, 0, where + ": " + error.what());
  }
  events.at += count;
  return true;
}

double Hdf5EventReader::progress() const {
  return table_->rows == 0 ? 1.0 : static_cast<double>(table_->at) / static_cast<double>(table_->rows);
}

bool is_hdf5(const std::filesystem::path& path) {
  std::ifstream file(path, std::ios::binary);
  std::string start(kHdf5Magic.size(), '\0');
  return file.read(start.data(), static_cast<std::streamsize>(start.size())) && start == kHdf5Magic;
}

}  // namespace evldt
