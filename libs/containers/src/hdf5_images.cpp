#include "evldt/containers/hdf5_images.hpp"

#include <array>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "hdf5_handle.hpp"

namespace evldt {
namespace {

using hdf5::Handle;

class Hdf5ImageSource final : public ImageSource {
 public:
  Hdf5ImageSource(const std::filesystem::path& path, const std::string& dataset)
      : path_(path.string()),
        name_(dataset.empty() ? "/davis/left/image_raw" : (dataset.front() == '/' ? dataset : "/" + dataset)) {
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);  // errors are reported by the exceptions thrown here
    try {
      file_ = Handle(H5Fopen(path_.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT));
      if (!file_.valid()) throw std::runtime_error("HDF5 cannot open it: " + hdf5::hdf5_error());
      if (!hdf5::exists(file_.get(), name_))
        throw std::runtime_error("no frames " + name_ + " (MVSEC: /davis/left/image_raw)");
      images_ = Handle(H5Dopen2(file_.get(), name_.c_str(), H5P_DEFAULT));
      if (!images_.valid()) throw std::runtime_error(name_ + " is not a dataset");
      const Handle space(H5Dget_space(images_.get()));
      const Handle type(H5Dget_type(images_.get()));
      if (H5Sget_simple_extent_ndims(space.get()) != 3 || H5Tget_class(type.get()) != H5T_INTEGER ||
          H5Tget_size(type.get()) != 1) {
        throw std::runtime_error(name_ + " is not N x H x W frames of 8-bit pixels");
      }
      H5Sget_simple_extent_dims(space.get(), dims_.data(), nullptr);
      // Checked before any frame is read into memory: a corrupt size must not become an allocation.
      if (dims_[1] < 1 || dims_[2] < 1 || dims_[1] > kMaxSensorSide || dims_[2] > kMaxSensorSide) {
        throw std::runtime_error(name_ + " holds frames of " + std::to_string(dims_[2]) + "x" +
                                 std::to_string(dims_[1]) + ", not a sensor's size (1.." +
                                 std::to_string(kMaxSensorSide) + " a side)");
      }
      const std::string times_name = name_ + "_ts";
      if (!hdf5::exists(file_.get(), times_name)) throw std::runtime_error("no frame times " + times_name);
      const Handle times(H5Dopen2(file_.get(), times_name.c_str(), H5P_DEFAULT));
      const Handle times_space(H5Dget_space(times.get()));
      hsize_t count = 0;
      if (H5Sget_simple_extent_ndims(times_space.get()) != 1)
        throw std::runtime_error(times_name + " is not a list of times");
      H5Sget_simple_extent_dims(times_space.get(), &count, nullptr);
      if (count != dims_[0]) {
        throw std::runtime_error(times_name + " holds " + std::to_string(count) + " times for " +
                                 std::to_string(dims_[0]) + " frames");
      }
      seconds_.resize(count);
      if (count > 0 && H5Dread(times.get(), H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, seconds_.data()) < 0) {
        throw std::runtime_error(times_name + " cannot be read: " + hdf5::hdf5_error());
      }
    } catch (const std::runtime_error& error) {
      throw std::runtime_error("'" + path_ + "': " + error.what());
    }
  }

  bool next(RecordingImage& image, std::string& location) override {
    location = path_ + ", " + name_ + "[" + std::to_string(next_) + "]";
    if (next_ == dims_[0]) return false;
    pixels_.resize(static_cast<std::size_t>(dims_[1] * dims_[2]));
    const Handle file_space(H5Dget_space(images_.get()));
    const std::array<hsize_t, 3> start{next_, 0, 0}, count{1, dims_[1], dims_[2]};
    const Handle memory(H5Screate_simple(3, count.data(), nullptr));
    if (H5Sselect_hyperslab(file_space.get(), H5S_SELECT_SET, start.data(), nullptr, count.data(), nullptr) < 0 ||
        H5Dread(images_.get(), H5T_NATIVE_UINT8, memory.get(), file_space.get(), H5P_DEFAULT, pixels_.data()) < 0) {
      throw std::runtime_error(location + ": " + hdf5::hdf5_error());
    }
    const double seconds = seconds_[next_];
    if (!std::isfinite(seconds) || std::abs(seconds) > 9e12)
      throw std::runtime_error(location + ": its time " + std::to_string(seconds) + " s is no time");
    image.t_us = hdf5::time_us(seconds, true);  // as the events' times in seconds are read
    image.width = static_cast<std::uint32_t>(dims_[2]);
    image.height = static_cast<std::uint32_t>(dims_[1]);
    image.encoding = "mono8";
    image.big_endian = false;
    image.step = image.width;
    image.data = pixels_;
    ++next_;
    return true;
  }

  [[nodiscard]] std::string description() const override { return "HDF5, " + name_ + " (MVSEC frames)"; }

 private:
  std::string path_, name_;
  Handle file_, images_;
  std::array<hsize_t, 3> dims_{};  // frames, rows, columns
  std::vector<double> seconds_;
  hsize_t next_ = 0;
  std::vector<std::uint8_t> pixels_;
};

}  // namespace

std::unique_ptr<ImageSource> open_hdf5_images(const std::filesystem::path& path, const std::string& dataset) {
  return std::make_unique<Hdf5ImageSource>(path, dataset);
}

}  // namespace evldt
