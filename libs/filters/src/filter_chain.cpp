#include "evldt/filters/filter_chain.hpp"

#include <algorithm>
#include <stdexcept>

namespace evldt {

const std::vector<std::string>& filter_names() {
  static const std::vector<std::string> names = {"hot-pixel", "background-activity", "refractory", "anti-flicker"};
  return names;
}

std::vector<std::string> parse_filter_chain(const std::string& text) {
  std::vector<std::string> chain;
  if (text.empty() || text == "none") return chain;
  std::size_t start = 0;
  while (start <= text.size()) {
    const std::size_t comma = std::min(text.find(',', start), text.size());
    const std::string name = text.substr(start, comma - start);
    if (std::ranges::find(filter_names(), name) == filter_names().end()) {
      throw std::invalid_argument("unknown filter '" + name + "' (filters: none, or hot-pixel, background-activity, refractory, anti-flicker)");
    }
    if (std::ranges::find(chain, name) != chain.end()) throw std::invalid_argument("filter '" + name + "' given twice");
    chain.push_back(name);
    start = comma + 1;
  }
  return chain;
}

std::string format_filter_chain(const std::vector<std::string>& chain) {
  std::string text;
  for (const auto& name : chain) text += (text.empty() ? "" : ",") + name;
  return text.empty() ? "none" : text;
}

void check_filter_config(const FilterConfig& config) {
  for (const std::string& name : config.chain) {
    if (std::ranges::find(filter_names(), name) == filter_names().end()) throw std::invalid_argument("unknown filter '" + name + "'");
  }
  if (config.background_window_us <= 0) throw std::invalid_argument("the background-activity window must be positive");
  if (!(config.background_min_noise_hz >= 0)) throw std::invalid_argument("the background-activity noise level must not be negative");
  if (config.refractory_us <= 0) throw std::invalid_argument("the refractory period must be positive");
  check_params(config.hot_pixel);
  check_params(config.anti_flicker);
}

FilterChain::FilterChain(const FilterConfig& config, SensorSize sensor) {
  check_filter_config(config);
  for (const std::string& name : config.chain) {
    if (name == "hot-pixel") {
      auto filter = std::make_unique<HotPixelFilter>(sensor, config.hot_pixel);
      hot_pixel_ = filter.get();
      filters_.push_back(std::move(filter));
    } else if (name == "background-activity") {
      filters_.push_back(std::make_unique<BackgroundActivityFilter>(sensor, config.background_window_us, config.background_min_noise_hz));
    } else if (name == "refractory") {
      filters_.push_back(std::make_unique<RefractoryFilter>(sensor, config.refractory_us));
    } else {
      filters_.push_back(std::make_unique<AntiFlickerFilter>(sensor, config.anti_flicker));
    }
  }
}

void FilterChain::filter(const EventBatch& in, EventBatch& out) {
  events_in_ += in.size();
  // The first filter copies what passes, the others filter that copy in place.
  const EventBatch* from = &in;
  for (const auto& filter : filters_) {
    filter->filter(*from, out);
    from = &out;
  }
  passed_ += out.size();
}

FilterCounts FilterChain::counts() const {
  FilterCounts counts;
  counts.events_in = events_in_;
  counts.passed = passed_;
  for (const auto& filter : filters_) {
    const std::string_view name = filter->name();
    std::uint64_t& reason = name == "hot-pixel"             ? counts.hot_pixel
                            : name == "background-activity" ? counts.background_activity
                            : name == "refractory"          ? counts.refractory
                                                            : counts.anti_flicker;
    reason = filter->dropped();
  }
  return counts;
}

std::span<const std::uint32_t> FilterChain::masked_pixels() const {
  return hot_pixel_ ? hot_pixel_->masked_pixels() : std::span<const std::uint32_t>();
}

}  // namespace evldt
