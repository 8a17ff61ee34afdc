// Sensed-space overlap, eq. (16)-(18), with both neighbour back-ends.
#include "test_support.h"

#include <obsgroup/overlap/sensed_space_overlap.h>

#include <pcl/search/kdtree.h>

#include <gtest/gtest.h>

#include <limits>
#include <stdexcept>

using namespace obsgroup;

namespace {

template <typename PointT>
typename pcl::PointCloud<PointT>::Ptr lineCloud(int count, double spacing) {
  typename pcl::PointCloud<PointT>::Ptr cloud(new pcl::PointCloud<PointT>);
  for (int k = 0; k < count; ++k) {
    PointT p;
    p.x = static_cast<float>(k * spacing);
    p.y = 0.0f;
    p.z = 0.0f;
    cloud->push_back(p);
  }
  return cloud;
}

template <typename PointT>
OverlapResult overlapWith(const std::vector<Observation<PointT>>& observations, NeighbourSearch method,
                          double delta = 0.1, double voxel = 0.0, int threads = 0) {
  SensedSpaceOverlap<PointT> sso;
  sso.setSensedSpaceModel(SensedSpaceModel::Points);  // eq. (16)-(17): what this file tests
  sso.setMatchDistance(delta);
  sso.setVoxelLeafSize(voxel);
  sso.setNeighbourSearch(method);
  sso.setNumberOfThreads(threads);
  return sso.compute(observations);
}

template <typename PointT>
void expectSameMatrix(const OverlapResult& a, const OverlapResult& b) {
  ASSERT_EQ(a.match_ratio.rows(), b.match_ratio.rows());
  ASSERT_EQ(a.match_ratio.nonZeros(), b.match_ratio.nonZeros());
  EXPECT_EQ((a.match_ratio - b.match_ratio).norm(), 0.0);
  ASSERT_EQ(a.pairs.size(), b.pairs.size());
  for (std::size_t k = 0; k < a.pairs.size(); ++k) {
    EXPECT_EQ(a.pairs[k].i, b.pairs[k].i);
    EXPECT_EQ(a.pairs[k].j, b.pairs[k].j);
    EXPECT_EQ(a.pairs[k].weight, b.pairs[k].weight);
  }
}

const NeighbourSearch kBackEnds[] = {NeighbourSearch::SharedGrid, NeighbourSearch::PclSearch};

}  // namespace

TEST(SensedSpaceOverlap, IdenticalCloudsGiveOne) {
  auto cloud = lineCloud<pcl::PointXYZ>(100, 0.05);
  const std::vector<Observation<pcl::PointXYZ>> obs{{cloud, pose2D(1, 2, 0.3)}, {cloud, pose2D(1, 2, 0.3)}};
  for (auto method : kBackEnds) {
    const OverlapResult r = overlapWith(obs, method);
    ASSERT_EQ(r.pairs.size(), 1u);
    EXPECT_EQ(r.pairs[0].weight, 1.0);
    EXPECT_EQ(r.match_ratio.coeff(0, 1), 1.0);
    EXPECT_EQ(r.match_ratio.coeff(1, 0), 1.0);
  }
}

TEST(SensedSpaceOverlap, DisjointCloudsGiveZeroAndNoQuery) {
  auto cloud = lineCloud<pcl::PointXYZ>(100, 0.05);
  const std::vector<Observation<pcl::PointXYZ>> obs{{cloud, pose2D(0, 0, 0)}, {cloud, pose2D(0, 10, 0)}};
  for (auto method : kBackEnds) {
    const OverlapResult r = overlapWith(obs, method);
    EXPECT_TRUE(r.pairs.empty());
    EXPECT_EQ(r.match_ratio.nonZeros(), 0);
    EXPECT_EQ(r.pairs_evaluated, 0u);
    EXPECT_EQ(r.point_tests, 0u);
  }
}

TEST(SensedSpaceOverlap, KnownHalfOverlap) {
  // 200 points on a 10 m line; the second copy is moved 5 m along it by its
  // pose: half of each cloud lies on the other.
  auto cloud = lineCloud<pcl::PointXYZ>(200, 0.05);
  const std::vector<Observation<pcl::PointXYZ>> obs{{cloud, pose2D(0, 0, 0)}, {cloud, pose2D(5, 0, 0)}};
  for (auto method : kBackEnds) {
    const OverlapResult r = overlapWith(obs, method, 0.01);
    EXPECT_NEAR(r.match_ratio.coeff(0, 1), 0.5, 0.01);
    EXPECT_NEAR(r.match_ratio.coeff(1, 0), 0.5, 0.01);
    ASSERT_EQ(r.pairs.size(), 1u);
    EXPECT_NEAR(r.pairs[0].weight, 0.5, 0.01);
  }
}

