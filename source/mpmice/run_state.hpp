#pragma once
// What a run holds on one decomposition of its grid: the layout, the cell state and the coupled
// step built on it. A run builds one at set-up, at a restart, and whenever it redoes its
// decomposition with the particles' weights (domain.rebalance_interval), always the same way:
//
//   buildRunState   the layout of the decomposition, the scene's initial state on it and a fresh
//                   coupled step (what a new run starts from);
//   adoptState      the state of the run in progress poured in: every cell field by name, the
//                   fluids' solid reference pressure, and the particles, each sent to the owner of
//                   its cell by the particle migration.
//
// A restart takes the state from a checkpoint file (readCheckpoint), a rebalance from the same run
// on its old decomposition (redistribute): one path, so a run rebalanced in memory continues as a
// run restarted from a checkpoint on the new decomposition would.
#include "grid/decomposition.hpp"
#include "mpmice/mpmice_step.hpp"

#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace cfdmpm {

template <int Dim>
struct RunState {
  std::shared_ptr<const Layout<Dim>> layout;
  std::unique_ptr<CellState<Dim>> cells;
  std::unique_ptr<MpmIceStep<Dim>> step;
};

/// The name of the fluids' solid reference pressure among the state's cell fields.
inline constexpr const char* kSolidReferencePressureName = "ice/solid_reference_pressure";

/// The cell fields of the coupled state with the names a checkpoint gives them ("state/density",
/// ...); `State` is CellState<Dim>, const or not.
template <class State>
auto namedFields(State& state)
{
  using FieldPointer = decltype(&state.density);
  return std::vector<std::pair<std::string, FieldPointer>>{
      {"state/volume_fraction", &state.volume_fraction}, {"state/density", &state.density},
      {"state/specific_volume", &state.specific_volume}, {"state/velocity", &state.velocity},
      {"state/temperature", &state.temperature},         {"state/pressure", &state.pressure}};
}

/// The layout of `decomposition`, the scene's initial state on it and the coupled step with the
/// material sets the scene has (which seeds the scene's particles). Collective.
template <int Dim>
RunState<Dim> buildRunState(const Scene& scene, const Grid<Dim>& grid, const Decomposition& decomposition,
                            const Teuchos::RCP<const Teuchos::Comm<int>>& comm);

/// Fills the owned entries of `field` (on the new layout) with the values of the run's cell field
/// called `name` (a name of namedFields, or kSolidReferencePressureName).
template <int Dim>
using CellValues = std::function<void(const std::string& name, Field<Dim>& field)>;

/// Makes the state of `run`, freshly built by buildRunState, that of a run in progress: every cell
/// field from `cells` (ghosts then from their owners), the fluids' solid reference pressure, and
/// this rank's share of the particles, `count` rows of `particles` in the order of
/// Particles::pack, which then go to the owners of their cells (in their order when they stay).
/// Collective.
template <int Dim>
void adoptState(const CellValues<Dim>& cells, const typename mpm::MpmSolver<Dim>::ParticleSnapshot& particles,
                int count, RunState<Dim>& run);

/// The run on another decomposition of its grid: built by buildRunState, with the state of `from`
/// (cell fields imported to their new owners, particles migrated) by adoptState. `from` is left as
/// it was. Collective.
template <int Dim>
RunState<Dim> redistribute(const Scene& scene, RunState<Dim>& from, const Decomposition& decomposition);

/// What dividing the patches by the fluid phases' work found (divisionByOpenCells).
struct Division {
  Decomposition decomposition;
  long long closed_cells = 0;   // cells that rigid bodies fill, over the grid
  double imbalance_before = 0;  // loadImbalance of the run's own division, with those weights
  double imbalance_after = 0;   // and of the one returned
};

/// The patches divided so that the fluid phases' work is balanced where rigid bodies fill cells:
/// such a cell (IceSolver::closedCells) weighs kClosedCellWork of an open one, and a division by
/// cell counts gave the rank that holds a bed far less to do (the seed scene's bed fills 60 % of
/// the cells of the rank that holds its slope on 2 ranks, 6 % of the other's). `run` is freshly
/// built (its closed cells marked from the initial state); returns its own decomposition where no
/// cell is closed, on one rank, or where the new one is not better by more than `gain`.
/// Collective; every rank gets the same answer.
template <int Dim>
Division divisionByOpenCells(const RunState<Dim>& run, double gain);

/// A new decomposition is taken only when it lowers the estimated imbalance by more than this (a
/// share of the mean load): a move costs about as much as three steps (doc/scaling.md), which a
/// gain of 2 % pays back within 150 steps.
inline constexpr double kRebalanceGain = 0.02;

/// The patches divided again (divideAgain) so that the cells' work (the cells rigid bodies fill
/// weighed kClosedCellWork) and the particles' work (MpmSolver::particlesPerPatch times
/// particleWork) are each balanced, where that lowers the estimated imbalance by more than `gain`;
/// else the run's own division. Collective; every rank gets the same answer.
template <int Dim>
Redivision divisionWithParticles(const RunState<Dim>& run, double gain);

}  // namespace cfdmpm
