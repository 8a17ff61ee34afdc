#include "obsgroup/overlap/world_points.h"

#include <algorithm>
#include <numeric>

#include <omp.h>

namespace obsgroup {

void WorldPoints::appendAll(const std::vector<std::vector<Eigen::Vector3f>>& per_observation, int threads) {
  const std::size_t first = boxes.size();
  const int n = static_cast<int>(per_observation.size());
  for (const auto& observation_points : per_observation)
    offsets.push_back(offsets.back() + observation_points.size());
  points.resize(offsets.back());
  boxes.resize(first + per_observation.size());
#pragma omp parallel for num_threads(threads > 0 ? threads : omp_get_max_threads()) schedule(dynamic, 16)
  for (int i = 0; i < n; ++i) {
    const auto& observation_points = per_observation[i];
    Eigen::AlignedBox3f box;  // default-constructed: empty
    for (const auto& p : observation_points) box.extend(p);
    boxes[first + i] = box;
    std::copy(observation_points.begin(), observation_points.end(), points.begin() + offsets[first + i]);
  }
}

std::vector<std::vector<int>> overlappingBoxes(const WorldPoints& world, double delta) {
  const int n = world.size();
  std::vector<std::vector<int>> result(n);
  std::vector<int> order;
  for (int i = 0; i < n; ++i)
    if (!world.boxes[i].isEmpty()) order.push_back(i);
  // Sweep and prune along x: O(N log N + overlapping pairs), not O(N^2).
  std::sort(order.begin(), order.end(), [&world](int a, int b) {
    return world.boxes[a].min().x() < world.boxes[b].min().x() ||
           (world.boxes[a].min().x() == world.boxes[b].min().x() && a < b);
  });
  const float grow = static_cast<float>(delta) * (1.0f + 1e-5f);
  for (std::size_t a = 0; a < order.size(); ++a) {
    const Eigen::AlignedBox3f& box_a = world.boxes[order[a]];
    for (std::size_t b = a + 1; b < order.size(); ++b) {
      const Eigen::AlignedBox3f& box_b = world.boxes[order[b]];
      if (box_b.min().x() > box_a.max().x() + grow) break;
      if ((box_b.min().array() <= box_a.max().array() + grow).all() &&
          (box_a.min().array() <= box_b.max().array() + grow).all()) {
        result[order[a]].push_back(order[b]);
        result[order[b]].push_back(order[a]);
      }
    }
  }
  for (auto& list : result) std::sort(list.begin(), list.end());
  return result;
}

}  // namespace obsgroup