TEST(SensedSpaceOverlap, MatchAtExactlyDeltaCounts) {
  // eq. (16) uses <=: a point exactly delta away matches, one beyond does not.
  // 0.25 and its multiples are exact in binary, and 0.25 is a cell edge.
  pcl::PointCloud<pcl::PointXYZ>::Ptr a(new pcl::PointCloud<pcl::PointXYZ>), b(new pcl::PointCloud<pcl::PointXYZ>);
  a->push_back({0.0f, 0.0f, 0.0f});
  a->push_back({0.75f, 0.5f, 0.0f});
  a->push_back({2.0f, 0.0f, 0.0f});
  b->push_back({0.25f, 0.0f, 0.0f});                           // exactly delta from a[0]
  b->push_back({0.75f, 0.25f, 0.0f});                          // exactly delta from a[1]
  b->push_back({std::nextafter(2.25f, 3.0f), 0.0f, 0.0f});     // just beyond delta from a[2]
  const std::vector<Observation<pcl::PointXYZ>> obs{{a, Eigen::Isometry3d::Identity()},
                                                    {b, Eigen::Isometry3d::Identity()}};
  for (auto method : kBackEnds) {
    const OverlapResult r = overlapWith(obs, method, 0.25);
    EXPECT_DOUBLE_EQ(r.match_ratio.coeff(0, 1), 2.0 / 3.0);
    EXPECT_DOUBLE_EQ(r.match_ratio.coeff(1, 0), 2.0 / 3.0);
  }
}

TEST(SensedSpaceOverlap, PsiIsTheSymmetricMeanOfPi) {
  const auto plan = sim::threeRooms();
  const auto obs = test::simulate<pcl::PointXYZ>(plan, sim::threeRoomsPoses(4));
  const OverlapResult r = overlapWith(obs, NeighbourSearch::SharedGrid);
  ASSERT_FALSE(r.pairs.empty());
  bool asymmetric = false;
  for (const auto& p : r.pairs) {
    ASSERT_LT(p.i, p.j);
    const double pij = r.match_ratio.coeff(p.i, p.j), pji = r.match_ratio.coeff(p.j, p.i);
    EXPECT_DOUBLE_EQ(p.weight, 0.5 * (pij + pji));  // eq. (18)
    EXPECT_GT(p.weight, 0.0);
    EXPECT_LE(p.weight, 1.0);
    asymmetric = asymmetric || pij != pji;  // Fig. 4: Pi itself is not symmetric
  }
  EXPECT_TRUE(asymmetric);
}

TEST(SensedSpaceOverlap, BothBackEndsMatchABruteForceReference) {
  const auto plan = sim::threeRooms();
  const auto obs = test::simulate<pcl::PointXYZ>(plan, sim::threeRoomsPoses(3));
  const OverlapResult grid = overlapWith(obs, NeighbourSearch::SharedGrid);
  const OverlapResult kd = overlapWith(obs, NeighbourSearch::PclSearch);
  expectSameMatrix<pcl::PointXYZ>(grid, kd);
  for (std::size_t i = 0; i < obs.size(); ++i) {
    for (std::size_t j = 0; j < obs.size(); ++j) {
      if (i == j) continue;
      EXPECT_NEAR(grid.match_ratio.coeff(i, j), test::bruteForceMatchRatio(obs[i], obs[j], 0.1), 1e-12)
          << i << " " << j;
    }
  }
}

TEST(SensedSpaceOverlap, BothBackEndsGiveIdenticalMatricesOnARealLog) {
  const auto obs = test::realLog();
  ASSERT_EQ(obs.size(), 72u) << "data/real/localization_demo is missing";
  const OverlapResult grid = overlapWith(obs, NeighbourSearch::SharedGrid);
  const OverlapResult kd = overlapWith(obs, NeighbourSearch::PclSearch);
  expectSameMatrix<pcl::PointXYZ>(grid, kd);
  EXPECT_GT(grid.pairs.size(), 100u);
  // The grid never compares more pairs than the bounding-box candidates.
  EXPECT_LE(grid.pairs_evaluated, kd.pairs_evaluated);
}

