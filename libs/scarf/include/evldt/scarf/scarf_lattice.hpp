#pragma once
// SCARF: "Set of Centre Active Receptive Fields" (docs/design.md, section 3).
//
// The sensor is tiled by b x b blocks with a half-block margin. Each block keeps a fixed ring of the
// N most recent events that fell into its active region (ACTIVE) or into the half-block band around
// it (INACTIVE). Because a block holds a fixed number of events rather than a time window, an edge
// leaves the same number of active entries whatever its speed; inactive entries push stale active
// ones out once an edge has left the block.
//
// Coordinates: pixel (x, y) covers [x, x+1) x [y, y+1) in continuous image coordinates, so block
// (i, j) covers [b/2 + i*b, b/2 + (i+1)*b) x [b/2 + j*b, b/2 + (j+1)*b) and block borders lie on
// integer lattice lines.

#include <cstdint>
#include <span>
#include <vector>

#include "evldt/events/event.hpp"

namespace evldt {

/// One ring-buffer entry in 2 bytes: the pixel relative to its block's extended region (which spans
/// 2b <= 128 pixels each way, so 7 bits an axis) and the ACTIVE flag. Half the bytes of absolute
/// coordinates: storage, the rounds' lattice snapshots and their point gathering touch half the memory.
struct LatticeEntry {
  std::uint16_t bits = 0;

  static constexpr std::uint16_t kActiveBit = 0x8000;
  static constexpr int kAxisBits = 7;
  static constexpr LatticeEntry make(int dx, int dy, bool active) {
    return {static_cast<std::uint16_t>(dx | (dy << kAxisBits) | (active ? kActiveBit : 0))};
  }
  [[nodiscard]] int dx() const { return bits & 0x7f; }
  [[nodiscard]] int dy() const { return (bits >> kAxisBits) & 0x7f; }
  [[nodiscard]] bool active() const { return (bits & kActiveBit) != 0; }
};

/// A block's entries and where its extended region begins: entry e lies at pixel
/// (origin_x + e.dx(), origin_y + e.dy()).
struct BlockEntries {
  std::span<const LatticeEntry> entries;
  int origin_x = 0;
  int origin_y = 0;
  [[nodiscard]] int pixel_x(LatticeEntry e) const { return origin_x + e.dx(); }
  [[nodiscard]] int pixel_y(LatticeEntry e) const { return origin_y + e.dy(); }
};

/// Size and placement of the blocks. Block index = j * blocks_x + i.
struct LatticeGeometry {
  SensorSize sensor;
  int block_size = 0;  ///< b, even
  int blocks_x = 0;    ///< floor(W / b) - 1
  int blocks_y = 0;    ///< floor(H / b) - 1
  int capacity = 0;    ///< N = floor(alpha * b * b / 2) entries per block

  /// Throws std::invalid_argument with a clear message on an unusable combination.
  static LatticeGeometry make(SensorSize sensor, int block_size, double alpha);
  /// True if the sensor is valid and holds at least one block of that size (two block sides each way).
  static bool fits(SensorSize sensor, int block_size) {
    return sensor.valid() && block_size > 0 && sensor.width / block_size >= 2 && sensor.height / block_size >= 2;
  }

  [[nodiscard]] int block_count() const { return blocks_x * blocks_y; }
  [[nodiscard]] int index(int i, int j) const { return j * blocks_x + i; }
  [[nodiscard]] int column(int block) const { return block % blocks_x; }
  [[nodiscard]] int row(int block) const { return block / blocks_x; }
  [[nodiscard]] float origin_x(int i) const { return static_cast<float>(block_size / 2 + i * block_size); }
  [[nodiscard]] float origin_y(int j) const { return static_cast<float>(block_size / 2 + j * block_size); }
  /// Block whose active region holds the continuous point, or -1.
  [[nodiscard]] int block_at(float x, float y) const;
  /// Fewest active points a block (or a line's blocks) must hold to be worth fitting: max(N/10, 3).
  [[nodiscard]] int min_points() const { return capacity / 10 > 3 ? capacity / 10 : 3; }
};

class ScarfLattice {
 public:
  /// keep_surface: maintain the per-pixel count of active entries (for display); costs a little per event.
  ScarfLattice(SensorSize sensor, int block_size, double alpha, bool keep_surface = false);
  // A copy would share the id versions are compared under; copy_state_from is the way to copy.
  ScarfLattice(const ScarfLattice&) = delete;
  ScarfLattice& operator=(const ScarfLattice&) = delete;
  ScarfLattice(ScarfLattice&&) = default;
  ScarfLattice& operator=(ScarfLattice&&) = default;

