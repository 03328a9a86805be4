// METIS partition of the patch graph: balance for uniform work, and a shift toward weights.
#include "grid/decomposition.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>

using namespace cfdmpm;

namespace {

std::vector<double> cellWeights(const Grid<2>& grid)
{
  std::vector<double> w(grid.patchCount());
  for (int p = 0; p < grid.patchCount(); ++p) w[p] = double(grid.patchCells(p).count());
  return w;
}

double imbalance(const std::vector<double>& load)
{
  const double mean = std::accumulate(load.begin(), load.end(), 0.0) / double(load.size());
  return *std::max_element(load.begin(), load.end()) / mean - 1.0;
}

}  // namespace

TEST(Decomposition, UniformGridIsBalancedWithinTenPercent)
{
  // 700 x 400 cells in 16 x 16 patches (44 x 25 = 1100 patches, edge patches smaller).
  const Grid<2> grid({0, 0, 0}, {3.5, 2.0, 0}, {700, 400, 1}, {16, 16, 1});
  for (int ranks : {2, 3, 4, 7, 16}) {
    const Decomposition dec = partitionPatches(grid, ranks);
    const auto load = rankLoads(dec, cellWeights(grid));
    // The bound: the heaviest rank within 10 % of the mean.
    EXPECT_LT(imbalance(load), 0.10) << ranks << " ranks";
    EXPECT_EQ(std::accumulate(load.begin(), load.end(), 0.0), double(grid.cellCount()));
  }
}

TEST(Decomposition, ThreeDimensionalGridIsBalanced)
{
  const Grid<3> grid({0, 0, 0}, {1, 1, 1}, {64, 48, 40}, {8, 8, 8});
  const Decomposition dec = partitionPatches(grid, 3);
  std::vector<double> w(grid.patchCount());
  for (int p = 0; p < grid.patchCount(); ++p) w[p] = double(grid.patchCells(p).count());
  EXPECT_LT(imbalance(rankLoads(dec, w)), 0.10);
}

TEST(Decomposition, HeavyPatchesShiftTheCut)
{
  // Patches in the left quarter carry 4x the work (particles there, say). The rank that gets them
  // must get fewer patches, and the weighted loads must again be balanced within 10 %.
  const Grid<2> grid({0, 0, 0}, {1, 1, 0}, {256, 128, 1}, {16, 16, 1});
  std::vector<double> w(grid.patchCount());
  for (int p = 0; p < grid.patchCount(); ++p)
    w[p] = (grid.patchIndex(p)[0] < 4 ? 4.0 : 1.0) * double(grid.patchCells(p).count());
  const Decomposition weighted = partitionPatches(grid, 2, w);
  const Decomposition uniform = partitionPatches(grid, 2);
  EXPECT_LT(imbalance(rankLoads(weighted, w)), 0.10);
  // Unweighted, the heavy work is lopsided (all of it on one side of a half-half cut).
  EXPECT_GT(imbalance(rankLoads(uniform, w)), 0.20);
  const int heavy_owner = weighted.patch_owner[0];
  const auto heavy_patches = weighted.patchesOf(heavy_owner).size();
  const auto light_patches = weighted.patchesOf(1 - heavy_owner).size();
  EXPECT_LT(heavy_patches, light_patches);
}

TEST(Decomposition, SameAnswerEveryCall)
{
  const Grid<2> grid({0, 0, 0}, {1, 1, 0}, {100, 100, 1}, {10, 10, 1});
  EXPECT_EQ(partitionPatches(grid, 3).patch_owner, partitionPatches(grid, 3).patch_owner);
}

TEST(Decomposition, TooFewPatchesNamesTheKey)
{
  const Grid<2> grid({0, 0, 0}, {1, 1, 0}, {16, 16, 1}, {16, 16, 1});
  try {
    partitionPatches(grid, 2);
    FAIL() << "one patch for two ranks must be refused";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("domain.patch_cells"), std::string::npos);
  }
}

TEST(Decomposition, RenumberedDivisionKeepsWorkWhereItIs)
{
  // The same division with its parts numbered the other way round moves nothing once renumbered;
  // a new division keeps each part on the rank that holds most of its work.
  const Grid<2> grid({0, 0, 0}, {1, 1, 0}, {128, 128, 1}, {16, 16, 1});
  const std::vector<double> w = cellWeights(grid);
  const Decomposition current = partitionPatches(grid, 4);
  Decomposition reversed = current;
  for (int& owner : reversed.patch_owner) owner = 3 - owner;
  EXPECT_EQ(closestNumbering(reversed, current, w).patch_owner, current.patch_owner);

  std::vector<double> heavy = w;
  for (int p = 0; p < grid.patchCount(); ++p)
    if (grid.patchIndex(p)[0] < 2) heavy[p] *= 3;  // particles gathered at the left
  const Decomposition balanced = closestNumbering(partitionPatches(grid, 4, heavy), current, heavy);
  int moved = 0, moved_unnumbered = 0;
  const Decomposition fresh = partitionPatches(grid, 4, heavy);
  for (int p = 0; p < grid.patchCount(); ++p) {
    moved += balanced.patch_owner[p] != current.patch_owner[p];
    moved_unnumbered += fresh.patch_owner[p] != current.patch_owner[p];
  }
  EXPECT_LE(moved, moved_unnumbered);
  EXPECT_LT(moved, grid.patchCount() / 2) << "a renumbered division should keep most patches in place";
  // Renumbering changes no rank's load, only which rank carries it.
  std::vector<double> a = rankLoads(balanced, heavy), b = rankLoads(fresh, heavy);
  std::sort(a.begin(), a.end());
  std::sort(b.begin(), b.end());
  EXPECT_EQ(a, b);
}