TEST(SensedSpaceOverlap, UserSearchMethodGivesTheSameMatrix) {
  const auto obs = test::realLog(20);
  ASSERT_EQ(obs.size(), 20u);
  SensedSpaceOverlap<pcl::PointXYZ> sso;
  sso.setSensedSpaceModel(SensedSpaceModel::Points);
  sso.setSearchMethod(pcl::search::KdTree<pcl::PointXYZ>::Ptr(new pcl::search::KdTree<pcl::PointXYZ>));
  EXPECT_EQ(sso.getNeighbourSearch(), NeighbourSearch::PclSearch);
  expectSameMatrix<pcl::PointXYZ>(sso.compute(obs), overlapWith(obs, NeighbourSearch::SharedGrid));
}

TEST(SensedSpaceOverlap, VoxelDownsampling) {
  const auto plan = sim::threeRooms();
  const auto obs = test::simulate<pcl::PointXYZ>(plan, sim::threeRoomsPoses(3));
  const OverlapResult full = overlapWith(obs, NeighbourSearch::SharedGrid, 0.1, 0.0);
  const OverlapResult coarse = overlapWith(obs, NeighbourSearch::SharedGrid, 0.1, 0.3);
  for (std::size_t i = 0; i < obs.size(); ++i) {
    EXPECT_EQ(full.points_per_observation[i], obs[i].cloud->size());
    EXPECT_LT(coarse.points_per_observation[i], full.points_per_observation[i]);
    EXPECT_GT(coarse.points_per_observation[i], 0u);
  }
  // Same kind of answer, different values; both back-ends still agree.
  EXPECT_NE((full.match_ratio - coarse.match_ratio).norm(), 0.0);
  expectSameMatrix<pcl::PointXYZ>(coarse, overlapWith(obs, NeighbourSearch::PclSearch, 0.1, 0.3));
  // Identical clouds stay at 1 after downsampling.
  const std::vector<Observation<pcl::PointXYZ>> twins{obs[0], obs[0]};
  EXPECT_EQ(overlapWith(twins, NeighbourSearch::SharedGrid, 0.1, 0.3).pairs.at(0).weight, 1.0);
}

TEST(SensedSpaceOverlap, NonFinitePointsAreDropped) {
  auto cloud = lineCloud<pcl::PointXYZ>(10, 0.05);
  auto dirty = lineCloud<pcl::PointXYZ>(10, 0.05);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  dirty->push_back({nan, 0.0f, 0.0f});
  dirty->push_back({0.0f, std::numeric_limits<float>::infinity(), 0.0f});
  dirty->is_dense = true;  // wrongly: must not be trusted
  const std::vector<Observation<pcl::PointXYZ>> obs{{cloud, pose2D(0, 0, 0)}, {dirty, pose2D(0, 0, 0)}};
  for (auto method : kBackEnds) {
    const OverlapResult r = overlapWith(obs, method);
    EXPECT_EQ(r.points_per_observation[1], 10u);
    EXPECT_EQ(r.pairs.at(0).weight, 1.0);
  }
}

TEST(SensedSpaceOverlap, TwoDimensionalAndThreeDimensionalPointTypes) {
  const auto plan = sim::threeRooms();
  const auto poses = sim::threeRoomsPoses(2);
  // 2D scans with an intensity field.
  const auto flat = test::simulate<pcl::PointXYZI>(plan, poses);
  expectSameMatrix<pcl::PointXYZI>(overlapWith(flat, NeighbourSearch::SharedGrid),
                                   overlapWith(flat, NeighbourSearch::PclSearch));
  // 3D clouds (several heights: the grid probes 3x3x3 cells) with normals.
  const auto solid = test::simulate3D<pcl::PointNormal>(plan, poses, {0.0f, 0.07f, 0.5f, 1.0f});
  const OverlapResult grid = overlapWith(solid, NeighbourSearch::SharedGrid);
  expectSameMatrix<pcl::PointNormal>(grid, overlapWith(solid, NeighbourSearch::PclSearch));
  for (std::size_t i = 0; i < solid.size(); ++i) {
    for (std::size_t j = 0; j < solid.size(); ++j) {
      if (i == j) continue;
      EXPECT_NEAR(grid.match_ratio.coeff(i, j), test::bruteForceMatchRatio(solid[i], solid[j], 0.1), 1e-12);
    }
  }
  // Coloured clouds compile and run through the same code.
  const auto coloured = test::simulate<pcl::PointXYZRGB>(plan, poses);
  EXPECT_EQ(overlapWith(coloured, NeighbourSearch::SharedGrid).pairs.size(),
            overlapWith(flat, NeighbourSearch::SharedGrid).pairs.size());
}

