#include "mpmice/run_state.hpp"

#include "mpmice/initial_state.hpp"

#include <map>

namespace cfdmpm {

template <int Dim>
RunState<Dim> buildRunState(const Scene& scene, const Grid<Dim>& grid, const Decomposition& decomposition,
                            const Teuchos::RCP<const Teuchos::Comm<int>>& comm)
{
  RunState<Dim> run;
  run.layout = std::make_shared<const Layout<Dim>>(grid, decomposition, scene.domain.ghost_width, comm);
  run.cells = std::make_unique<CellState<Dim>>(run.layout, int(scene.materials.size()));
  setInitialState(scene, densityFunctions(scene), *run.cells);
  run.step = std::make_unique<MpmIceStep<Dim>>(scene, run.layout, *run.cells);
  return run;
}

template <int Dim>
void adoptState(const CellValues<Dim>& cells, const typename mpm::MpmSolver<Dim>::ParticleSnapshot& particles,
                int count, RunState<Dim>& run)
{
  for (const auto& [name, field] : namedFields(*run.cells)) {
    cells(name, *field);
    field->exchangeHalo();
  }
  if (IceSolver<Dim>* fluids = run.step->fluids()) {
    Field<Dim> reference(run.layout, Location::Cell, 1, "solid_reference_pressure");
    cells(kSolidReferencePressureName, reference);
    reference.exchangeHalo();
    fluids->setSolidReferencePressure(reference);
  }
  if (mpm::MpmSolver<Dim>* solids = run.step->particles()) {
    solids->restoreParticles(particles, count);
    solids->relocateParticles();
  }
}

template <int Dim>
RunState<Dim> redistribute(const Scene& scene, RunState<Dim>& from, const Decomposition& decomposition)
{
  RunState<Dim> to = buildRunState(scene, from.layout->grid(), decomposition, from.layout->comm());
  std::map<std::string, const Field<Dim>*> fields;
  for (const auto& [name, field] : namedFields(std::as_const(*from.cells))) fields[name] = field;
  if (const IceSolver<Dim>* fluids = from.step->fluids()) fields[kSolidReferencePressureName] = &fluids->solidReferencePressure();
  typename mpm::MpmSolver<Dim>::ParticleSnapshot particles;
  int count = 0;
  if (const mpm::MpmSolver<Dim>* solids = from.step->particles()) {
    solids->saveParticles(particles);
    count = solids->particles().count;
  }
  adoptState<Dim>([&](const std::string& name, Field<Dim>& field) { field.importOwned(*fields.at(name)); }, particles,
                  count, to);
  return to;
}

template <int Dim>
Division divisionByOpenCells(const RunState<Dim>& run, double gain)
{
  Division result;
  result.decomposition = run.layout->decomposition();
  const IceSolver<Dim>* fluids = run.step->fluids();
  if (!fluids) return result;
  const std::vector<long long> closed = fluids->closedCellsPerPatch();
  for (long long n : closed) result.closed_cells += n;
  if (result.closed_cells == 0 || result.decomposition.ranks < 2) return result;
  const Grid<Dim>& grid = run.layout->grid();
  const Redivision again = divideAgain(grid, result.decomposition, patchWork(grid, {}, 0.0, closed), gain);
  result.decomposition = again.decomposition;
  result.imbalance_before = again.imbalance_before;
  result.imbalance_after = again.imbalance_after;
  return result;
}

namespace {

// The work of one particle in units of one cell's, for the weights of a division with the
// particles (divisionWithParticles; domain.rebalance_interval), from the per-phase costs measured
// on one core (doc/scaling.md, "Weights"; bench/scaling.sh): with moving fluids a cell carries the
// whole fluid step and a particle its share of phases 1, 2, 9 and 12 and of the sums between steps
// (the slide: 0.12-0.14 in 2-D, 0.23-0.27 in 3-D in two series of runs); in a dry scene a cell
// carries only its nodes' share of the grid update (the granular column: 11-12; not measured in
// 3-D, where the 2-D value is taken). With two constraints the division itself does not depend on
// them, only the estimated imbalance that decides a move.
double particleWork(int dimension, bool fluids_move)
{
  if (!fluids_move) return 11.0;
  return dimension == 3 ? 0.25 : 0.13;
}

}  // namespace

template <int Dim>
Redivision divisionWithParticles(const RunState<Dim>& run, double gain)
{
  std::vector<long long> particles;
  if (const mpm::MpmSolver<Dim>* solids = run.step->particles()) particles = solids->particlesPerPatch();
  std::vector<long long> closed;
  if (const IceSolver<Dim>* fluids = run.step->fluids()) closed = fluids->closedCellsPerPatch();
  const Grid<Dim>& grid = run.layout->grid();
  const PatchWork work = patchWork(grid, particles, particleWork(Dim, run.step->fluidsMove()), closed);
  return divideAgain(grid, run.layout->decomposition(), work, gain);
}

template RunState<2> buildRunState(const Scene&, const Grid<2>&, const Decomposition&,
                                   const Teuchos::RCP<const Teuchos::Comm<int>>&);
template RunState<3> buildRunState(const Scene&, const Grid<3>&, const Decomposition&,
                                   const Teuchos::RCP<const Teuchos::Comm<int>>&);
template void adoptState(const CellValues<2>&, const mpm::MpmSolver<2>::ParticleSnapshot&, int, RunState<2>&);
template void adoptState(const CellValues<3>&, const mpm::MpmSolver<3>::ParticleSnapshot&, int, RunState<3>&);
template RunState<2> redistribute(const Scene&, RunState<2>&, const Decomposition&);
template RunState<3> redistribute(const Scene&, RunState<3>&, const Decomposition&);
template Division divisionByOpenCells(const RunState<2>&, double);
template Division divisionByOpenCells(const RunState<3>&, double);
template Redivision divisionWithParticles(const RunState<2>&, double);
template Redivision divisionWithParticles(const RunState<3>&, double);

}  // namespace cfdmpm