  /// Stores one on-sensor event (the caller validates coordinates). O(1), never allocates.
  void insert(std::uint16_t x, std::uint16_t y) {
    const Rings rings = begin_change();
    if (rings.surface == nullptr) {
      insert_event<false>(rings, x, y);
    } else {
      insert_event<true>(rings, x, y);
    }
  }
  /// Stores the on-sensor events (xs[i], ys[i]) in order; the spans have the same length. With
  /// `copies` > 1 each event is stored that many times, as that many inserts of it would (the rings
  /// end the same; below 2, once): the events of a thinned stream, stored in copies, fill a block's
  /// ring faster, so it reaches back less far in time (RealtimeEngine::stored_copies).
  void insert(std::span<const std::uint16_t> xs, std::span<const std::uint16_t> ys, int copies = 1);
  void insert(const EventBatch& batch) { insert(batch.x, batch.y); }

  [[nodiscard]] const LatticeGeometry& geometry() const { return geometry_; }
  /// The entries a block currently holds (at most N, in no particular order).
  [[nodiscard]] BlockEntries entries(int block) const {
    return {{entries_.data() + static_cast<std::size_t>(block) * geometry_.capacity, blocks_[block].filled},
            geometry_.column(block) * geometry_.block_size,
            geometry_.row(block) * geometry_.block_size};
  }
  [[nodiscard]] int active_count(int block) const { return blocks_[block].active; }
  /// ACTIVE entries written into the block so far, modulo 2^16: the difference of two readings (as
  /// std::uint16_t) is how many came between them, up to 65535.
  [[nodiscard]] std::uint16_t active_arrivals(int block) const { return arrivals_[static_cast<std::size_t>(block)]; }
  /// When the block last changed (events written, clear), on a clock that advances once per insert
  /// call: equal values mean identical contents, so a reader can skip a block it has already seen
  /// in this state.
  [[nodiscard]] std::uint64_t version(int block) const { return blocks_[block].version; }
  /// Which lattice the versions count the changes of: this one's id, or that of the lattice this is
  /// an unmodified copy of (copy_state_from). Versions compare only under the same value.
  [[nodiscard]] std::uint64_t versions_of() const { return copied_from_ ? copied_from_ : id_; }
  /// Per-pixel number of active entries, row-major W x H; empty unless keep_surface was set.
  [[nodiscard]] const std::vector<std::uint16_t>& surface() const { return surface_; }

  /// Makes this lattice's rings equal to those of a lattice of the same geometry, without allocating
  /// (the surface is not copied): only the blocks whose version differs are copied, so a view kept
  /// up to date costs what changed since its last update. Used by the real-time engine to give each
  /// loop a consistent view.
  void copy_state_from(const ScarfLattice& other);
  /// Bytes of storage held (rings, block states, lookup tables, surface).
  [[nodiscard]] std::size_t memory_bytes() const;
  void clear();

 private:
  struct alignas(16) BlockState {
    std::uint16_t head = 0;     ///< next slot to overwrite
    std::uint16_t filled = 0;   ///< slots in use (reaches N and stays)
    std::uint16_t active = 0;   ///< ACTIVE entries among them
    std::uint64_t version = 0;  ///< the change clock when the block last changed
  };
  /// Per pixel column (row): the block column (row) whose active region holds it, and the one on
  /// the side of the half it lies in, whose extended region also holds it; -1 where there is none.
  /// Rows are pre-multiplied by blocks_x so a block index is a single add; the pixel's place in
  /// each block's extended region is pre-shifted to its bits in an entry, so an entry is an or.
  struct AxisBlocks {
    std::int32_t home = -1;
    std::int32_t side = -1;
    std::uint16_t home_bits = 0;
    std::uint16_t side_bits = 0;
  };
  /// The table of one axis of `length` pixels, `blocks` blocks, block indices scaled by `stride`,
  /// offsets shifted left by `shift`.
  static std::vector<AxisBlocks> axis_blocks(int length, int block_size, int blocks, int stride, int shift);
  /// What the insert loop works with, held in locals: stores into the rings could otherwise alias
  /// members the compiler would then reload at every event.
  struct Rings {
    const AxisBlocks* columns;
    const AxisBlocks* rows;
    BlockState* blocks;
    std::uint16_t* arrivals;  ///< per block, ACTIVE entries written modulo 2^16
    LatticeEntry* entries;
    std::uint16_t* surface;  ///< null without keep_surface
    std::size_t width;
    int blocks_x, block_size;  ///< where an evicted entry lay, for the surface
    std::uint16_t capacity;
    std::uint64_t version;  ///< what every block this call writes takes as its version
  };

