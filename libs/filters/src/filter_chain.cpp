#include "evldt/filters/filter_chain.hpp"

#include <sys/mman.h>

#include <algorithm>
#include <cstdint>
#include <new>
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
      throw std::invalid_argument("unknown filter '" + name +
                                  "' (filters: none, or hot-pixel, background-activity, refractory, anti-flicker)");
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
  for (auto name = config.chain.begin(); name != config.chain.end(); ++name) {
    if (std::ranges::find(filter_names(), *name) == filter_names().end())
      throw std::invalid_argument("unknown filter '" + *name + "'");
    if (std::find(config.chain.begin(), name, *name) != name)
      throw std::invalid_argument("filter '" + *name + "' given twice");
  }
  BackgroundActivityFilter::check_params(config.background_window_us, config.background_min_noise_hz);
  RefractoryFilter::check_params(config.refractory_us);
  check_params(config.hot_pixel);
  check_params(config.anti_flicker);
}

namespace {

// Events ahead whose state is fetched into the cache while the current one is tested: at the larger
// sensor sizes the table is far larger than the caches and events land all over it, so without
// this each event waits for memory (measured: twice the throughput at 1280x720).
constexpr std::size_t kPrefetchAhead = 16;

// The table is mapped from the kernel in whole huge pages, zeroed by it, and faulted in here,
// before the first batch (a service does not count a batch late for queueing behind its start),
// not by the first batches, which at 1280x720 then took 70 ms and queued the next ones past the
// latency budget.
// Transparent huge pages are asked for where the kernel offers them: events land all over a table
// far larger than what the TLB covers with 4 KiB pages (measured: 15% more throughput at 640x480
// and 1280x720).
constexpr std::size_t kHugePage = std::size_t{2} << 20;

std::size_t mapped_size(std::size_t bytes) { return (bytes + kHugePage - 1) / kHugePage * kHugePage; }

std::byte* map_zeroed(std::size_t bytes) {
  // One huge page more than needed, so the table can start on a huge-page boundary.
  const std::size_t size = mapped_size(bytes) + kHugePage;
  void* const memory = mmap(nullptr, size, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  if (memory == MAP_FAILED) throw std::bad_alloc();
  auto* const start = static_cast<std::byte*>(memory);
  const auto address = reinterpret_cast<std::uintptr_t>(start);
  const std::size_t lead = (kHugePage - address % kHugePage) % kHugePage;
  if (lead > 0) munmap(start, lead);
  munmap(start + lead + mapped_size(bytes), kHugePage - lead);
#ifdef MADV_HUGEPAGE
  madvise(start + lead, mapped_size(bytes), MADV_HUGEPAGE);  // a hint: without it, 4 KiB pages
#endif
#ifdef MADV_POPULATE_WRITE
  if (madvise(start + lead, mapped_size(bytes), MADV_POPULATE_WRITE) == 0) return start + lead;
#endif
  // A kernel before 5.14: one write a page faults it in.
  for (std::size_t at = 0; at < mapped_size(bytes); at += 4096) start[lead + at] = std::byte{0};
  return start + lead;
}

}  // namespace

// The filters in a given order, as a compile-time list: the pass over a batch is instantiated for
// each of the 65 orders (none to four distinct filters), so each event's tests inline into one
// loop with no dispatch per event.
template <filter_chain_detail::Kind... Ks>
struct FilterChain::Pass {
  static constexpr bool kRecords = ((Ks == Kind::Refractory || Ks == Kind::AntiFlicker) || ...);
  static constexpr bool kCounts = ((Ks == Kind::HotPixel) || ...);
  static constexpr bool kSurface = ((Ks == Kind::BackgroundActivity) || ...);

  static void run(FilterChain& chain, const EventBatch& in, EventBatch& out) {
    const std::size_t size = in.size();
    if (&in != &out) out.truncate(size);  // room for every event: no allocation once warm
    const Timestamp* const ts = in.t.data();
    const std::uint16_t *const xs = in.x.data(), *const ys = in.y.data();
    const std::int8_t* const ps = in.p.data();
    Timestamp* const out_t = out.t.data();
    std::uint16_t *const out_x = out.x.data(), *const out_y = out.y.data();
    std::int8_t* const out_p = out.p.data();
    std::byte* const table = chain.table_.get();
    auto* const states = reinterpret_cast<PixelState*>(table);
    auto* const counts = reinterpret_cast<std::uint32_t*>(table + chain.counts_offset_);
    auto* const surface = reinterpret_cast<std::uint32_t*>(table + chain.surface_offset_);
    const auto width = static_cast<std::size_t>(chain.width_);
    const std::size_t stride = chain.surface_stride_;
    std::size_t kept = 0;
    for (std::size_t i = 0; i < size; ++i) {
      if (i + kPrefetchAhead < size) {
        const std::size_t ax = xs[i + kPrefetchAhead], ay = ys[i + kPrefetchAhead];
        if constexpr (kRecords) __builtin_prefetch(states + ay * width + ax, 1);
        if constexpr (kCounts) __builtin_prefetch(counts + ay * width + ax, 1);
        if constexpr (kSurface) {
          const std::uint32_t* const row = surface + ay * stride + ax;  // the row above, from the left neighbour
          __builtin_prefetch(row);
          __builtin_prefetch(row + 2);
          __builtin_prefetch(row + stride, 1);
          __builtin_prefetch(row + stride + 2, 1);
          __builtin_prefetch(row + 2 * stride);
          __builtin_prefetch(row + 2 * stride + 2);
        }
      }
      const Timestamp t = ts[i];
      const std::uint16_t x = xs[i], y = ys[i];
      const std::int8_t p = ps[i];
      [[maybe_unused]] const auto pixel = static_cast<std::uint32_t>(y * width + x);
      // In order, up to the first that drops the event.
      if (!(test<Ks>(chain, t, x, y, p, pixel, states, counts, surface, stride) && ...)) continue;
      out_t[kept] = t;  // kept <= i: safe in place
      out_x[kept] = x;
      out_y[kept] = y;
      out_p[kept] = p;
      ++kept;
    }
    out.truncate(kept);
    chain.passed_ += kept;
  }

