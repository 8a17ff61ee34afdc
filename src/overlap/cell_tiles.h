#pragma once
// Per-cell tallies over the cells that regions and evidence touch, without
// sorting every (cell, observation) entry of a run: cells are found through
// their tile (64 x 64 plane cells, or 16^3 voxels) in a hash table, and each
// tile holds one slot per cell in flat arrays. Tiles are added before the
// parallel passes that count into them, so those passes only read the
// table. Internal: not installed.

#include "region_cells.h"

#include <atomic>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <unordered_map>
#include <vector>

namespace obsgroup {
namespace region_cells {

class CellTiles {
 public:
  static constexpr std::uint32_t kCellsPerTile = 4096;
  static constexpr std::size_t kNoSlot = ~std::size_t(0);

  /// Plane cells (keyOf<2>) or voxels (keyOf<3>).
  explicit CellTiles(bool planar) : planar_(planar) {}

  bool planar() const { return planar_; }

  /// The tile of a cell: its coordinates without their low 6 (plane) or 4 (voxel) bits.
  std::uint64_t tileOf(std::uint64_t key) const {
    if (planar_) return ((key >> 38) << 32) | ((key & 0xffffffffu) >> 6);
    constexpr std::uint64_t mask = (std::uint64_t(1) << 21) - 1;
    return ((key >> 46) << 42) | ((((key >> 21) & mask) >> 4) << 21) | ((key & mask) >> 4);
  }

  /// Adds a tile if it is new; tiles are numbered in the order they are added.
  void add(std::uint64_t tile) {
    if (index_.emplace(tile, std::uint32_t(tiles_.size())).second) tiles_.push_back(tile);
  }

  std::size_t tiles() const { return tiles_.size(); }
  std::size_t slots() const { return tiles_.size() * kCellsPerTile; }

  /// The key of a slot's cell.
  std::uint64_t keyOfSlot(std::size_t slot) const {
    const std::uint64_t tile = tiles_[slot / kCellsPerTile], cell = slot % kCellsPerTile;
    if (planar_) return ((tile >> 32) << 38 | (cell >> 6) << 32) | ((tile & 0xffffffffu) << 6 | (cell & 63));
    constexpr std::uint64_t mask = (std::uint64_t(1) << 21) - 1;
    const std::uint64_t x = (tile >> 42) << 4 | cell >> 8, y = ((tile >> 21) & mask) << 4 | ((cell >> 4) & 15),
                        z = (tile & mask) << 4 | (cell & 15);
    return x << 42 | y << 21 | z;
  }

  /// Finds slots, remembering the last tile: keys in ascending order mostly
  /// stay in one tile. One per thread; the table must not change meanwhile.
  class Lookup {
   public:
    explicit Lookup(const CellTiles& tiles) : tiles_(tiles) {}
    /// The slot of a key, kNoSlot when its tile was never added.
    std::size_t slot(std::uint64_t key) {
      const std::uint64_t tile = tiles_.tileOf(key);
      if (tile != last_tile_) {
        const auto it = tiles_.index_.find(tile);
        last_base_ = it == tiles_.index_.end() ? kNoSlot : std::size_t(it->second) * kCellsPerTile;
        last_tile_ = tile;
      }
      return last_base_ == kNoSlot ? kNoSlot : last_base_ + tiles_.cellInTile(key);
    }

    /// slot(key) for a key whose tile must have been added.
    std::size_t existingSlot(std::uint64_t key) {
      const std::size_t s = slot(key);
      if (s == kNoSlot) throw std::logic_error("CellTiles: a cell outside the tiles added for it");
      return s;
    }

   private:
    const CellTiles& tiles_;
    std::uint64_t last_tile_ = ~std::uint64_t(0);
    std::size_t last_base_ = kNoSlot;
  };

 private:
  std::uint32_t cellInTile(std::uint64_t key) const {
    if (planar_) return std::uint32_t(((key >> 32) & 63) << 6 | (key & 63));
    return std::uint32_t(((key >> 42) & 15) << 8 | ((key >> 21) & 15) << 4 | (key & 15));
  }

  bool planar_;
  std::unordered_map<std::uint64_t, std::uint32_t> index_;
  std::vector<std::uint64_t> tiles_;  // by index
};

/// Counters, one per slot, that threads add to at once. The sums are
/// integers, so they do not depend on the order of the additions.
class SlotCounters {
 public:
  explicit SlotCounters(std::size_t slots) : size_(slots), counts_(new std::atomic<std::uint32_t>[slots]) {
    for (std::size_t s = 0; s < slots; ++s) counts_[s].store(0, std::memory_order_relaxed);
  }
  /// Adds one; returns the count before.
  std::uint32_t increment(std::size_t slot) { return counts_[slot].fetch_add(1, std::memory_order_relaxed); }
  std::uint32_t get(std::size_t slot) const { return counts_[slot].load(std::memory_order_relaxed); }
  void set(std::size_t slot, std::uint32_t value) { counts_[slot].store(value, std::memory_order_relaxed); }
  std::size_t size() const { return size_; }

 private:
  std::size_t size_;
  std::unique_ptr<std::atomic<std::uint32_t>[]> counts_;
};

}  // namespace region_cells
}  // namespace obsgroup
