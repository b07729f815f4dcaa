#include "evldt/scarf/scarf_lattice.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <stdexcept>
#include <string>

namespace evldt {

namespace {

// A LatticeEntry keeps 7 bits an axis of the place in a block's extended region (2b pixels).
constexpr int kMaxBlockSize = 1 << (LatticeEntry::kAxisBits - 1);

std::uint64_t next_lattice_id() {
  static std::atomic<std::uint64_t> next{1};
  return next.fetch_add(1, std::memory_order_relaxed);
}

}  // namespace

LatticeGeometry LatticeGeometry::make(SensorSize sensor, int block_size, double alpha) {
  if (!sensor.valid()) {
    throw std::invalid_argument(sensor.range_error());
  }
  if (block_size < 2 || block_size % 2 != 0 || block_size > kMaxBlockSize) {
    throw std::invalid_argument("block size " + std::to_string(block_size) + " must be even and in 2.." +
                                std::to_string(kMaxBlockSize));
  }
  if (!(alpha > 0.0) || !std::isfinite(alpha)) {
    throw std::invalid_argument("alpha must be a positive number");
  }
  LatticeGeometry g;
  g.sensor = sensor;
  g.block_size = block_size;
  g.blocks_x = sensor.width / block_size - 1;
  g.blocks_y = sensor.height / block_size - 1;
  const double capacity = std::floor(alpha * block_size * block_size / 2.0);
  if (!fits(sensor, block_size)) {
    throw std::invalid_argument("block size " + std::to_string(block_size) + " leaves no block on a " +
                                std::to_string(sensor.width) + "x" + std::to_string(sensor.height) + " sensor");
  }
  if (capacity < 3 || capacity > 65535) {
    throw std::invalid_argument("alpha * b * b / 2 = " + std::to_string(capacity) +
                                " entries per block is outside 3..65535");
  }
  g.capacity = static_cast<int>(capacity);
  return g;
}

int LatticeGeometry::block_at(float x, float y) const {
  const float u = (x - static_cast<float>(block_size / 2)) / static_cast<float>(block_size);
  const float v = (y - static_cast<float>(block_size / 2)) / static_cast<float>(block_size);
  if (!(u >= 0.0f) || !(v >= 0.0f)) return -1;  // also rejects NaN
  const int i = static_cast<int>(u);
  const int j = static_cast<int>(v);
  if (i >= blocks_x || j >= blocks_y) return -1;
  return index(i, j);
}

std::vector<ScarfLattice::AxisBlocks> ScarfLattice::axis_blocks(int length, int block_size, int blocks, int stride,
                                                                int shift) {
  std::vector<AxisBlocks> table(static_cast<std::size_t>(length));
  const int half = block_size / 2;
  for (int p = 0; p < length; ++p) {
    const int shifted = p - half;
    // floor division, so the margin before block 0 maps to block -1
    const int cell = shifted >= 0 ? shifted / block_size : -1;
    const int offset = shifted - cell * block_size;
    const int neighbour = offset < half ? cell - 1 : cell + 1;
    // A block's extended region begins at its index times b (half a block before its active region).
    if (cell >= 0 && cell < blocks) {
      table[p].home = cell * stride;
      table[p].home_bits = static_cast<std::uint16_t>((p - cell * block_size) << shift);
    }
    if (neighbour >= 0 && neighbour < blocks) {
      table[p].side = neighbour * stride;
      table[p].side_bits = static_cast<std::uint16_t>((p - neighbour * block_size) << shift);
    }
  }
  return table;
}

ScarfLattice::ScarfLattice(SensorSize sensor, int block_size, double alpha, bool keep_surface)
    : geometry_(LatticeGeometry::make(sensor, block_size, alpha)), id_(next_lattice_id()) {
  columns_ = axis_blocks(sensor.width, block_size, geometry_.blocks_x, 1, 0);
  rows_ = axis_blocks(sensor.height, block_size, geometry_.blocks_y, geometry_.blocks_x, LatticeEntry::kAxisBits);
  blocks_.resize(static_cast<std::size_t>(geometry_.block_count()));
  arrivals_.resize(static_cast<std::size_t>(geometry_.block_count()));
  entries_.resize(static_cast<std::size_t>(geometry_.block_count()) * geometry_.capacity);
  if (keep_surface) surface_.assign(static_cast<std::size_t>(sensor.width) * sensor.height, 0);
}

void ScarfLattice::insert(std::span<const std::uint16_t> xs, std::span<const std::uint16_t> ys, int copies) {
  const Rings rings = begin_change();
  const std::size_t n = std::min(xs.size(), ys.size());
  if (copies > 1) {  // apart, so the common loops keep their single pushes
    if (rings.surface == nullptr) {
      for (std::size_t i = 0; i < n; ++i) insert_event<false>(rings, xs[i], ys[i], copies);
    } else {
      for (std::size_t i = 0; i < n; ++i) insert_event<true>(rings, xs[i], ys[i], copies);
    }
  } else if (rings.surface == nullptr) {
    for (std::size_t i = 0; i < n; ++i) insert_event<false>(rings, xs[i], ys[i]);
  } else {
    for (std::size_t i = 0; i < n; ++i) insert_event<true>(rings, xs[i], ys[i]);
  }
}

void ScarfLattice::copy_state_from(const ScarfLattice& other) {
  if (other.geometry_.sensor != geometry_.sensor || other.geometry_.block_size != geometry_.block_size ||
      other.geometry_.capacity != geometry_.capacity) {
    throw std::invalid_argument("copy_state_from: lattices differ in geometry");
  }
  const bool same_source = copied_from_ == other.versions_of();
  const std::size_t capacity = static_cast<std::size_t>(geometry_.capacity);
  const std::size_t count = blocks_.size();
  const auto changed = [&](std::size_t block) {
    return !same_source || blocks_[block].version != other.blocks_[block].version;
  };
  // Runs of changed blocks are copied with one memcpy each: where most blocks changed this is a
  // plain copy of the lattice, where few did it touches only those.
  for (std::size_t begin = 0; begin < count;) {
    if (!changed(begin)) {
      ++begin;
      continue;
    }
    std::size_t end = begin + 1;
    while (end < count && changed(end)) ++end;
    std::copy(other.blocks_.begin() + static_cast<std::ptrdiff_t>(begin),
              other.blocks_.begin() + static_cast<std::ptrdiff_t>(end),
              blocks_.begin() + static_cast<std::ptrdiff_t>(begin));
    std::copy(other.arrivals_.begin() + static_cast<std::ptrdiff_t>(begin),
              other.arrivals_.begin() + static_cast<std::ptrdiff_t>(end),
              arrivals_.begin() + static_cast<std::ptrdiff_t>(begin));
    std::copy(other.entries_.begin() + static_cast<std::ptrdiff_t>(begin * capacity),
              other.entries_.begin() + static_cast<std::ptrdiff_t>(end * capacity),
              entries_.begin() + static_cast<std::ptrdiff_t>(begin * capacity));
    begin = end;
  }
  copied_from_ = other.versions_of();
  id_ = next_lattice_id();
  change_clock_ = std::max(change_clock_, other.change_clock_);
}

std::size_t ScarfLattice::memory_bytes() const {
  return entries_.size() * sizeof(LatticeEntry) + blocks_.size() * sizeof(BlockState) +
         arrivals_.size() * sizeof(std::uint16_t) + (columns_.size() + rows_.size()) * sizeof(AxisBlocks) +
         surface_.size() * sizeof(std::uint16_t);
}

void ScarfLattice::clear() {
  copied_from_ = 0;
  ++change_clock_;
  for (BlockState& state : blocks_) state = BlockState{.version = change_clock_};
  std::fill(surface_.begin(), surface_.end(), std::uint16_t{0});
}

}  // namespace evldt
