#pragma once
// Where events come from, behind one interface: a recording file (every format of README's Formats table,
// an lcm-log of event batches among them), a built-in simulated scene, or a video file / webcam turned into
// events by frame differencing. The offline runner and the camera service read through it.

#include <atomic>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "evldt/events/byte_source.hpp"
#include "evldt/events/event.hpp"
#include "evldt/events/event_decoder.hpp"
#include "evldt/events/event_format.hpp"
#include "evldt/sim/event_simulator.hpp"
#include "evldt/sim/frame_difference.hpp"

namespace evldt {

class EventSource {
 public:
  virtual ~EventSource() = default;
  /// Clears `batch` and fills it with the next events in time order; false at the end. A corrupt
  /// recording throws FormatError after its valid prefix has been returned.
  virtual bool read(EventBatch& batch) = 0;
  /// The sensor size, where the source knows it (some recordings' headers do not say).
  [[nodiscard]] virtual std::optional<SensorSize> geometry() const = 0;
  /// What the recording's decoder skipped or counted so far (nothing, for sources that decode nothing).
  [[nodiscard]] virtual DecodeCounts decode_counts() const { return {}; }
  /// Fraction done, in [0, 1] (0 for a live camera).
  [[nodiscard]] virtual double progress() const = 0;
  /// Events come as a camera makes them (a growing file, a byte stream): they are not paced, and
  /// the source cannot be read again.
  [[nodiscard]] virtual bool live() const { return false; }
  /// Times a live source's connection was made again after it was lost.
  [[nodiscard]] virtual std::uint64_t reconnects() const { return 0; }
  [[nodiscard]] const std::string& name() const { return name_; }

 protected:
  std::string name_;
};

/// A recording. Containers are recognised by their content: an lcm-log (its event batches, checked
/// as a subscriber checks them, `backwards_slack_us` for their time order), an HDF5 file, a ROS 1 or
/// 2 bag (.bag, .db3), an MCAP file, an AEDAT 4.0 file; the other formats by their first bytes, name
/// or `format`. `channel` picks the lcm-log channel, the bag or MCAP topic or the HDF5 event table
/// (empty: the first EVENTS_* channel, the first event topic, the first known table).
std::unique_ptr<EventSource> open_recording(const std::filesystem::path& path, std::optional<EventFormat> format,
                                            const std::string& channel, Timestamp backwards_slack_us);
/// A live stream of bytes in a recording format (RAW EVT 2.0/2.1/3.0, and whatever the file formats
/// read: see EventStreamReader), the format from `format`, else the first bytes, `extension` or the
/// header. Blocks until the header has come.
std::unique_ptr<EventSource> open_stream(std::unique_ptr<ByteSource> bytes, std::optional<EventFormat> format,
                                         std::string_view extension);
/// DV's AEDAT 4.0 network stream (see open_aedat4_stream), read as it comes.
std::unique_ptr<EventSource> open_dv_stream(std::unique_ptr<ByteSource> bytes);
/// A live source opened again when it ends or is cut (a camera server restarting): each one from
/// `open` (which throws std::runtime_error when it cannot connect) is read as a stream of its own
/// (header, then data); between attempts it waits, without using the CPU, 0.1 s doubling up to
/// 2 s. Connects before it returns; ends only when `stop` is set (throws std::runtime_error if
/// stopped before the first connection).
std::unique_ptr<EventSource> open_reconnecting(std::function<std::unique_ptr<EventSource>()> open,
                                               const std::atomic<bool>& stop);
/// A scene run through the event simulator; `label` names it in logs.
std::unique_ptr<EventSource> open_scene(Scene scene, const SimulatorConfig& config, const std::string& label);

struct VideoSourceOptions {
  std::string input;  ///< a video file, or a webcam index ("0")
  FrameDifferenceConfig emulator;
  double fps_override = 0;  ///< frame rate to assume where the file does not say (0: ask the file, else 30)
};
/// Frames of a video file or webcam, as events by frame differencing. Throws std::runtime_error if
/// it cannot be opened. A file's frame times come from its frame rate (deterministic); a webcam's
/// from the wall clock.
std::unique_ptr<EventSource> open_video(const VideoSourceOptions& options);

}  // namespace evldt
