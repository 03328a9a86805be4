#pragma once
// What one rank holds of the grid: its patches, its owned cells and nodes, the ghost cells and nodes
// around them, the Tpetra maps and transfer plans for both, and index tables that kernels use to find
// neighbours. All index arithmetic for neighbours, corners and boundary faces lives here.
//
// Local numbering: owned entries first (ascending global id), then ghosts (ascending global id). A
// field stored on the overlap map therefore has its owned part as a prefix, which the field classes
// use for in-place halo exchange and node sums.
#include "common/types.hpp"
#include "grid/decomposition.hpp"
#include "grid/grid.hpp"

#include <Teuchos_Comm.hpp>
#include <Teuchos_RCP.hpp>
#include <Tpetra_Import.hpp>

#include <memory>
#include <vector>

namespace cfdmpm {

/// Dense lookup from global (i, j, k) to a local id over a bounding box; usable inside kernels.
struct BoxLookup {
  Kokkos::View<LocalOrdinal*, MemorySpace> lid;  // kNotLocal where the rank holds no entry
  long long lower[3] = {0, 0, 0};
  long long extent[3] = {1, 1, 1};

  KOKKOS_INLINE_FUNCTION LocalOrdinal operator()(long long i, long long j, long long k) const
  {
    const long long a = i - lower[0], b = j - lower[1], c = k - lower[2];
    if (a < 0 || b < 0 || c < 0 || a >= extent[0] || b >= extent[1] || c >= extent[2]) return -2;
    return lid(a + extent[0] * (b + extent[1] * c));
  }
};

template <int Dim>
class Layout {
 public:
  using Import = Tpetra::Import<LocalOrdinal, GlobalOrdinal, Node>;
  using IndexTable = Kokkos::View<LocalOrdinal**, MemorySpace>;
  using IjkTable = Kokkos::View<int**, MemorySpace>;
  /// Values in neighbour tables besides a local id.
  static constexpr LocalOrdinal kOutsideDomain = -1;  // across a domain face (boundary)
  static constexpr LocalOrdinal kNotLocal = -2;       // inside the domain, beyond the ghost layers

  Layout(const Grid<Dim>& grid, const Decomposition& decomposition, int ghost_width,
         Teuchos::RCP<const Teuchos::Comm<int>> comm);

  const Grid<Dim>& grid() const { return grid_; }
  const Decomposition& decomposition() const { return decomposition_; }
  int ghostWidth() const { return ghost_width_; }
  const Teuchos::RCP<const Teuchos::Comm<int>>& comm() const { return comm_; }
  const std::vector<int>& patches() const { return patches_; }
  std::vector<Box> ownedCellBoxes() const;
  std::vector<Box> ownedNodeBoxes() const;

  // --- cells ------------------------------------------------------------------------------
  LocalOrdinal ownedCells() const { return LocalOrdinal(owned_cell_map_->getNodeNumElements()); }
  LocalOrdinal overlapCells() const { return LocalOrdinal(overlap_cell_map_->getNodeNumElements()); }
  const Teuchos::RCP<const Map>& ownedCellMap() const { return owned_cell_map_; }
  const Teuchos::RCP<const Map>& overlapCellMap() const { return overlap_cell_map_; }
  const Teuchos::RCP<const Import>& cellImport() const { return cell_import_; }
  /// (overlap cell, d) -> global index in direction d.
  const IjkTable& cellIndex() const { return cell_ijk_; }
  /// (overlap cell, f) -> local id of the neighbour across face f = 2 d + side, or kOutsideDomain /
  /// kNotLocal.
  const IndexTable& cellNeighbours() const { return cell_neighbours_; }
  /// (overlap cell, c) -> local id of corner node c (bit d of c set: upper side in direction d).
  const IndexTable& cellNodes() const { return cell_nodes_; }
  /// Owned cells that touch domain face f.
  const Kokkos::View<LocalOrdinal*, MemorySpace>& boundaryCells(int f) const { return boundary_cells_[f]; }
  const BoxLookup& cellLookup() const { return cell_lookup_; }

  // --- nodes ------------------------------------------------------------------------------
  LocalOrdinal ownedNodes() const { return LocalOrdinal(owned_node_map_->getNodeNumElements()); }
  LocalOrdinal overlapNodes() const { return LocalOrdinal(overlap_node_map_->getNodeNumElements()); }
  const Teuchos::RCP<const Map>& ownedNodeMap() const { return owned_node_map_; }
  const Teuchos::RCP<const Map>& overlapNodeMap() const { return overlap_node_map_; }
  /// Import owned -> overlap nodes; used in reverse (Export with ADD) for node sums.
  const Teuchos::RCP<const Import>& nodeImport() const { return node_import_; }
  const IjkTable& nodeIndex() const { return node_ijk_; }
  const BoxLookup& nodeLookup() const { return node_lookup_; }

 private:
  Grid<Dim> grid_;
  Decomposition decomposition_;
  int ghost_width_;
  Teuchos::RCP<const Teuchos::Comm<int>> comm_;
  std::vector<int> patches_;

  Teuchos::RCP<const Map> owned_cell_map_, overlap_cell_map_, owned_node_map_, overlap_node_map_;
  Teuchos::RCP<const Import> cell_import_, node_import_;
  IjkTable cell_ijk_, node_ijk_;
  IndexTable cell_neighbours_, cell_nodes_;
  Kokkos::View<LocalOrdinal*, MemorySpace> boundary_cells_[2 * Dim];
  BoxLookup cell_lookup_, node_lookup_;
};

extern template class Layout<2>;
extern template class Layout<3>;

}  // namespace cfdmpm
