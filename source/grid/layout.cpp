#include "grid/layout.hpp"

#include <algorithm>
#include <unordered_set>

namespace cfdmpm {

namespace {

using Ijk = std::array<long long, 3>;

// Calls f(ijk) for every index in box b, x fastest.
template <class F>
void forEach(const Box& b, F&& f)
{
  for (long long k = b.lower[2]; k < b.upper[2]; ++k)
    for (long long j = b.lower[1]; j < b.upper[1]; ++j)
      for (long long i = b.lower[0]; i < b.upper[0]; ++i) f(Ijk{i, j, k});
}

// Owned ids first (sorted), then ghosts (sorted, without the owned ones).
std::vector<GlobalOrdinal> ownedThenGhosts(std::vector<GlobalOrdinal> owned, std::vector<GlobalOrdinal> all)
{
  std::sort(owned.begin(), owned.end());
  std::sort(all.begin(), all.end());
  all.erase(std::unique(all.begin(), all.end()), all.end());
  std::vector<GlobalOrdinal> ghosts;
  std::set_difference(all.begin(), all.end(), owned.begin(), owned.end(), std::back_inserter(ghosts));
  owned.insert(owned.end(), ghosts.begin(), ghosts.end());
  return owned;
}

Teuchos::RCP<const Map> makeMap(const std::vector<GlobalOrdinal>& gids,
                                const Teuchos::RCP<const Teuchos::Comm<int>>& comm)
{
  const Tpetra::global_size_t invalid = Teuchos::OrdinalTraits<Tpetra::global_size_t>::invalid();
  return Teuchos::rcp(new Map(invalid, Teuchos::ArrayView<const GlobalOrdinal>(gids.data(), gids.size()), 0, comm));
}

// Global (i, j, k) of every local id, and the dense lookup over their bounding box.
template <int Dim>
void indexTables(const std::vector<GlobalOrdinal>& gids, const Ijk& counts,
                 Kokkos::View<int**, MemorySpace>& ijk_table, BoxLookup& lookup, const char* label)
{
  const std::size_t n = gids.size();
  ijk_table = Kokkos::View<int**, MemorySpace>(std::string(label) + " ijk", n, Dim);
  auto ijk_host = Kokkos::create_mirror_view(ijk_table);
  Ijk lo{0, 0, 0}, hi{1, 1, 1};
  for (int d = 0; d < 3; ++d) lo[d] = counts[d], hi[d] = -1;
  for (std::size_t l = 0; l < n; ++l) {
    const Ijk ijk = Grid<Dim>::unlinear(gids[l], counts);
    for (int d = 0; d < 3; ++d) {
      if (d < Dim) ijk_host(l, d) = int(ijk[d]);
      lo[d] = std::min(lo[d], ijk[d]);
      hi[d] = std::max(hi[d], ijk[d]);
    }
  }
  Kokkos::deep_copy(ijk_table, ijk_host);

  long long size = 1;
  for (int d = 0; d < 3; ++d) {
    if (n == 0) lo[d] = 0, hi[d] = -1;
    lookup.lower[d] = lo[d];
    lookup.extent[d] = hi[d] - lo[d] + 1;
    size *= lookup.extent[d];
  }
  lookup.lid = Kokkos::View<LocalOrdinal*, MemorySpace>(std::string(label) + " lookup", std::max(size, 0LL));
  auto lid_host = Kokkos::create_mirror_view(lookup.lid);
  Kokkos::deep_copy(lid_host, LocalOrdinal(-2));
  for (std::size_t l = 0; l < n; ++l) {
    const Ijk ijk = Grid<Dim>::unlinear(gids[l], counts);
    lid_host((ijk[0] - lo[0]) + lookup.extent[0] * ((ijk[1] - lo[1]) + lookup.extent[1] * (ijk[2] - lo[2]))) =
        LocalOrdinal(l);
  }
  Kokkos::deep_copy(lookup.lid, lid_host);
}

// A host-side copy of a lookup, for building tables.
auto hostLookup(const BoxLookup& lookup)
{
  auto lid = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), lookup.lid);
  return [lid, lookup](const Ijk& q) -> LocalOrdinal {
    long long a[3];
    for (int d = 0; d < 3; ++d) {
      a[d] = q[d] - lookup.lower[d];
      if (a[d] < 0 || a[d] >= lookup.extent[d]) return -2;
    }
    return lid(a[0] + lookup.extent[0] * (a[1] + lookup.extent[1] * a[2]));
  };
}

}  // namespace