TEST(SensedSpaceOverlap, ThreadCountDoesNotChangeTheMatrix) {
  const auto obs = test::realLog();
  ASSERT_EQ(obs.size(), 72u);
  for (auto method : kBackEnds)
    expectSameMatrix<pcl::PointXYZ>(overlapWith(obs, method, 0.1, 0.0, 1), overlapWith(obs, method, 0.1, 0.0, 2));
}

TEST(SensedSpaceOverlap, CrowdedDenseCloudsMatchTheBruteForceReference) {
  // Small 3D clouds crowded into a 0.6 m cube, each with many points in every
  // cell's neighbourhood, and some pairs exactly delta apart. With 50 clouds
  // a neighbourhood holds 33 to 50 observations (the match bits of a point fill
  // both halves of one word); with 150, more than 64 (several words).
  for (const int clouds : {50, 150}) {
    std::vector<Observation<pcl::PointXYZ>> obs;
    std::uint32_t state = 12345;
    const auto uniform = [&state]() {
      state = state * 1664525u + 1013904223u;
      return float(state >> 8) / float(1u << 24);
    };
    for (int i = 0; i < clouds; ++i) {
      pcl::PointCloud<pcl::PointXYZ>::Ptr cloud(new pcl::PointCloud<pcl::PointXYZ>);
      for (int k = 0; k < 40; ++k) cloud->push_back(pcl::PointXYZ(0.6f * uniform(), 0.6f * uniform(), 0.6f * uniform()));
      cloud->push_back(pcl::PointXYZ(0.25f * float(i % 3), 0.0f, 0.0f));  // 0.25 apart: at delta = 0.25 exactly
      obs.push_back({cloud, Eigen::Isometry3d::Identity()});
    }
    for (const double delta : {0.05, 0.25}) {
      const OverlapResult grid = overlapWith(obs, NeighbourSearch::SharedGrid, delta, 0.0, 2);
      expectSameMatrix<pcl::PointXYZ>(grid, overlapWith(obs, NeighbourSearch::PclSearch, delta));
      expectSameMatrix<pcl::PointXYZ>(grid, overlapWith(obs, NeighbourSearch::SharedGrid, delta, 0.0, 1));
      for (std::size_t i = 0; i < obs.size(); i += 7) {
        for (std::size_t j = 0; j < obs.size(); j += 5) {
          if (i == j) continue;
          EXPECT_NEAR(grid.match_ratio.coeff(i, j), test::bruteForceMatchRatio(obs[i], obs[j], delta), 1e-12)
              << clouds << " clouds: " << i << " " << j << " delta " << delta;
        }
      }
    }
  }
}

TEST(SensedSpaceOverlap, ProgressCountsObservationsAndEndsAtTheTotal) {
  const auto obs = test::realLog(20);
  for (auto method : kBackEnds) {
    SensedSpaceOverlap<pcl::PointXYZ> sso;
    sso.setSensedSpaceModel(SensedSpaceModel::Points);
    sso.setNeighbourSearch(method);
    std::vector<std::pair<std::size_t, std::size_t>> calls;
    sso.setProgressCallback([&calls](std::size_t done, std::size_t total) { calls.emplace_back(done, total); });
    sso.compute(obs);
    ASSERT_FALSE(calls.empty());
    for (const auto& [done, total] : calls) {
      EXPECT_EQ(total, obs.size());
      EXPECT_LE(done, total);
    }
    EXPECT_EQ(calls.back().first, obs.size());
  }
}

TEST(SensedSpaceOverlap, FarFromTheOriginEqualsAtTheOrigin) {
  // UTM-sized coordinates: the same map shifted by (500 km, 4000 km).
  const auto plan = sim::threeRooms();
  auto obs = test::simulate<pcl::PointXYZ>(plan, sim::threeRoomsPoses(3));
  const OverlapResult near = overlapWith(obs, NeighbourSearch::SharedGrid);
  for (auto& o : obs) o.pose.pretranslate(Eigen::Vector3d(5.0e5, 4.0e6, 0.0));
  expectSameMatrix<pcl::PointXYZ>(near, overlapWith(obs, NeighbourSearch::SharedGrid));
  expectSameMatrix<pcl::PointXYZ>(near, overlapWith(obs, NeighbourSearch::PclSearch));
}