  Rings begin_change() {
    copied_from_ = 0;
    ++change_clock_;
    return {columns_.data(),
            rows_.data(),
            blocks_.data(),
            arrivals_.data(),
            entries_.data(),
            surface_.empty() ? nullptr : surface_.data(),
            static_cast<std::size_t>(geometry_.sensor.width),
            geometry_.blocks_x,
            geometry_.block_size,
            static_cast<std::uint16_t>(geometry_.capacity),
            change_clock_};
  }

  /// Pushes the event, `copies` times, into each block that holds it: an event's blocks are
  /// distinct, so pushing its copies block by block ends as inserting it `copies` times over.
  template <bool kSurface>
  static void insert_event(const Rings& rings, std::uint16_t x, std::uint16_t y, int copies = 1) {
    const AxisBlocks column = rings.columns[x];
    const AxisBlocks row = rings.rows[y];
    if ((column.home | row.home) >= 0)
      push<kSurface, true>(rings, row.home + column.home, column.home_bits | row.home_bits, x, y, copies);
    if ((column.side | row.home) >= 0)
      push<kSurface, false>(rings, row.home + column.side, column.side_bits | row.home_bits, x, y, copies);
    if ((column.home | row.side) >= 0)
      push<kSurface, false>(rings, row.side + column.home, column.home_bits | row.side_bits, x, y, copies);
    if ((column.side | row.side) >= 0)
      push<kSurface, false>(rings, row.side + column.side, column.side_bits | row.side_bits, x, y, copies);
  }

  // Branch-free bookkeeping: whether the overwritten entry was active is data (about a third of
  // entries are), and a branch on it mispredicts. The block's state stays in registers over the copies.
  template <bool kSurface, bool kActive>
  static void push(const Rings& rings, std::int32_t block, std::uint16_t place_bits, std::uint16_t x, std::uint16_t y,
                   int copies) {
    BlockState state = rings.blocks[block];
    LatticeEntry* const ring = rings.entries + static_cast<std::size_t>(block) * rings.capacity;
    const LatticeEntry entry{static_cast<std::uint16_t>(kActive ? place_bits | LatticeEntry::kActiveBit : place_bits)};
    for (int c = 0; c < copies; ++c) {
      LatticeEntry& slot = ring[state.head];
      const auto full = static_cast<std::uint16_t>(state.filled == rings.capacity);
      const auto evicted_active = static_cast<std::uint16_t>(full & (slot.bits >> 15));
      if constexpr (kSurface) {
        if (evicted_active) {
          const std::size_t ex = static_cast<std::size_t>(block % rings.blocks_x * rings.block_size + slot.dx());
          const std::size_t ey = static_cast<std::size_t>(block / rings.blocks_x * rings.block_size + slot.dy());
          --rings.surface[ey * rings.width + ex];
        }
        if (kActive) ++rings.surface[static_cast<std::size_t>(y) * rings.width + x];
      } else {
        (void)x;
        (void)y;
      }
      state.filled = static_cast<std::uint16_t>(state.filled + 1 - full);
      state.active = static_cast<std::uint16_t>(state.active + (kActive ? 1 : 0) - evicted_active);
      slot = entry;
      const auto next = static_cast<std::uint16_t>(state.head + 1);
      state.head = next == rings.capacity ? std::uint16_t{0} : next;
    }
    state.version = rings.version;
    if constexpr (kActive) rings.arrivals[block] = static_cast<std::uint16_t>(rings.arrivals[block] + copies);
    rings.blocks[block] = state;
  }

  LatticeGeometry geometry_;
  std::vector<AxisBlocks> columns_, rows_;
  std::vector<BlockState> blocks_;
  // Apart from the block states: a fourth 16-bit field there made storage 10-20% slower (the
  // compiler then copied the whole state through more registers at every push).
  std::vector<std::uint16_t> arrivals_;
  std::vector<LatticeEntry> entries_;
  // Versions are only comparable with the lattice they were copied from: a process-unique id (a
  // fresh one at every copy, so changes after a copy are numbered apart from those before), and
  // the id of the lattice this one is an unmodified copy of (0: none).
  std::uint64_t id_;
  std::uint64_t copied_from_ = 0;
  std::uint64_t change_clock_ = 0;  ///< +1 per insert call or clear; never below a version held
  std::vector<std::uint16_t> surface_;
};

}  // namespace evldt
