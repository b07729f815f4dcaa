#include "evldt/sim/event_simulator.hpp"

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>
#include <tuple>

namespace evldt {

namespace {

// Linear intensity -> log intensity, with a floor so black is finite (as a real pixel's dark current).
constexpr double kDarkCurrent = 0.02;
float log_intensity(double brightness) {
  return static_cast<float>(std::log(std::max(brightness, 0.0) + kDarkCurrent));
}

// Pixels whose centre (x + 0.5, y + 0.5) is inside the convex polygon get `value`.
void fill_convex(const std::vector<Vec2d>& polygon, float value, int width, int height, std::vector<float>& image) {
  double top = 1e300, bottom = -1e300;
  for (const Vec2d& v : polygon) {
    top = std::min(top, v.y());
    bottom = std::max(bottom, v.y());
  }
  const int y_first = std::max(0, static_cast<int>(std::ceil(top - 0.5)));
  const int y_last = std::min(height - 1, static_cast<int>(std::floor(bottom - 0.5)));
  for (int y = y_first; y <= y_last; ++y) {
    const double yc = y + 0.5;
    double left = 1e300, right = -1e300;
    for (std::size_t i = 0; i < polygon.size(); ++i) {
      const Vec2d& p = polygon[i];
      const Vec2d& q = polygon[(i + 1) % polygon.size()];
      if ((p.y() <= yc && q.y() > yc) || (q.y() <= yc && p.y() > yc)) {
        const double x = p.x() + (yc - p.y()) * (q.x() - p.x()) / (q.y() - p.y());
        left = std::min(left, x);
        right = std::max(right, x);
      }
    }
    if (left >= right) continue;
    const int x_first = std::max(0, static_cast<int>(std::ceil(left - 0.5)));
    const int x_end = std::min(width, static_cast<int>(std::ceil(right - 0.5)));
    if (x_first < x_end)
      std::fill(image.begin() + static_cast<std::ptrdiff_t>(y) * width + x_first,
                image.begin() + static_cast<std::ptrdiff_t>(y) * width + x_end, value);
  }
}

}  // namespace

EventSimulator::EventSimulator(Scene scene, const SimulatorConfig& config)
    : scene_(std::move(scene)),
      config_(config),
      random_(config.seed),
      width_(scene_.sensor.width),
      height_(scene_.sensor.height) {
  if (!scene_.sensor.valid()) throw std::invalid_argument("scene has no sensor size");
  if (config.lens && config.lens->size() != 2 * static_cast<std::size_t>(width_) * static_cast<std::size_t>(height_)) {
    throw std::invalid_argument("the lens does not match the scene's sensor size");
  }
  if (!(config.contrast_on > 0) || !(config.contrast_off > 0) || !(config.max_step_px > 0) || config.max_step_us <= 0) {
    throw std::invalid_argument("contrast thresholds and step limits must be positive");
  }
  const std::size_t pixels = static_cast<std::size_t>(width_) * height_;
  threshold_on_.resize(pixels);
  threshold_off_.resize(pixels);
  for (std::size_t i = 0; i < pixels; ++i) {
    threshold_on_[i] =
        static_cast<float>(std::max(0.02, config.contrast_on + config.contrast_sigma * random_.normal()));
    threshold_off_[i] =
        static_cast<float>(std::max(0.02, config.contrast_off + config.contrast_sigma * random_.normal()));
  }
  for (int i = 0; i < config.hot_pixels; ++i) hot_pixels_.push_back(static_cast<std::uint32_t>(random_.below(pixels)));
  last_event_.assign(pixels, -config.refractory_us - 1);
  log_now_.resize(pixels);
  render(0, log_now_);
  log_prev_ = log_now_;
  log_reference_ = log_now_;
  const double noise_total = (config.noise_rate_hz + std::max(0.0, config.dark_noise_hz)) * static_cast<double>(pixels);
  next_noise_s_ = noise_total > 0 ? random_.exponential(1.0 / noise_total) : 1e300;
  const double hot_total = config.hot_rate_hz * static_cast<double>(hot_pixels_.size());
  next_hot_s_ = hot_total > 0 ? random_.exponential(1.0 / hot_total) : 1e300;
}

void EventSimulator::render(Timestamp t_us, std::vector<float>& log_image) const {
  const double t = static_cast<double>(t_us) * 1e-6;
  std::vector<float>& canvas = config_.lens ? lens_canvas_ : log_image;
  canvas.resize(log_image.size());
  const float background = log_intensity(scene_.background);
  std::fill(canvas.begin(), canvas.end(), background);
  for (std::size_t k = 0; k < scene_.shapes.size(); ++k) {
    const Shape& shape = scene_.shapes[k];
    fill_convex(scene_.polygon_at(k, t), log_intensity(shape.brightness * shape.flicker.factor_at(t_us)), width_,
                height_, canvas);
  }
  if (!config_.lens) return;
  // Each sensor pixel sees the rectified scene where its centre looks: bilinear between the four
  // rendered pixels around that point (centres at index + 0.5), the background beyond the image.
  const std::vector<float>& looks = *config_.lens;
  for (std::size_t i = 0; i < log_image.size(); ++i) {
    const float u = looks[2 * i] - 0.5f, v = looks[2 * i + 1] - 0.5f;
    if (!(u >= -0.5f && v >= -0.5f && u <= static_cast<float>(width_) - 0.5f &&
          v <= static_cast<float>(height_) - 0.5f)) {
      log_image[i] = background;
      continue;
    }
    const int x0 = std::clamp(static_cast<int>(std::floor(u)), 0, width_ - 2),
              y0 = std::clamp(static_cast<int>(std::floor(v)), 0, height_ - 2);
    const float ax = std::clamp(u - static_cast<float>(x0), 0.0f, 1.0f),
                ay = std::clamp(v - static_cast<float>(y0), 0.0f, 1.0f);
    const float* row = canvas.data() + static_cast<std::size_t>(y0) * static_cast<std::size_t>(width_) + x0;
    // Weighted sums, so that a look at a pixel's centre takes its value exactly (a pinhole lens
    // gives the pinhole's events).
    const float top = (1.0f - ax) * row[0] + ax * row[1];
    const float bottom = (1.0f - ax) * row[width_] + ax * row[width_ + 1];
    log_image[i] = (1.0f - ay) * top + ay * bottom;
  }
}

void EventSimulator::render_frame(Timestamp t_us, std::vector<std::uint8_t>& grey, const ApsModel& aps) const {
  const std::size_t pixels = static_cast<std::size_t>(width_) * static_cast<std::size_t>(height_);
  std::vector<float> log_image(pixels);
  std::vector<double> brightness(pixels, 0.0);
  // The exposure as the mean of instants across it, one per 250 us (at least 1, at most 32).
  const int instants = aps.exposure_us <= 0 ? 1 : static_cast<int>(std::clamp<Timestamp>(aps.exposure_us / 250, 2, 32));
  for (int k = 0; k < instants; ++k) {
    const Timestamp at =
        instants == 1 ? t_us : t_us - aps.exposure_us / 2 + aps.exposure_us * (2 * k + 1) / (2 * instants);
    render(at, log_image);
    for (std::size_t i = 0; i < pixels; ++i) {
      brightness[i] += std::clamp(std::exp(static_cast<double>(log_image[i])) - kDarkCurrent, 0.0, 1.0) / instants;
    }
  }
  std::mt19937_64 rng(config_.seed * 0x9e3779b97f4a7c15ULL ^ static_cast<std::uint64_t>(t_us));
  std::normal_distribution<double> noise(0.0, aps.read_noise > 0 ? aps.read_noise : 1.0);
  grey.resize(pixels);
  for (std::size_t i = 0; i < pixels; ++i) {
    const double level = brightness[i] * 255.0 + (aps.read_noise > 0 ? noise(rng) : 0.0);
    grey[i] = static_cast<std::uint8_t>(std::lround(std::clamp(level, 0.0, 255.0)));
  }
}

Timestamp EventSimulator::next_step() {
  // Largest step (up to max_step_us) over which no vertex moves more than max_step_px, ending 1 us
  // before a light switches and then at the switch, so that its events fall at the switching time.
  Timestamp step = std::min(config_.max_step_us, scene_.duration_us - rendered_);
  for (const Shape& shape : scene_.shapes) {
    const Timestamp at = shape.flicker.next_switch_us(rendered_);
    if (at - rendered_ <= step) step = at - 1 > rendered_ ? at - 1 - rendered_ : at - rendered_;
  }
  const double t0 = static_cast<double>(rendered_) * 1e-6;
  for (int attempt = 0; attempt < 16 && step > 1; ++attempt) {
    const double t1 = static_cast<double>(rendered_ + step) * 1e-6;
    double largest = 0;
    for (std::size_t k = 0; k < scene_.shapes.size(); ++k) {
      const auto a = scene_.polygon_at(k, t0), b = scene_.polygon_at(k, t1);
      for (std::size_t v = 0; v < a.size(); ++v) largest = std::max(largest, (b[v] - a[v]).norm());
    }
    if (largest <= config_.max_step_px) break;
    step = std::max<Timestamp>(
        1, static_cast<Timestamp>(static_cast<double>(step) * config_.max_step_px / largest * 0.95));
  }
  return rendered_ + step;
}

void EventSimulator::emit_signal(Timestamp t0, Timestamp t1) {
  const double span = static_cast<double>(t1 - t0);
  const std::size_t pixels = log_now_.size();
  for (std::size_t i = 0; i < pixels; ++i) {
    const float before = log_prev_[i], after = log_now_[i];
    if (after == before) continue;
    float& reference = log_reference_[i];
    const float on = threshold_on_[i], off = threshold_off_[i];
    const bool rising = after > reference;
    const float threshold = rising ? on : off;
    const int crossings = static_cast<int>(std::floor(std::abs(after - reference) / threshold));
    for (int m = 1; m <= crossings; ++m) {
      const float level = reference + (rising ? 1.0f : -1.0f) * static_cast<float>(m) * threshold;
      const double fraction = std::clamp(static_cast<double>((level - before) / (after - before)), 0.0, 1.0);
      const Timestamp t = t0 + std::max<Timestamp>(1, static_cast<Timestamp>(std::llround(fraction * span)));
      if (t - last_event_[i] < config_.refractory_us) {
        ++counters_.refractory_losses;
        continue;
      }
      last_event_[i] = t;
      pending_.push_back({t, static_cast<std::uint16_t>(i % static_cast<std::size_t>(width_)),
                          static_cast<std::uint16_t>(i / static_cast<std::size_t>(width_)),
                          static_cast<std::int8_t>(rising ? 1 : -1)});
      ++counters_.signal_events;
    }
    reference += (rising ? 1.0f : -1.0f) * static_cast<float>(crossings) * threshold;
  }
}

void EventSimulator::emit_noise(Timestamp t0, Timestamp t1) {
  const double end_s = static_cast<double>(t1) * 1e-6;
  const std::size_t pixels = log_now_.size();
  const double noise_total =
      (config_.noise_rate_hz + std::max(0.0, config_.dark_noise_hz)) * static_cast<double>(pixels);
  auto fire = [&](double time_s, std::size_t pixel) {
    const Timestamp t = std::clamp<Timestamp>(static_cast<Timestamp>(std::ceil(time_s * 1e6)), t0 + 1, t1);
    pending_.push_back({t, static_cast<std::uint16_t>(pixel % static_cast<std::size_t>(width_)),
                        static_cast<std::uint16_t>(pixel / static_cast<std::size_t>(width_)),
                        static_cast<std::int8_t>(random_.below(2) ? 1 : -1)});
    ++counters_.noise_events;
  };
  while (next_noise_s_ <= end_s) {
    const std::size_t pixel = random_.below(pixels);
    // Thinning: candidates come at the darkest pixel's rate; a brighter one keeps a share of them.
    if (config_.dark_noise_hz <= 0 ||
        random_.uniform() * (config_.noise_rate_hz + config_.dark_noise_hz) <
            config_.noise_rate_hz + config_.dark_noise_hz * (1.0 - brightness_at(pixel))) {
      fire(next_noise_s_, pixel);
    }
    next_noise_s_ += random_.exponential(1.0 / noise_total);
  }
  while (next_hot_s_ <= end_s) {
    fire(next_hot_s_, hot_pixels_[random_.below(hot_pixels_.size())]);
    next_hot_s_ += random_.exponential(1.0 / (config_.hot_rate_hz * static_cast<double>(hot_pixels_.size())));
  }
}

double EventSimulator::brightness_at(std::size_t pixel) const {
  return std::clamp(std::exp(static_cast<double>(log_now_[pixel])) - kDarkCurrent, 0.0, 1.0);
}

void EventSimulator::read_out(std::size_t first) {
  const double spacing_us = config_.readout_rate_eps > 0 ? 1e6 / config_.readout_rate_eps : 0.0;
  std::size_t kept = first;
  for (std::size_t i = first; i < pending_.size(); ++i) {
    Event e = pending_[i];
    const Timestamp jitter =
        config_.timestamp_jitter_us > 0
            ? static_cast<Timestamp>(random_.below(static_cast<std::size_t>(config_.timestamp_jitter_us) + 1))
            : 0;
    const double leaves_us = std::max(static_cast<double>(e.t + jitter), readout_free_us_);
    if (spacing_us > 0 && leaves_us - static_cast<double>(e.t) > static_cast<double>(config_.readout_queue_us)) {
      ++counters_.readout_losses;
      continue;
    }
    readout_free_us_ = leaves_us + spacing_us;
    e.t = std::max(last_out_, static_cast<Timestamp>(std::ceil(leaves_us)));
    last_out_ = e.t;
    pending_[kept++] = e;
  }
  pending_.resize(kept);
}

bool EventSimulator::run_until(Timestamp until_us, EventBatch& out) {
  const Timestamp limit = std::min(until_us, scene_.duration_us);
  const std::size_t before = out.size();
  while (rendered_ < limit) {
    const Timestamp t1 = next_step();
    std::swap(log_prev_, log_now_);
    render(t1, log_now_);
    // Drop what was handed out, then sort the new sub-frame's events behind the rest.
    pending_.erase(pending_.begin(), pending_.begin() + static_cast<std::ptrdiff_t>(pending_head_));
    pending_head_ = 0;
    const std::size_t first_new = pending_.size();
    emit_signal(rendered_, t1);
    emit_noise(rendered_, t1);
    std::stable_sort(pending_.begin() + static_cast<std::ptrdiff_t>(first_new), pending_.end(),
                     [](const Event& a, const Event& b) { return std::tie(a.t, a.y, a.x) < std::tie(b.t, b.y, b.x); });
    if (config_.readout_rate_eps > 0 || config_.timestamp_jitter_us > 0) read_out(first_new);
    rendered_ = t1;
    ++counters_.sub_frames;
  }
  while (pending_head_ < pending_.size() && pending_[pending_head_].t <= limit)
    out.push_back(pending_[pending_head_++]);
  now_ = std::max(now_, limit);
  return out.size() > before || now_ < scene_.duration_us;
}

}  // namespace evldt
