#pragma once
// Event-camera model over a Scene: per-pixel log intensity rendered at sub-frame times fine enough
// that no vertex moves more than max_step_px per step; a pixel fires each time its log intensity
// moves a contrast threshold (C+/C-, with per-pixel spread) away from its reference, with the event
// time interpolated linearly between the two sub-frames; a refractory period; background noise
// (more of it in the dark, if asked), optional hot pixels, flickering lights (sub-frames fall on
// their switching times) and a readout of limited bandwidth that delays, jitters and drops events.
// Deterministic for a seed.

#include <cstdint>
#include <memory>
#include <vector>

#include "evldt/events/event.hpp"
#include "evldt/sim/random.hpp"
#include "evldt/sim/scene.hpp"

namespace evldt {

struct SimulatorConfig {
  double contrast_on = 0.2;       ///< C+ (log intensity)
  double contrast_off = 0.2;      ///< C-
  double contrast_sigma = 0.03;   ///< per-pixel spread of both thresholds (std dev, absolute)
  Timestamp refractory_us = 100;  ///< a pixel's events closer than this to its previous one are lost
  double noise_rate_hz = 0.1;     ///< background events per pixel per second
  double dark_noise_hz = 0;       ///< more background events per pixel per second, times (1 - brightness)
  int hot_pixels = 0;             ///< pixels that fire at hot_rate_hz regardless of the scene
  double hot_rate_hz = 2000;
  double max_step_px = 0.5;  ///< largest vertex motion between two rendered sub-frames
  Timestamp max_step_us = 1000;
  /// Readout: events leave the sensor at most this many per second, in time order, stamped when
  /// they leave (0: no limit); an event that would wait longer than readout_queue_us is lost.
  double readout_rate_eps = 0;
  Timestamp readout_queue_us = 1000;
  Timestamp timestamp_jitter_us = 0;  ///< up to this much later, uniformly (kept in time order)
  std::uint64_t seed = 1;
  /// The scene through a calibrated lens: per sensor pixel (row-major), where its centre looks in the
  /// scene's (rectified) coordinates, x then y (undistorted_pixel_centres of libs/calibration). The
  /// events then come in sensor pixels while the scene's exact lines stay rectified. Null: a pinhole.
  std::shared_ptr<const std::vector<float>> lens;
};

struct SimulatorCounters {
  std::uint64_t signal_events = 0;
  std::uint64_t noise_events = 0;
  std::uint64_t refractory_losses = 0;
  std::uint64_t readout_losses = 0;  ///< lost because the readout queue was full
  std::uint64_t sub_frames = 0;
};

/// How an APS takes a frame: the exposure it integrates over (motion blurs an edge across what it
/// moves meanwhile) and the read noise added to each pixel.
struct ApsModel {
  Timestamp exposure_us = 0;  ///< 0: an instant
  double read_noise = 0;      ///< standard deviation, in grey levels (0..255)
};

class EventSimulator {
 public:
  EventSimulator(Scene scene, const SimulatorConfig& config);

  /// Appends (without clearing) the events with t in (now, min(until, duration)] in time order and
  /// advances; returns false once the scene's duration is reached and nothing was added. Sub-frames
  /// follow the scene, not the calls, so any split of the time range gives the same events.
  bool run_until(Timestamp until_us, EventBatch& out);

  /// The scene at `t_us` (the exposure's middle) as an 8-bit grey frame (row-major, the sensor's
  /// size), brightness 0..1 to 0..255: what a DAVIS's APS would see, pixel-aligned with the events.
  /// Any time, in any order; the noise is the same for the same seed and time.
  void render_frame(Timestamp t_us, std::vector<std::uint8_t>& grey, const ApsModel& aps = {}) const;

  [[nodiscard]] Timestamp now_us() const { return now_; }
  [[nodiscard]] const Scene& scene() const { return scene_; }
  [[nodiscard]] const SimulatorCounters& counters() const { return counters_; }

 private:
  void render(Timestamp t_us, std::vector<float>& log_image) const;
  Timestamp next_step();
  void emit_signal(Timestamp t0, Timestamp t1);
  void emit_noise(Timestamp t0, Timestamp t1);
  /// Linear brightness of a pixel in the newest sub-frame, in [0, 1].
  [[nodiscard]] double brightness_at(std::size_t pixel) const;
  /// Passes the sub-frame's new events (from `first`, in time order) through the readout.
  void read_out(std::size_t first);

  Scene scene_;
  SimulatorConfig config_;
  SimRandom random_;
  int width_, height_;
  Timestamp now_ = 0;       // events up to here have been handed out
  Timestamp rendered_ = 0;  // time of the newest rendered sub-frame
  std::vector<float> log_prev_, log_now_, log_reference_;
  mutable std::vector<float> lens_canvas_;  // with a lens: the scene rendered rectified, then sampled per pixel
  std::vector<float> threshold_on_, threshold_off_;
  std::vector<Timestamp> last_event_;
  std::vector<std::uint32_t> hot_pixels_;
  double next_noise_s_ = 0, next_hot_s_ = 0;
  double readout_free_us_ = 0;  // when the readout can send its next event
  Timestamp last_out_ = 0;      // the newest time stamped on the way out
  std::vector<Event> pending_;  // events of the rendered sub-frames not handed out yet, in time order
  std::size_t pending_head_ = 0;
  SimulatorCounters counters_;
};

}  // namespace evldt