TEST(SensedSpaceOverlap, RejectsBadInput) {
  auto cloud = lineCloud<pcl::PointXYZ>(10, 0.05);
  std::vector<Observation<pcl::PointXYZ>> obs{{cloud, pose2D(0, 0, 0)}, {nullptr, pose2D(0, 0, 0)}};
  EXPECT_THROW(overlapWith(obs, NeighbourSearch::SharedGrid), std::invalid_argument);
  obs[1].cloud = cloud;
  obs[1].pose.translation().x() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(overlapWith(obs, NeighbourSearch::SharedGrid), std::invalid_argument);
  obs[1].pose = pose2D(0, 0, 0);
  EXPECT_THROW(overlapWith(obs, NeighbourSearch::SharedGrid, 0.0), std::invalid_argument);
  EXPECT_THROW(overlapWith(obs, NeighbourSearch::SharedGrid, 0.1, -1.0), std::invalid_argument);
  // A voxel leaf too small for the cloud's extent is refused, not ignored.
  EXPECT_THROW(overlapWith(obs, NeighbourSearch::SharedGrid, 0.1, 1e-12), std::invalid_argument);
}

TEST(SensedSpaceOverlap, EmptyObservationMatchesNothing) {
  auto cloud = lineCloud<pcl::PointXYZ>(10, 0.05);
  pcl::PointCloud<pcl::PointXYZ>::Ptr empty(new pcl::PointCloud<pcl::PointXYZ>);
  const std::vector<Observation<pcl::PointXYZ>> obs{{cloud, pose2D(0, 0, 0)}, {empty, pose2D(0, 0, 0)}};
  for (auto method : kBackEnds) {
    const OverlapResult r = overlapWith(obs, method);
    EXPECT_TRUE(r.pairs.empty());
    EXPECT_EQ(r.points_per_observation[1], 0u);
  }
}

namespace {

/// A kd-tree that fails on its `fail_at`-th radius search, as a user's own
/// search object might.
class FailingSearch : public pcl::search::KdTree<pcl::PointXYZ> {
 public:
  explicit FailingSearch(int fail_at) : fail_at_(fail_at) {}
  int radiusSearch(const pcl::PointXYZ& point, double radius, pcl::Indices& k_indices,
                   std::vector<float>& k_sqr_distances, unsigned int max_nn = 0) const override {
    if (++calls_ == fail_at_) throw std::runtime_error("the user's search failed");
    return pcl::search::KdTree<pcl::PointXYZ>::radiusSearch(point, radius, k_indices, k_sqr_distances, max_nn);
  }

 private:
  int fail_at_;
  mutable int calls_ = 0;
};

}  // namespace

// The user's code runs inside parallel loops: its exception reaches the
// caller unchanged, on any thread count, never std::terminate.
TEST(SensedSpaceOverlap, ExceptionsOfTheUsersCodeReachTheCaller) {
  const auto obs = test::realLog(20);
  for (int threads : {1, 2, 4}) {
    for (auto method : kBackEnds) {
      SensedSpaceOverlap<pcl::PointXYZ> sso;
      sso.setSensedSpaceModel(SensedSpaceModel::Points);  // the parallel loops that report progress
      sso.setNeighbourSearch(method);
      sso.setNumberOfThreads(threads);
      // Every call throws: on one thread the first comes from inside the
      // loop; on more, thread 0 may get no index and the first be the last.
      sso.setProgressCallback([](std::size_t, std::size_t) { throw std::runtime_error("progress callback failed"); });
      try {
        sso.compute(obs);
        ADD_FAILURE() << "no exception";
      } catch (const std::runtime_error& e) {
        EXPECT_STREQ(e.what(), "progress callback failed");
      }
    }
    SensedSpaceOverlap<pcl::PointXYZ> sso;
    sso.setSensedSpaceModel(SensedSpaceModel::Points);
    sso.setNumberOfThreads(threads);
    sso.setSearchMethod(pcl::search::KdTree<pcl::PointXYZ>::Ptr(new FailingSearch(100)));
    try {
      sso.compute(obs);
      ADD_FAILURE() << "no exception";
    } catch (const std::runtime_error& e) {
      EXPECT_STREQ(e.what(), "the user's search failed");
    }
  }
}
