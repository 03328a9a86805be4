// The particles' sums for the fluids' cells (MpmSolver::particlesToCells): the volume a solid takes
// in the cells, as the coupled step's pressure equation and equilibration see it.
#include "mpm/mpm_solver.hpp"
#include "mpm_scene_builder.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

using namespace cfdmpm;
using namespace cfdmpm::mpm;

namespace {

double globalSum(const Teuchos::Comm<int>& comm, double local)
{
  double global = 0;
  Teuchos::reduceAll(comm, Teuchos::REDUCE_SUM, local, Teuchos::outArg(global));
  return global;
}

}  // namespace

// A granular solid's plastic dilation is not solid volume for the fluids: the pores it opens fill
// with the fluid around it (a drained sand). Without that, a Drucker-Prager column collapsing under
// water, whose particles at its surface return to the apex of the cone (tension) and part, pushed
// the water out of its cells as if it had grown: the column swelled by 49 % in 0.4 s, single
// particles to 23 times their volume (doc/mpmice.md). Here a block of Drucker-Prager sand (4 x 4
// cells of 10 mm, 64 particles) whose particles have all dilated plastically by 25 % (V_p = 1.25
// V_p0, ε^p_v = ln 1.25, as an apex return leaves them) and an elastic block beside it squeezed by
// 10 % (V_p = 0.9 V_p0, no plastic strain). The cells hold the sand's initial volume and the elastic
// block's present one, to round-off of the sums (1e-12 relative; a wrong count is off by 25 % or
// 10 %).
TEST(ParticlesToCells, PlasticDilationIsLeftToTheFluids)
{
  Scene scene = scenes::dryScene<2>({0, 0, 0}, {0.12, 0.08, 0}, {12, 8, 1}, {6, 8, 1}, {0, 0, 0});
  Teuchos::ParameterList sand;
  sand.set("kind", std::string("solid"));
  sand.set("density", 1985.0);
  sand.set("particles_per_cell", 2);
  Teuchos::ParameterList& model = sand.sublist("model");
  model.set("type", std::string("drucker_prager"));
  model.set("youngs_modulus", 1.0e6);
  model.set("poisson_ratio", 0.3);
  model.set("friction_angle", 30.0);
  model.set("cohesion", 0.0);
  scene.materials.push_back(MaterialSpec{"sand", "solid", sand});
  scenes::addLinearElastic(scene, "block", 1000.0, 1.0e6, 0.3, 2);
  scenes::addBox(scene, "sand", {0.02, 0.02, 0}, {0.06, 0.06, 0});
  scenes::addBox(scene, "block", {0.07, 0.02, 0}, {0.11, 0.06, 0});
  const auto comm = Tpetra::getDefaultComm();
  const auto layout = scenes::layoutFor<2>(scene, comm);
  MpmSolver<2> solver(scene, layout, MpmOptions{});
  const double dilation = 1.25, squeeze = 0.9;
  double initial[2] = {0, 0}, present[2] = {0, 0};
  {
    Particles<2>& particles = solver.particles();
    auto volume = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), particles.volume);
    auto state = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), particles.state);
    auto material = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), particles.material);
    for (int p = 0; p < particles.count; ++p) {
      const int m = material(p);
      initial[m] += volume(p);
      if (m == 0) {
        volume(p) *= dilation;
        state(p).volumetric_plastic_strain = std::log(dilation);
      } else {
        volume(p) *= squeeze;
      }
      present[m] += volume(p);
    }
    Kokkos::deep_copy(particles.volume, volume);
    Kokkos::deep_copy(particles.state, state);
  }
  for (int m = 0; m < 2; ++m) initial[m] = globalSum(*comm, initial[m]), present[m] = globalSum(*comm, present[m]);
  Field<2> cells(layout, Location::Cell, MpmSolver<2>::cellColumns(2), "particle sums");
  solver.particlesToGrid();
  solver.particlesToCells(cells);
  const auto sums = cells.view();
  double in_cells[2] = {0, 0};
  for (LocalOrdinal c = 0; c < layout->ownedCells(); ++c)
    for (int m = 0; m < 2; ++m) in_cells[m] += sums(c, 2 + m);
  for (int m = 0; m < 2; ++m) in_cells[m] = globalSum(*comm, in_cells[m]);
  if (comm->getRank() == 0)
    std::printf("[ cells    ] sand: particles %.6e m^2 (initial %.6e), cells %.6e; block: particles %.6e, cells %.6e\n",
                present[0], initial[0], in_cells[0], present[1], in_cells[1]);
  EXPECT_NEAR(in_cells[0], initial[0], 1e-12 * initial[0]);
  EXPECT_NEAR(in_cells[1], present[1], 1e-12 * present[1]);
}

// The count of contributions (MpmSolver::touchColumn) is what lets the coupled step pass over the
// cells that no particle reaches reading one column: wherever it is 0, every other column must be 0
// too, on owned and ghost cells alike. Two bodies moving at 2 m/s across cell faces within the step
// (Δt = 2.5e-3 s: a fifth of a cell, so the moved boxes, the layers and the covers over the step all
// reach beyond the cells the boxes overlap), an elastic one and a moving rigid one (whose face shares
// take their own path), on 1 and 2 ranks. The test fails if any write of the sums is not counted;
// it also asserts that the count is not everywhere (most of the cells stay out of reach).
TEST(ParticlesToCells, CellsWithoutContributionsHoldNothing)
{
  Scene scene = scenes::dryScene<2>({0, 0, 0}, {0.24, 0.16, 0}, {24, 16, 1}, {12, 8, 1}, {0, 0, 0});
  scenes::addLinearElastic(scene, "block", 1000.0, 1.0e6, 0.3, 2);
  scenes::addRigid(scene, "plunger", 2000.0, {-2.0, 1.0});
  scenes::addBox(scene, "block", {0.023, 0.031, 0}, {0.071, 0.067, 0}, {2.0, -1.5, 0});
  scenes::addBox(scene, "plunger", {0.15, 0.09, 0}, {0.19, 0.13, 0});
  const auto comm = Tpetra::getDefaultComm();
  const auto layout = scenes::layoutFor<2>(scene, comm);
  MpmSolver<2> solver(scene, layout, MpmOptions{});
  Field<2> cells(layout, Location::Cell, MpmSolver<2>::cellColumns(2), "particle sums");
  solver.particlesToGrid();
  solver.integrateGrid(0.0);  // v* = v
  solver.particlesToCells(cells, 2.5e-3);
  const auto sums = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), cells.view());
  const int touch = MpmSolver<2>::touchColumn(2);
  long long reached = 0, unreached_but_filled = 0, local = 0;
  for (LocalOrdinal c = 0; c < LocalOrdinal(sums.extent(0)); ++c, ++local) {
    if (sums(c, touch) > 0) {
      ++reached;
      continue;
    }
    for (int k = 0; k < cells.columns(); ++k)
      if (sums(c, k) != 0.0) ++unreached_but_filled;
  }
  long long global[3] = {0, 0, 0};
  const long long counts[3] = {reached, unreached_but_filled, local};
  Teuchos::reduceAll(*comm, Teuchos::REDUCE_SUM, 3, counts, global);
  if (comm->getRank() == 0)
    std::printf("[ cells    ] %lld of %lld local cells reached, %lld values in cells not counted as reached\n", global[0],
                global[2], global[1]);
  EXPECT_EQ(global[1], 0);
  EXPECT_GT(global[0], 0);
  EXPECT_LT(global[0], global[2] / 2);
}
