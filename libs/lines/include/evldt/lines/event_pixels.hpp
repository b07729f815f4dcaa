#pragma once
// "Is there an event near this point?" over a SCARF lattice, answered from pixel maps of the blocks'
// entries, each made as the questions first come to its block. Whole lines ask it along every gap,
// corner and end they may reach over (tens of points per line per step): a scan of a block's N
// entries per point was most of their time.

#include <cstdint>
#include <vector>

#include "evldt/lines/geometry.hpp"
#include "evldt/scarf/scarf_lattice.hpp"

namespace evldt {

class EventPixels {
 public:
  /// Answers from `lattice` (may be null: no events) until the next reset. The maps keep their memory.
  void reset(const ScarfLattice* lattice);
  /// Whether the block whose active region holds `at` holds an event at a pixel within `radius` (at
  /// most b/2) of it; its entries hold every event within b/2 of its active region. False off the blocks.
  [[nodiscard]] bool any_within(Point2 at, float radius);

 private:
  /// The map of `block`'s extended region (2b x 2b, row-major), made on first use in a step.
  const std::uint8_t* map_of(int block);

  const ScarfLattice* lattice_ = nullptr;
  int block_size_ = 0;
  std::vector<std::int32_t> map_index_;  ///< per block: its map's index in maps_, or -1
  std::vector<int> mapped_blocks_;       ///< blocks with a map this step
  std::vector<std::uint8_t> maps_;       ///< the maps, one after another
};

}  // namespace evldt