  template <Kind K>
  static bool test(FilterChain& chain, Timestamp t, std::size_t x, std::size_t y, std::int8_t p, std::uint32_t pixel,
                   PixelState* states, std::uint32_t* counts, std::uint32_t* surface, std::size_t stride) {
    if constexpr (K == Kind::HotPixel) {
      return chain.hot_pixel_->pass(t, pixel, counts);
    } else if constexpr (K == Kind::AntiFlicker) {
      return chain.anti_flicker_->pass(t, states[pixel].flicker[p > 0 ? 1 : 0]);
    } else if constexpr (K == Kind::BackgroundActivity) {
      return chain.background_activity_->pass(t, surface + (y + 1) * stride + x + 1);
    } else {
      return chain.refractory_->pass(t, pixel, states);
    }
  }
};

template <filter_chain_detail::Kind... Ks>
void FilterChain::add_passes(std::array<PassFunction, kOrderCodes>& passes) {
  passes[order_code<Ks...>()] = &Pass<Ks...>::run;
  if constexpr (sizeof...(Ks) < 4) {
    if constexpr (((Ks != Kind::HotPixel) && ...)) add_passes<Ks..., Kind::HotPixel>(passes);
    if constexpr (((Ks != Kind::BackgroundActivity) && ...)) add_passes<Ks..., Kind::BackgroundActivity>(passes);
    if constexpr (((Ks != Kind::Refractory) && ...)) add_passes<Ks..., Kind::Refractory>(passes);
    if constexpr (((Ks != Kind::AntiFlicker) && ...)) add_passes<Ks..., Kind::AntiFlicker>(passes);
  }
}

FilterChain::FilterChain(const FilterConfig& config, SensorSize sensor) : width_(sensor.width) {
  check_filter_config(config);
  std::size_t code = 0, digit = 1;
  for (const std::string& name : config.chain) {
    Kind kind = Kind::AntiFlicker;
    if (name == "hot-pixel") {
      hot_pixel_.emplace(sensor, config.hot_pixel);
      kind = Kind::HotPixel;
    } else if (name == "background-activity") {
      background_activity_.emplace(sensor, config.background_window_us, config.background_min_noise_hz);
      kind = Kind::BackgroundActivity;
    } else if (name == "refractory") {
      refractory_.emplace(sensor, config.refractory_us);
      kind = Kind::Refractory;
    } else {
      anti_flicker_.emplace(config.anti_flicker);
    }
    code += digit * (static_cast<std::size_t>(kind) + 1);
    digit *= 5;
  }
  static const std::array<PassFunction, kOrderCodes> passes = [] {
    std::array<PassFunction, kOrderCodes> all{};
    add_passes<>(all);
    return all;
  }();
  pass_ = passes[code];
  const std::size_t pixels = static_cast<std::size_t>(sensor.width) * static_cast<std::size_t>(sensor.height);
  const std::size_t record_bytes = refractory_ || anti_flicker_ ? pixels * sizeof(PixelState) : 0;
  const std::size_t count_bytes = hot_pixel_ ? pixels * sizeof(std::uint32_t) : 0;
  const std::size_t surface_bytes =
      background_activity_ ? BackgroundActivityFilter::surface_size(sensor) * sizeof(std::uint32_t) : 0;
  const std::size_t table_bytes = record_bytes + count_bytes + surface_bytes;
  if (table_bytes > 0) {
    table_ = std::unique_ptr<std::byte, Unmap>(map_zeroed(table_bytes), Unmap{mapped_size(table_bytes)});
    counts_offset_ = record_bytes;
    surface_offset_ = record_bytes + count_bytes;
    surface_stride_ = BackgroundActivityFilter::surface_stride(sensor);
  }
}

void FilterChain::Unmap::operator()(std::byte* memory) const { munmap(memory, bytes); }

void FilterChain::filter(const EventBatch& in, EventBatch& out) {
  events_in_ += in.size();
  pass_(*this, in, out);
}

FilterCounts FilterChain::counts() const {
  FilterCounts counts;
  counts.events_in = events_in_;
  counts.passed = passed_;
  if (hot_pixel_) counts.hot_pixel = hot_pixel_->dropped();
  if (background_activity_) counts.background_activity = background_activity_->dropped();
  if (refractory_) counts.refractory = refractory_->dropped();
  if (anti_flicker_) counts.anti_flicker = anti_flicker_->dropped();
  return counts;
}

std::span<const std::uint32_t> FilterChain::masked_pixels() const {
  return hot_pixel_ ? hot_pixel_->masked_pixels() : std::span<const std::uint32_t>();
}

}  // namespace evldt
