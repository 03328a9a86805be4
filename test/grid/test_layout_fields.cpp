// Layout and fields on 1, 2 and 3 ranks: halo exchange, node sums, repartition, neighbour tables.
#include "fields/field.hpp"

#include <gtest/gtest.h>
#include <Tpetra_Core.hpp>

#include <cmath>

using namespace cfdmpm;

namespace {

auto comm() { return Tpetra::getDefaultComm(); }

// A value that differs for every (global id, column) and is exact in double precision.
double known(long long gid, int column) { return double(gid) * 10.0 + column + 0.25; }

template <int Dim>
Grid<Dim> testGrid();
template <>
Grid<2> testGrid<2>() { return Grid<2>({0, 0, 0}, {1.3, 0.7, 0}, {26, 14, 1}, {5, 4, 1}); }
template <>
Grid<3> testGrid<3>() { return Grid<3>({0, 0, 0}, {1, 1, 1}, {12, 10, 9}, {4, 4, 3}); }

template <int Dim>
std::shared_ptr<const Layout<Dim>> makeLayout(const Grid<Dim>& grid, int ghost_width,
                                               const std::vector<double>& weight = {})
{
  return std::make_shared<const Layout<Dim>>(grid, partitionPatches(grid, comm()->getSize(), weight),
                                             ghost_width, comm());
}

template <int Dim>
void fillOwnedWithKnownValues(Field<Dim>& field, const Map& map)
{
  auto v = field.view();
  for (LocalOrdinal l = 0; l < field.overlapCount(); ++l)
    for (int c = 0; c < field.columns(); ++c)
      v(l, c) = l < field.ownedCount() ? known(map.getGlobalElement(l), c) : -1.0;
}

template <int Dim>
long long mismatches(const Field<Dim>& field, const Map& overlap_map)
{
  auto v = field.view();
  long long bad = 0;
  for (LocalOrdinal l = 0; l < field.overlapCount(); ++l)
    for (int c = 0; c < field.columns(); ++c)
      if (v(l, c) != known(overlap_map.getGlobalElement(l), c)) ++bad;
  return bad;
}

long long globalSum(long long local)
{
  long long total = 0;
  Teuchos::reduceAll(*comm(), Teuchos::REDUCE_SUM, local, Teuchos::outArg(total));
  return total;
}

}  // namespace

template <class T>
class LayoutTest : public ::testing::Test {};
using Dimensions = ::testing::Types<std::integral_constant<int, 2>, std::integral_constant<int, 3>>;
TYPED_TEST_SUITE(LayoutTest, Dimensions);

TYPED_TEST(LayoutTest, EveryGhostCellEqualsItsOwnerAfterHaloExchange)
{
  constexpr int Dim = TypeParam::value;
  const Grid<Dim> grid = testGrid<Dim>();
  for (int ghost_width : {1, 2}) {
    const auto layout = makeLayout(grid, ghost_width);
    Field<Dim> field(layout, Location::Cell, 3, "test");
    fillOwnedWithKnownValues(field, *layout->overlapCellMap());
    field.exchangeHalo();
    // Exact equality: a halo exchange copies values.
    EXPECT_EQ(globalSum(mismatches(field, *layout->overlapCellMap())), 0) << "ghost width " << ghost_width;
    // Every cell is owned exactly once.
    EXPECT_EQ(globalSum(layout->ownedCells()), grid.cellCount());
    EXPECT_EQ(globalSum(layout->ownedNodes()), grid.nodeCount());
  }
}

TYPED_TEST(LayoutTest, GhostLayersCoverTheStencilWidth)
{
  // Every owned cell's neighbours up to ghost_width away (inside the domain) are local.
  constexpr int Dim = TypeParam::value;
  const Grid<Dim> grid = testGrid<Dim>();
  const int ghost_width = 2;
  const auto layout = makeLayout(grid, ghost_width);
  const auto ijk = layout->cellIndex();
  const auto& lookup = layout->cellLookup();
  long long missing = 0;
  for (LocalOrdinal l = 0; l < layout->ownedCells(); ++l)
    for (int d = 0; d < Dim; ++d)
      for (int s = -ghost_width; s <= ghost_width; ++s) {
        long long q[3] = {ijk(l, 0), ijk(l, 1), Dim == 3 ? ijk(l, Dim - 1) : 0};
        q[d] += s;
        if (q[d] < 0 || q[d] >= grid.cells()[d]) continue;
        if (lookup(q[0], q[1], q[2]) < 0) ++missing;
      }
  EXPECT_EQ(missing, 0);
}

