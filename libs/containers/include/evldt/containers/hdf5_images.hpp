#pragma once
// The APS frames of HDF5 files in MVSEC's layout: an N x H x W dataset of 8-bit grey frames
// (/davis/left/image_raw, /davis/right/image_raw) and beside it, named with "_ts" appended, their
// N times in seconds on the clock of the events (/davis/left/image_raw_ts).

#include <filesystem>
#include <memory>
#include <string>

#include "evldt/containers/image_source.hpp"

namespace evldt {

/// Opens `path` and its frames: `dataset`, or if empty /davis/left/image_raw. Throws
/// std::runtime_error naming the file for a file HDF5 cannot open, no such dataset, one that is not
/// N x H x W of 8-bit integers, or times missing or not one per frame.
std::unique_ptr<ImageSource> open_hdf5_images(const std::filesystem::path& path, const std::string& dataset);

}  // namespace evldt
