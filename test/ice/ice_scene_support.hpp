#pragma once
// Helpers for tests that run the ICE solver on small scenes written inline as YAML.
#include "grid/decomposition.hpp"
#include "ice/ice_solver.hpp"
#include "ice/material_eos.hpp"
#include "input/scene.hpp"
#include "mpmice/initial_state.hpp"

#include <Teuchos_DefaultComm.hpp>

#include <cstdio>
#include <fstream>
#include <memory>
#include <string>
#include <vector>
#include <unistd.h>

namespace cfdmpm::test {

/// Reads a scene from YAML text (through a temporary file, as a user's file would be read).
inline Scene sceneFromYaml(const std::string& text)
{
  char path[] = "/tmp/cfdmpm-scene-XXXXXX.yaml";
  const int fd = mkstemps(path, 5);
  if (fd < 0) throw std::runtime_error("cannot create a temporary scene file");
  close(fd);
  {
    std::ofstream out(path);
    out << text;
  }
  Scene scene = readScene(path);
  std::remove(path);
  return scene;
}

/// The Martin & Moyce dam break (0.5 m x 0.2 m tank, water column 0.05715 m x 0.1143 m, air above)
/// on nx x ny cells; `ice_section` is the YAML flow map of the `ice` settings.
inline Scene damBreakScene(long long nx, long long ny, long long patch, const std::string& ice_section = "{}")
{
  return sceneFromYaml(R"(
cfdmpm:
  domain: {dimension: 2, lower: [0.0, 0.0], upper: [0.5, 0.2], cells: [)" + std::to_string(nx) + ", " +
                       std::to_string(ny) + "], patch_cells: [" + std::to_string(patch) + ", " + std::to_string(patch) +
                       R"(], gravity: [0.0, -9.81]}
  materials:
    water:
      kind: fluid
      equation_of_state: {type: linear_water, bulk_modulus: 2.15e9, reference_density: 998.0, reference_pressure: 101325.0, reference_temperature: 293.15}
      viscosity: 1.0e-3
      specific_heat: 4157.0
    air:
      kind: fluid
      equation_of_state: {type: ideal_gas, gas_constant: 287.0, gamma: 1.4}
      viscosity: 1.8e-5
  initial_state: {background_material: air, temperature: 293.15, pressure: 101325.0}
  regions:
    column: {material: water, shape: box, lower: [0.0, 0.0], upper: [0.05715, 0.1143]}
  time: {end_time: 0.25, dt_initial: 1.0e-4}
  output: {directory: unused, interval: 0.01}
  ice: )" + ice_section + "\n");
}

/// A scene's state and solver on a communicator.
template <int Dim>
struct IceRun {
  IceRun(const Scene& s, const Teuchos::RCP<const Teuchos::Comm<int>>& comm)
      : scene(s),
        layout(std::make_shared<const Layout<Dim>>(Grid<Dim>(s.domain), partitionPatches(Grid<Dim>(s.domain), comm->getSize()),
                                                   s.domain.ghost_width, comm)),
        state(layout, int(s.materials.size())),
        solver(s, layout)
  {
    setInitialState(scene, densityFunctions(scene), state);
    solver.equilibrate(state);
  }

  /// Steps with the solver's own Δt (or a fixed one when fixed_dt > 0) until end_time.
  void runUntil(double end_time, double fixed_dt = 0)
  {
    while (time < end_time * (1 - 1e-12)) {
      double dt = fixed_dt > 0 ? fixed_dt
                               : (steps == 0 ? scene.time.dt_initial : solver.stableTimeStep(state, dt_previous).dt);
      dt_previous = dt;
      dt = std::min(dt, end_time - time);
      last = solver.step(state, dt);
      time += dt;
      ++steps;
    }
  }

  Scene scene;
  std::shared_ptr<const Layout<Dim>> layout;
  CellState<Dim> state;
  IceSolver<Dim> solver;
  IceStepReport last;
  double time = 0, dt_previous = 0;
  long long steps = 0;
};

/// Sum over ranks.
inline double globalSum(const Teuchos::Comm<int>& comm, double local)
{
  double total = 0;
  Teuchos::reduceAll(comm, Teuchos::REDUCE_SUM, local, Teuchos::outArg(total));
  return total;
}

inline double globalMax(const Teuchos::Comm<int>& comm, double local)
{
  double total = 0;
  Teuchos::reduceAll(comm, Teuchos::REDUCE_MAX, local, Teuchos::outArg(total));
  return total;
}

// Every owned value of a field, placed at its global id, summed over ranks: the whole field on
// every rank (for comparing runs on different partitions; small grids only).
inline std::vector<double> gatherField(const Field<2>& field)
{
  const auto& map = *field.layout().ownedCellMap();
  const int columns = field.columns();
  std::vector<double> local(field.layout().grid().cellCount() * columns, 0.0), total(local.size());
  const auto v = field.view();
  for (LocalOrdinal c = 0; c < field.ownedCount(); ++c)
    for (int k = 0; k < columns; ++k) local[map.getGlobalElement(c) * columns + k] = v(c, k);
  Teuchos::reduceAll(*field.layout().comm(), Teuchos::REDUCE_SUM, int(local.size()), local.data(), total.data());
  return total;
}

}  // namespace cfdmpm::test
