// Partitions a user's own similarity matrix with obsgroup::core alone: two
// cliques of four joined by one weak edge give two groups.
#include <obsgroup/partition/recursive_partitioner.h>

#include <cstdio>
#include <vector>

int main() {
  std::vector<Eigen::Triplet<double>> entries;
  auto join = [&](int i, int j, double w) {
    entries.emplace_back(i, j, w);
    entries.emplace_back(j, i, w);
  };
  for (int clique = 0; clique < 2; ++clique)
    for (int i = 0; i < 4; ++i)
      for (int j = i + 1; j < 4; ++j) join(4 * clique + i, 4 * clique + j, 1.0);
  join(3, 4, 0.01);
  obsgroup::WeightMatrix W(8, 8);
  W.setFromTriplets(entries.begin(), entries.end());
  const obsgroup::Partition partition = obsgroup::recursivePartition(W);
  std::printf("core consumer: %zu groups\n", partition.groups.size());
  return partition.groups.size() == 2 ? 0 : 1;
}
