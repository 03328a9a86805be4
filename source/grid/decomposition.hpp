#pragma once
// Decomposition of the patches among MPI ranks by METIS, on the graph whose vertices are patches
// (weighted by work: their cells, and for a rebalance their cells and particles as two weights, each
// balanced on its own) and whose edges join face neighbours (weighted by the number of cells on the
// shared face, the halo traffic between them).
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

/// `division` with its parts renumbered so that as much work as possible stays where `current`
/// has it: METIS numbers the parts of a new partition without regard to an earlier one, and a
/// rebalance should move only what it must. Parts are matched greedily, the pair (part, rank)
/// sharing the most work first. Deterministic, like partitionPatches.
Decomposition closestNumbering(const Decomposition& division, const Decomposition& current,
                               const std::vector<double>& patch_weight);

/// The heaviest rank's load over the mean load, minus one: 0 when the ranks are balanced, 0.5 when
/// the slowest rank has half as much again as the mean (and the step takes 1.5 times as long as
/// a balanced one would).
double loadImbalance(const std::vector<double>& load);

/// The work of every patch in units of one cell's, in the two parts that different phases of a
/// step do: the cells' (fluid phases, one per cell) and the particles' (particle phases,
/// `particle_work` per particle). A phase ends with a halo exchange that waits for its slowest
/// rank, so each part needs to be balanced on its own.
struct PatchWork {
  std::vector<double> cells;
  std::vector<double> particles;

  std::vector<double> total() const
  {
    std::vector<double> sum = cells;
    for (std::size_t p = 0; p < sum.size(); ++p) sum[p] += particles[p];
    return sum;
  }
};

/// The work of a cell that rigid bodies fill (IceSolver::closedCells), in units of an open cell's:
/// the fluid phases skip it, but it keeps its row of the pressure matrix (CG, the preconditioner)
/// and the passes over every cell (closure, checks, halos). Measured on the seed scene at 10 mm on
/// 2 ranks (doc/scaling.md, "Weights").
constexpr double kClosedCellWork = 0.5;

/// The work of the grid's patches with `particles` per patch (indexed by patch id; empty: none)
/// and `closed` cells per patch (empty: none), each closed cell weighing kClosedCellWork.
template <int Dim>
PatchWork patchWork(const Grid<Dim>& grid, const std::vector<long long>& particles, double particle_work,
                    const std::vector<long long>& closed = {});

/// Partitions the patches with both parts of the work balanced, each on its own (METIS with two
/// constraints; with no particles, by cells). Where METIS finds no such division that gives every
/// rank a patch (few patches per rank), the total work is balanced. Deterministic like the other.
template <int Dim>
Decomposition partitionPatches(const Grid<Dim>& grid, int ranks, const PatchWork& work);

/// The estimated imbalance of a step: the slowest rank's cell work plus the slowest rank's particle
/// work (each phase waits for its own slowest rank), over the balanced work per rank, minus one.
double loadImbalance(const Decomposition& decomposition, const PatchWork& work);

/// What dividing the patches again found (divideAgain).
struct Redivision {
  Decomposition decomposition;
  double imbalance_before = 0;  // loadImbalance of the current division
  double imbalance_after = 0;   // and of the one returned (the same where it is the current one)
};

/// The patches divided again by `work` (partitionPatches, renumbered by closestNumbering so that as
/// much work as possible stays where `current` has it), where that lowers the estimated imbalance by
/// more than `gain`; else `current`, as also where METIS leaves a rank without patches.
/// Deterministic like partitionPatches.
template <int Dim>
Redivision divideAgain(const Grid<Dim>& grid, const Decomposition& current, const PatchWork& work, double gain);

}  // namespace cfdmpm
