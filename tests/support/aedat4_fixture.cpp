// Test helper: an AEDAT 4.0 file of a built-in scene (boxes-6dof, 240x180, 0.3 s), its events in
// packets of 2000 on stream 0 and a grey frame every 20 ms on stream 1, laid out as one writer does:
//   dv             each FlatBuffer finished size-prefixed, with identifiers (DV's file writer);
//   aedat-library  each finished plain, its size then put in front (the aedat library, Python/Rust),
//                  so 8-byte fields are aligned from the buffer's start, 4 bytes off DV's.
// The same data both ways, so what a reader makes of the two must be the same.
// Usage: aedat4_fixture OUT.aedat4 dv|aedat-library none|lz4|zstd

#include <flatbuffers/flatbuffers.h>
#include <lz4frame.h>
#include <zstd.h>

#include <cstdio>
#include <cstring>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "aedat4_header_generated.h"
#include "dv_events_generated.h"
#include "dv_frame_generated.h"
#include "evldt/containers/aedat4.hpp"
#include "evldt/sim/event_simulator.hpp"
#include "evldt/sim/scenes.hpp"

namespace {

using Bytes = std::vector<std::uint8_t>;

void append_le32(Bytes& out, std::uint32_t value) {
  for (int k = 0; k < 4; ++k) out.push_back(static_cast<std::uint8_t>(value >> (8 * k)));
}

Bytes finished(flatbuffers::FlatBufferBuilder& builder, bool aedat_library) {
  const std::size_t prefix = aedat_library ? 4 : 0;
  Bytes bytes(prefix + builder.GetSize());
  for (std::size_t k = 0; k < prefix; ++k) bytes[k] = static_cast<std::uint8_t>(builder.GetSize() >> (8 * k));
  std::memcpy(bytes.data() + prefix, builder.GetBufferPointer(), builder.GetSize());
  return bytes;
}

Bytes compressed(const Bytes& data, evldt::aedat4::CompressionType compression) {
  Bytes out;
  if (compression == evldt::aedat4::CompressionType::LZ4) {
    out.resize(LZ4F_compressFrameBound(data.size(), nullptr));
    const std::size_t size = LZ4F_compressFrame(out.data(), out.size(), data.data(), data.size(), nullptr);
    if (LZ4F_isError(size)) throw std::runtime_error("lz4 failed");
    out.resize(size);
  } else if (compression == evldt::aedat4::CompressionType::ZSTD) {
    out.resize(ZSTD_compressBound(data.size()));
    const std::size_t size = ZSTD_compress(out.data(), out.size(), data.data(), data.size(), 3);
    if (ZSTD_isError(size)) throw std::runtime_error("zstd failed");
    out.resize(size);
  } else {
    out = data;
  }
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace evldt;
  if (argc != 4) {
    std::fprintf(stderr, "usage: aedat4_fixture OUT.aedat4 dv|aedat-library none|lz4|zstd\n");
    return 1;
  }
  const std::string layout = argv[2], compression_name = argv[3];
  if (layout != "dv" && layout != "aedat-library") {
    std::fprintf(stderr, "layout: dv or aedat-library\n");
    return 1;
  }
  const bool aedat_library = layout == "aedat-library";
  aedat4::CompressionType compression = aedat4::CompressionType::NONE;
  if (compression_name == "lz4") compression = aedat4::CompressionType::LZ4;
  if (compression_name == "zstd") compression = aedat4::CompressionType::ZSTD;
  if (compression == aedat4::CompressionType::NONE && compression_name != "none") {
    std::fprintf(stderr, "compression: none, lz4 or zstd\n");
    return 1;
  }

  Scene scene = make_scene("boxes-6dof");
  scene.duration_us = 300'000;
  EventSimulator simulator(scene, SimulatorConfig{});
  EventBatch events;
  simulator.run_until(scene.duration_us, events);

  const char* info =
      R"(<dv version="2.0"><node name="outInfo" path="/mainloop/Recorder/outInfo/">)"
      R"(<node name="0" path="/mainloop/Recorder/outInfo/0/"><attr key="typeIdentifier" type="string">EVTS</attr>)"
      R"(<node name="info" path="/mainloop/Recorder/outInfo/0/info/"><attr key="sizeX" type="int">240</attr>)"
      R"(<attr key="sizeY" type="int">180</attr><attr key="source" type="string">DAVIS240C_FIXTURE</attr></node></node>)"
      R"(<node name="1" path="/mainloop/Recorder/outInfo/1/"><attr key="typeIdentifier" type="string">FRME</attr></node>)"
      R"(</node></dv>)";
  Bytes file(kAedat4Magic.begin(), kAedat4Magic.end());
  {
    flatbuffers::FlatBufferBuilder builder;
    builder.ForceDefaults(true);  // the 8-byte dataTablePosition is written
    const auto header = aedat4::CreateIOHeaderDirect(builder, compression, -1, info);
    if (aedat_library) {
      builder.Finish(header);
    } else {
      aedat4::FinishSizePrefixedIOHeaderBuffer(builder, header);
    }
    const Bytes bytes = finished(builder, aedat_library);
    file.insert(file.end(), bytes.begin(), bytes.end());
  }
  const auto packet = [&](std::int32_t stream, const Bytes& payload) {
    const Bytes stored = compressed(payload, compression);
    append_le32(file, static_cast<std::uint32_t>(stream));
    append_le32(file, static_cast<std::uint32_t>(stored.size()));
    file.insert(file.end(), stored.begin(), stored.end());
  };
  constexpr std::size_t kPerPacket = 2000;
  constexpr Timestamp kFramePeriodUs = 20'000;
  Timestamp next_frame = kFramePeriodUs;
  std::vector<std::uint8_t> grey;
  for (std::size_t from = 0; from < events.size(); from += kPerPacket) {
    const std::size_t to = std::min(events.size(), from + kPerPacket);
    flatbuffers::FlatBufferBuilder builder;
    std::vector<dv::Event> elements;
    for (std::size_t i = from; i < to; ++i) {
      elements.emplace_back(events.t[i], static_cast<std::int16_t>(events.x[i]), static_cast<std::int16_t>(events.y[i]),
                            events.p[i] > 0);
    }
    const auto events_packet = dv::CreateEventPacket(builder, builder.CreateVectorOfStructs(elements));
    if (aedat_library) {
      builder.Finish(events_packet);
    } else {
      dv::FinishSizePrefixedEventPacketBuffer(builder, events_packet);
    }
    packet(0, finished(builder, aedat_library));
    // The frames whose time the events have passed, as a recorder interleaves them.
    for (; next_frame <= events.t[to - 1] && next_frame < scene.duration_us; next_frame += kFramePeriodUs) {
      simulator.render_frame(next_frame, grey);
      flatbuffers::FlatBufferBuilder frame_builder;
      const auto pixels = frame_builder.CreateVector(grey);
      dv::FrameBuilder frame(frame_builder);
      frame.add_timestamp(next_frame);
      frame.add_timestampStartOfExposure(next_frame - 1000);
      frame.add_timestampEndOfExposure(next_frame + 1000);
      frame.add_format(dv::FrameFormat::OPENCV_8U_C1);
      frame.add_sizeX(static_cast<std::int16_t>(scene.sensor.width));
      frame.add_sizeY(static_cast<std::int16_t>(scene.sensor.height));
      frame.add_pixels(pixels);
      const auto done = frame.Finish();
      if (aedat_library) {
        frame_builder.Finish(done);
      } else {
        dv::FinishSizePrefixedFrameBuffer(frame_builder, done);
      }
      packet(1, finished(frame_builder, aedat_library));
    }
  }
  std::ofstream out(argv[1], std::ios::binary);
  out.write(reinterpret_cast<const char*>(file.data()), static_cast<std::streamsize>(file.size()));
  return out ? 0 : 1;
}
