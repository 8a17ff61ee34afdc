#pragma once
/// \file
/// The sensed-space overlap W of a set of observations that changes one
/// observation at a time (online grouping), kept equal to the batch
/// computation by recomputing only what a change can reach. Plain Eigen, no
/// PCL: the points come already filtered and in the common frame.

#include "obsgroup/common/interrupt.h"
#include "obsgroup/graph/observation_graph.h"
#include "obsgroup/overlap/sensed_regions.h"

#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

namespace obsgroup {

/// Psi (eq. 18) of a changing set of observations, each in a slot (its id).
///
/// What a change reaches, per model:
///  - points: only the pairs of the changed observation (Pi_ij depends on
///    the points of i and j alone);
///  - free space: the same, through the cells its beams cross;
///  - visibility: also every observation whose view reaches a cell whose
///    occupancy the change flipped (the occupancy grid is made of everyone's
///    points), however far from the changed one, unless that view read none
///    of the shared occupancy (it had a point of its own along every ray, as
///    a 360-degree scan in a closed room has: only its own surfaces stop it).
/// Those regions are recomputed with the batch code, and the shared-cell
/// counts patched by the difference of the old and new regions. The weights
/// are then those SensedSpaceOverlap::compute gives for the observations
/// present, in slot order, bit for bit, as long as the points are the same
/// bits (the caller re-centres them on the first observation present, as
/// SensedSpaceOverlap::toWorld does, and calls setAll when that changes).
class IncrementalOverlap {
 public:
  IncrementalOverlap(SensedSpaceModel model, double delta, const RegionParameters& params);
  ~IncrementalOverlap();
  IncrementalOverlap(IncrementalOverlap&&) noexcept;
  IncrementalOverlap& operator=(IncrementalOverlap&&) noexcept;

  /// Throws std::invalid_argument when the observation could not be added
  /// as `slot` (a point too far from the first observation for the region
  /// grid), before anything changes.
  void check(int slot, const std::vector<Eigen::Vector3f>& points, const Eigen::Vector3d& sensor_origin) const;
  /// Puts an observation in `slot` (new or replacing): points and sensor
  /// position in the re-centred common frame. Nothing is computed until update().
  void set(int slot, std::vector<Eigen::Vector3f> points, const Eigen::Vector3d& sensor_origin);
  /// Empties a slot.
  void erase(int slot);
  /// Forgets every computed overlap (the next update() recomputes all), e.g.
  /// after the caller re-centred every observation.
  void invalidate();

  /// Brings the overlap up to date and returns the slots whose row of W
  /// changed since the last update(), ascending. `threads`: 0 for all cores;
  /// the result does not depend on it.
  std::vector<int> update(int threads = 0, const InterruptFlag* interrupt = nullptr);
  /// The slots present whose own data changed in the last update(): points
  /// set, or a region recomputed to other cells. Every pair of W that
  /// changed has one of them at an end (or both), so a set of slots holding
  /// none of them has the same block of W (recursivePartition's sources).
  std::vector<int> sourcesOfLastUpdate() const;

  /// The slots present, ascending (node k of weightMatrix() is slots()[k]).
  std::vector<int> slots() const;
  /// W over slots() with the given diagonal (as buildWeightMatrix).
  WeightMatrix weightMatrix(double diagonal) const;
  /// The same W, with the columns of the rows unchanged since `previous`
  /// was built copied from it rather than computed again: `previous` must
  /// be the matrix the last weightMatrix() call returned (it is not used
  /// when its size, entry count or diagonal say otherwise, or when a slot it
  /// held moved to another position, as after a removal). Both overloads
  /// note what they built for the next call: not from two threads at once.
  WeightMatrix weightMatrix(double diagonal, const WeightMatrix* previous) const;
  /// The same, into `out`, whose storage is reused (an online update
  /// alternates two matrices instead of allocating one each time); `out`
  /// must not be `previous`.
  void weightMatrix(double diagonal, const WeightMatrix* previous, WeightMatrix& out) const;
  /// Points of a slot (M of eq. 17 for points); cells of its region for the
  /// region models.
  std::size_t pointCount(int slot) const;
  std::size_t regionCells(int slot) const;
  /// Visibility: whether the plane cell holding p (x and y in the re-centred
  /// frame) is occupied in the evidence of the observations present, as of
  /// the last update(): the cells SensedSpaceOverlap::compute gives in
  /// OverlapResult::occupied_cells for the same observations; always false
  /// for the other models. A function that remembers the tile it read last
  /// (walks along a line read the same tile again and again): for one caller
  /// at a time, until the next change.
  std::function<bool(const Eigen::Vector2d&)> planeCellReader() const;
  /// Observations whose region was recomputed by the last update() (the
  /// changed ones and, for visibility, those whose view a change reached).
  std::size_t recomputedLastUpdate() const;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace obsgroup
