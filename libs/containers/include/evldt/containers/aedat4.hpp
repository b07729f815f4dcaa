#pragma once
// AEDAT 4.0 (iniVation's DV software: DVXplorer, DAVIS): "#!AER-DAT4.0\r\n", a size-prefixed
// FlatBuffer header (compression, data table position, an XML description of the streams), then
// packets: int32 stream id, int32 size, and a payload compressed whole (LZ4 frame, Zstandard frame,
// or none) that holds a size-prefixed FlatBuffer. The first polarity stream ("EVTS") is read as
// events, other streams (IMU, triggers, frames) skipped and counted; the first frame stream
// ("FRME", one frame per packet: schemas/dv_frame.fbs) is read as images. Sensor size and camera
// name come from the event stream's sizeX, sizeY and source.

#include <filesystem>
#include <memory>
#include <string_view>

#include "evldt/containers/image_source.hpp"
#include "evldt/containers/packet_source.hpp"
#include "evldt/events/byte_source.hpp"

namespace evldt {

inline constexpr std::string_view kAedat4Magic = "#!AER-DAT4.0\r\n";

/// Throws FormatError naming the file and byte offset for a header that cannot be read or a file
/// without a polarity event stream.
std::unique_ptr<PacketSource> open_aedat4(const std::filesystem::path& path);
/// DV's network output (dv-runtime's net-tcp-server and net-socket-server, dv-processing's
/// NetworkWriter): an AEDAT 4.0 file's layout without its version line and data table, from the
/// size-prefixed IOHeader on; it ends when the server closes it at a packet boundary.
std::unique_ptr<PacketSource> open_aedat4_stream(std::unique_ptr<ByteSource> bytes);
/// The frames of a file's first frame stream (FRME), grey (mono8) or BGR (bgr8), each at the middle
/// of its exposure (its time stamp where the exposure is not given). Throws std::runtime_error
/// naming the file for a header that cannot be read or a file without a frame stream.
std::unique_ptr<ImageSource> open_aedat4_images(const std::filesystem::path& path);

}  // namespace evldt