TEST(Decomposition, ImbalanceAndWork)
{
  EXPECT_DOUBLE_EQ(loadImbalance({1.0, 1.0, 1.0}), 0.0);
  EXPECT_DOUBLE_EQ(loadImbalance({3.0, 1.0}), 0.5);  // the heavier rank has 1.5 times the mean
  // A patch's work: its cells, and particle_work per particle; the last patch in x is smaller.
  const Grid<2> grid({0, 0, 0}, {1, 1, 0}, {24, 16, 1}, {16, 16, 1});
  const PatchWork work = patchWork(grid, {10, 20}, 0.5);
  EXPECT_EQ(work.cells, cellWeights(grid));
  EXPECT_EQ(work.particles, (std::vector<double>{5.0, 10.0}));
  EXPECT_EQ(work.total(), (std::vector<double>{261.0, 138.0}));
  EXPECT_EQ(patchWork(grid, {}, 0.5).particles, (std::vector<double>{0.0, 0.0}));
  // Cells that rigid bodies fill weigh kClosedCellWork of an open one; a patch all closed still
  // weighs at least one cell (METIS's first constraint must stay positive).
  const PatchWork shut = patchWork(grid, {}, 0.5, {100, 128});
  EXPECT_DOUBLE_EQ(shut.cells[0], 256.0 - (1.0 - kClosedCellWork) * 100);
  EXPECT_DOUBLE_EQ(shut.cells[1], 128.0 - (1.0 - kClosedCellWork) * 128);
  const Grid<2> tiny({0, 0, 0}, {1, 1, 0}, {2, 2, 1}, {1, 1, 1});
  EXPECT_DOUBLE_EQ(patchWork(tiny, {}, 0.5, {1, 1, 1, 1}).cells[0], 1.0);
  // Each phase waits for its slowest rank: rank 0 with the most cells and rank 1 with the most
  // particles make a step of 256 + 10 against a balanced (384 + 15) / 2.
  Decomposition two;
  two.ranks = 2;
  two.patch_owner = {0, 1};
  EXPECT_DOUBLE_EQ(loadImbalance(two, work), (256.0 + 10.0) / ((384.0 + 15.0) / 2) - 1);
}

TEST(Decomposition, CellsAndParticlesAreBalancedEachOnItsOwn)
{
  // Particles in the left eighth of a grid, 16 per cell at 0.14 cells each: by total work alone a
  // rank gets the particles' patches and few cells, the others many cells; with two constraints
  // every rank gets about as many cells and as many particles as the others.
  const Grid<2> grid({0, 0, 0}, {1, 1, 0}, {256, 128, 1}, {8, 8, 1});
  std::vector<long long> particles(grid.patchCount(), 0);
  for (int p = 0; p < grid.patchCount(); ++p)
    if (grid.patchIndex(p)[0] < 4) particles[p] = 16 * 64;
  const PatchWork work = patchWork(grid, particles, 0.14);
  for (int ranks : {2, 4, 16}) {
    const Decomposition both = partitionPatches(grid, ranks, work);
    const Decomposition total = partitionPatches(grid, ranks, work.total());
    EXPECT_LT(loadImbalance(rankLoads(both, work.cells)), 0.10) << ranks << " ranks";
    EXPECT_LT(loadImbalance(rankLoads(both, work.particles)), 0.10) << ranks << " ranks";
    EXPECT_LT(loadImbalance(both, work), loadImbalance(total, work)) << ranks << " ranks";
  }
}

TEST(Decomposition, EveryCellIsInItsPatch)
{
  // Patches of 16 x 16 and 5 x 7 x 3, the last in each direction smaller.
  const Grid<2> plane({0, 0, 0}, {1, 1, 0}, {24, 16, 1}, {16, 16, 1});
  const Grid<3> box({0, 0, 0}, {1, 1, 1}, {11, 9, 4}, {5, 7, 3});
  const auto check = [](const auto& grid) {
    for (int p = 0; p < grid.patchCount(); ++p) {
      const Box cells = grid.patchCells(p);
      for (long long k = cells.lower[2]; k < cells.upper[2]; ++k)
        for (long long j = cells.lower[1]; j < cells.upper[1]; ++j)
          for (long long i = cells.lower[0]; i < cells.upper[0]; ++i) EXPECT_EQ(grid.patchOfCell({i, j, k}), p);
    }
  };
  check(plane);
  check(box);
}
