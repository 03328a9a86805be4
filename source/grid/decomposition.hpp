#pragma once
// Decomposition of the patches among MPI ranks by METIS, on the graph whose vertices are patches
// (weighted by work: cells plus, later, particles) and whose edges join face neighbours (weighted by
// the number of cells on the shared face, the halo traffic between them).
#include "grid/grid.hpp"

#include <vector>

namespace cfdmpm {

struct Decomposition {
  int ranks = 1;
  std::vector<int> patch_owner;  // rank of every patch, indexed by patch id

  std::vector<int> patchesOf(int rank) const
  {
    std::vector<int> p;
    for (int i = 0; i < int(patch_owner.size()); ++i)
      if (patch_owner[i] == rank) p.push_back(i);
    return p;
  }
};

/// Partitions the grid's patches into `ranks` parts with METIS. `patch_weight` (one per patch,
/// > 0) is the work of each patch; empty means the cell count. Deterministic: every rank that calls
/// it with the same arguments gets the same answer, so it runs redundantly on all ranks.
template <int Dim>
Decomposition partitionPatches(const Grid<Dim>& grid, int ranks,
                               const std::vector<double>& patch_weight = {});

/// Work per rank (sum of patch weights) for a decomposition; for balance reports.
std::vector<double> rankLoads(const Decomposition& decomposition,
                              const std::vector<double>& patch_weight);

}  // namespace cfdmpm