TYPED_TEST(LayoutTest, NeighbourTableAndBoundaryFacesAgreeWithIndices)
{
  constexpr int Dim = TypeParam::value;
  const Grid<Dim> grid = testGrid<Dim>();
  const auto layout = makeLayout(grid, 1);
  const auto ijk = layout->cellIndex();
  const auto neighbours = layout->cellNeighbours();
  long long wrong = 0;
  for (LocalOrdinal l = 0; l < layout->ownedCells(); ++l)
    for (int f = 0; f < 2 * Dim; ++f) {
      const int d = f / 2;
      const long long expected = ijk(l, d) + (f % 2 ? 1 : -1);
      const LocalOrdinal n = neighbours(l, f);
      if (expected < 0 || expected >= grid.cells()[d]) {
        wrong += (n != Layout<Dim>::kOutsideDomain);
      } else {
        wrong += (n < 0);
        if (n >= 0)
          for (int e = 0; e < Dim; ++e) wrong += (ijk(n, e) != (e == d ? expected : ijk(l, e)));
      }
    }
  EXPECT_EQ(globalSum(wrong), 0);
  for (int f = 0; f < 2 * Dim; ++f) {
    const long long face_cells = grid.cellCount() / grid.cells()[f / 2];
    EXPECT_EQ(globalSum(layout->boundaryCells(f).extent(0)), face_cells) << faceName(f);
  }
}

TYPED_TEST(LayoutTest, NodeSumAcrossRanksEqualsSerialSum)
{
  // Every owned cell adds a cell-dependent amount to its corner nodes, as a particle-to-grid
  // transfer does. The summed nodes must equal the sum computed serially over all cells.
  constexpr int Dim = TypeParam::value;
  const Grid<Dim> grid = testGrid<Dim>();
  const auto layout = makeLayout(grid, 1);
  Field<Dim> nodes(layout, Location::Node, 2, "node test");
  auto contribution = [](long long cell, int corner, int column) {
    return std::sin(0.37 * double(cell) + 1.1 * corner) + column;
  };
  {
    auto v = nodes.view();
    const auto corners = layout->cellNodes();
    const auto& cell_map = *layout->ownedCellMap();
    for (LocalOrdinal c = 0; c < layout->ownedCells(); ++c)
      for (int k = 0; k < Grid<Dim>::nodes_per_cell; ++k)
        for (int col = 0; col < 2; ++col) v(corners(c, k), col) += contribution(cell_map.getGlobalElement(c), k, col);
  }
  nodes.sumToOwners();

  // Serial reference: loop over every cell of the grid in global order.
  std::vector<double> reference(grid.nodeCount() * 2, 0.0);
  for (long long cell = 0; cell < grid.cellCount(); ++cell) {
    const auto ijk = grid.cellIndex(cell);
    for (int k = 0; k < Grid<Dim>::nodes_per_cell; ++k) {
      auto n = ijk;
      for (int d = 0; d < Dim; ++d) n[d] += (k >> d) & 1;
      for (int col = 0; col < 2; ++col) reference[grid.nodeId(n) * 2 + col] += contribution(cell, k, col);
    }
  }
  // At most 2^Dim terms of size <= 2 are summed in another order: the difference is a few ulps of
  // the sum; 1e-14 relative is ~45 ulps.
  const auto v = nodes.view();
  const auto& map = *layout->overlapNodeMap();
  long long bad = 0;
  double worst = 0;
  for (LocalOrdinal l = 0; l < nodes.overlapCount(); ++l)
    for (int col = 0; col < 2; ++col) {
      const double ref = reference[map.getGlobalElement(l) * 2 + col];
      const double err = std::abs(v(l, col) - ref) / std::max(1.0, std::abs(ref));
      worst = std::max(worst, err);
      bad += err > 1e-14;
    }
  EXPECT_EQ(globalSum(bad), 0) << "worst relative difference " << worst;
}

TYPED_TEST(LayoutTest, RepartitionPreservesEveryValue)
{
  constexpr int Dim = TypeParam::value;
  const Grid<Dim> grid = testGrid<Dim>();
  const auto before = makeLayout(grid, 2);
  // A different partition: patches near the origin weigh 5x.
  std::vector<double> weight(grid.patchCount());
  for (int p = 0; p < grid.patchCount(); ++p) weight[p] = grid.patchIndex(p)[0] == 0 ? 5.0 : 1.0;
  const auto after = makeLayout(grid, 2, weight);

  Field<Dim> cells(before, Location::Cell, 2, "cells");
  Field<Dim> nodes(before, Location::Node, 1, "nodes");
  fillOwnedWithKnownValues(cells, *before->overlapCellMap());
  fillOwnedWithKnownValues(nodes, *before->overlapNodeMap());
  cells.repartition(after);
  nodes.repartition(after);
  EXPECT_EQ(globalSum(cells.ownedCount()), grid.cellCount());
  EXPECT_EQ(globalSum(mismatches(cells, *after->overlapCellMap())), 0);
  EXPECT_EQ(globalSum(mismatches(nodes, *after->overlapNodeMap())), 0);
  if (comm()->getSize() > 1) {
    // The weights must actually have moved something, or this test proves nothing.
    long long moved = 0;
    for (std::size_t p = 0; p < after->decomposition().patch_owner.size(); ++p)
      moved += after->decomposition().patch_owner[p] != before->decomposition().patch_owner[p];
    EXPECT_GT(moved, 0);
  }
}