template <int Dim>
Layout<Dim>::Layout(const Grid<Dim>& grid, const Decomposition& decomposition, int ghost_width,
                    Teuchos::RCP<const Teuchos::Comm<int>> comm)
    : grid_(grid), decomposition_(decomposition), ghost_width_(ghost_width), comm_(comm)
{
  if (ghost_width < 1) throw std::invalid_argument("Layout: ghost width must be >= 1");
  if (decomposition.ranks != comm->getSize())
    throw std::invalid_argument("Layout: decomposition is for " + std::to_string(decomposition.ranks) +
                                " ranks, the communicator has " + std::to_string(comm->getSize()));
  patches_ = decomposition.patchesOf(comm->getRank());

  // 1. Cells: owned = the patches' cells; ghosts = cells within ghost_width (in every direction,
  //    diagonals included) of an owned cell.
  std::vector<GlobalOrdinal> owned_cells, all_cells;
  for (int p : patches_) {
    const Box b = grid.patchCells(p);
    forEach(b, [&](const Ijk& c) { owned_cells.push_back(grid.cellId(c)); });
    Box wide = b;
    for (int d = 0; d < Dim; ++d) {
      wide.lower[d] = std::max(0LL, b.lower[d] - ghost_width);
      wide.upper[d] = std::min(grid.cells()[d], b.upper[d] + ghost_width);
    }
    forEach(wide, [&](const Ijk& c) { all_cells.push_back(grid.cellId(c)); });
  }
  const std::vector<GlobalOrdinal> cell_gids = ownedThenGhosts(owned_cells, all_cells);
  owned_cell_map_ = makeMap(std::vector<GlobalOrdinal>(cell_gids.begin(), cell_gids.begin() + owned_cells.size()), comm);
  overlap_cell_map_ = makeMap(cell_gids, comm);
  cell_import_ = Teuchos::rcp(new Import(owned_cell_map_, overlap_cell_map_));
  indexTables<Dim>(cell_gids, grid.cells(), cell_ijk_, cell_lookup_, "cell");

  // 2. Nodes: owned = the patches' nodes (see Grid::ownerCellOfNode); ghosts = the other corners of
  //    the overlap cells.
  std::vector<GlobalOrdinal> owned_nodes, all_nodes;
  for (int p : patches_) forEach(grid.patchNodes(p), [&](const Ijk& n) { owned_nodes.push_back(grid.nodeId(n)); });
  for (GlobalOrdinal c : cell_gids) {
    const Ijk ijk = grid.cellIndex(c);
    for (int corner = 0; corner < Grid<Dim>::nodes_per_cell; ++corner) {
      Ijk n = ijk;
      for (int d = 0; d < Dim; ++d) n[d] += (corner >> d) & 1;
      all_nodes.push_back(grid.nodeId(n));
    }
  }
  const std::vector<GlobalOrdinal> node_gids = ownedThenGhosts(owned_nodes, all_nodes);
  owned_node_map_ = makeMap(std::vector<GlobalOrdinal>(node_gids.begin(), node_gids.begin() + owned_nodes.size()), comm);
  overlap_node_map_ = makeMap(node_gids, comm);
  node_import_ = Teuchos::rcp(new Import(owned_node_map_, overlap_node_map_));
  indexTables<Dim>(node_gids, grid.nodes(), node_ijk_, node_lookup_, "node");

  // 3. Neighbour and corner tables over the overlap cells, and boundary cell lists.
  const LocalOrdinal n_cells = LocalOrdinal(cell_gids.size());
  cell_neighbours_ = IndexTable("cell neighbours", n_cells, 2 * Dim);
  cell_nodes_ = IndexTable("cell nodes", n_cells, Grid<Dim>::nodes_per_cell);
  auto neighbours = Kokkos::create_mirror_view(cell_neighbours_);
  auto corners = Kokkos::create_mirror_view(cell_nodes_);
  std::vector<std::vector<LocalOrdinal>> boundary(2 * Dim);
  const auto cell_lookup_host = hostLookup(cell_lookup_);
  const auto node_lookup_host = hostLookup(node_lookup_);
  const LocalOrdinal n_owned = LocalOrdinal(owned_cells.size());
  for (LocalOrdinal l = 0; l < n_cells; ++l) {
    const Ijk ijk = grid.cellIndex(cell_gids[l]);
    for (int f = 0; f < 2 * Dim; ++f) {
      const int d = f / 2;
      Ijk q = ijk;
      q[d] += (f % 2 == 0) ? -1 : 1;
      if (q[d] < 0 || q[d] >= grid.cells()[d]) {
        neighbours(l, f) = kOutsideDomain;
        if (l < n_owned) boundary[f].push_back(l);
      } else {
        neighbours(l, f) = cell_lookup_host(q);
      }
    }
    for (int corner = 0; corner < Grid<Dim>::nodes_per_cell; ++corner) {
      Ijk n = ijk;
      for (int d = 0; d < Dim; ++d) n[d] += (corner >> d) & 1;
      corners(l, corner) = node_lookup_host(n);
    }
  }
  Kokkos::deep_copy(cell_neighbours_, neighbours);
  Kokkos::deep_copy(cell_nodes_, corners);
  for (int f = 0; f < 2 * Dim; ++f) {
    boundary_cells_[f] = Kokkos::View<LocalOrdinal*, MemorySpace>(std::string("boundary cells ") + faceName(f),
                                                                  boundary[f].size());
    auto host = Kokkos::create_mirror_view(boundary_cells_[f]);
    for (std::size_t i = 0; i < boundary[f].size(); ++i) host(i) = boundary[f][i];
    Kokkos::deep_copy(boundary_cells_[f], host);
  }
}

template <int Dim>
std::vector<Box> Layout<Dim>::ownedCellBoxes() const
{
  std::vector<Box> boxes;
  for (int p : patches_) boxes.push_back(grid_.patchCells(p));
  return boxes;
}

template <int Dim>
std::vector<Box> Layout<Dim>::ownedNodeBoxes() const
{
  std::vector<Box> boxes;
  for (int p : patches_) boxes.push_back(grid_.patchNodes(p));
  return boxes;
}

template class Layout<2>;
template class Layout<3>;

}  // namespace cfdmpm
