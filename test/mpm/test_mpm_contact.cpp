// Contact between MPM materials (Bardenhagen et al. 2001): an elastic block on a rigid plate made of
// particles. Dropped, it bounces off the plate instead of passing through; on a tilted plate with
// contact friction mu it slides like a rigid block, a = g (sin theta - mu cos theta).
#include "mpm/mpm_solver.hpp"
#include "mpm_scene_builder.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

using namespace cfdmpm;
using namespace cfdmpm::mpm;

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kH = 0.01;         // cell size (m)
constexpr double kPlateTop = 0.08;  // m

/// A rigid plate 3 cells thick under an elastic block 10 x 5 cells whose bottom is `gap` above it.
Scene plateScene(const std::array<double, 3>& gravity, double gap)
{
  Scene scene = scenes::dryScene<2>({0, 0, 0}, {1.0, 0.2, 0}, {100, 20, 1}, {25, 20, 1}, gravity);
  scenes::addRigid(scene, "plate", 2000.0);
  scenes::addLinearElastic(scene, "block", 1000.0, 1.0e6, 0.3, 2);
  scenes::addBox(scene, "plate", {0.0, kPlateTop - 3 * kH, 0}, {1.0, kPlateTop, 0});
  scenes::addBox(scene, "block", {0.05, kPlateTop + gap, 0}, {0.15, kPlateTop + gap + 5 * kH, 0});
  return scene;
}

struct BlockState {
  double centre[2] = {0, 0};
  double velocity[2] = {0, 0};
  double lowest = 1e300;        // lowest particle of the block (m)
  double plate_moved = 0;       // largest displacement of a plate particle (m)
};

BlockState blockState(const MpmSolver<2>& solver, const Kokkos::View<double* [2], Kokkos::HostSpace>& plate_start)
{
  const auto& particles = solver.particles();
  auto x = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), particles.position);
  auto v = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), particles.velocity);
  auto m = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), particles.mass);
  auto material = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), particles.material);
  BlockState s;
  double mass = 0;
  for (int p = 0; p < particles.count; ++p) {
    if (material(p) == 0) {  // the plate: one rank, so indices are stable
      for (int d = 0; d < 2; ++d) s.plate_moved = std::max(s.plate_moved, std::abs(x(p, d) - plate_start(p, d)));
      continue;
    }
    mass += m(p);
    for (int d = 0; d < 2; ++d) s.centre[d] += m(p) * x(p, d), s.velocity[d] += m(p) * v(p, d);
    s.lowest = std::min(s.lowest, x(p, 1));
  }
  for (int d = 0; d < 2; ++d) s.centre[d] /= mass, s.velocity[d] /= mass;
  return s;
}

}  // namespace

TEST(MaterialContact, DroppedElasticBlockBouncesOffRigidPlateWithoutPassingIt)
{
  const double g = 9.81, gap = 2 * kH;
  const double impact_speed = std::sqrt(2 * g * gap);  // 0.63 m/s after free fall over the gap
  const Scene scene = plateScene({0, -g, 0}, gap);
  MpmOptions options;
  options.cfl = 0.4;
  MpmSolver<2> solver(scene, scenes::layoutFor<2>(scene, Tpetra::getDefaultComm()), options);
  auto plate_start = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), solver.particles().position);
  const double dt = solver.stableTimeStep().dt;
  // Free fall over the gap takes sqrt(2 gap / g) = 0.064 s; watch until 0.2 s.
  double lowest = 1e300, fastest_down = 0, fastest_up = 0;
  for (double t = 0; t < 0.2; t += dt) {
    solver.step(dt);
    const BlockState now = blockState(solver, plate_start);
    lowest = std::min(lowest, now.lowest);
    fastest_down = std::max(fastest_down, -now.velocity[1]);
    fastest_up = std::max(fastest_up, now.velocity[1]);
  }
  const BlockState end = blockState(solver, plate_start);
  std::printf("[ contact  ] drop: lowest block particle %.5f m (plate top %.3f m; the particle sits h/4 = %.4f m "
              "above the block's bottom); fastest down %.3f m/s (free fall over the gap %.3f m/s, over the gap "
              "less a cell %.3f m/s), fastest rebound %.3f m/s; plate moved %.1e m\n",
              lowest, kPlateTop, kH / 4, fastest_down, impact_speed, std::sqrt(2 * g * (gap - kH)), fastest_up,
              end.plate_moved);
  // The block never passes into the plate: its lowest particle stays above the plate's top.
  // Contact acts where both materials have node mass, so the block turns up to a cell early (the
  // known gap of node-based contact).
  EXPECT_GT(lowest, kPlateTop);
  EXPECT_LT(lowest, kPlateTop + kH + kH / 4);
  // It fell freely over the gap less one cell: between sqrt(2 g (gap - h)) and sqrt(2 g gap).
  // Elastic and free to separate, it bounced up, without gaining energy.
  const double early_impact_speed = std::sqrt(2 * g * (gap - kH));
  EXPECT_GT(fastest_down, early_impact_speed);
  EXPECT_LT(fastest_down, impact_speed);
  EXPECT_GT(fastest_up, 0.1 * early_impact_speed);
  EXPECT_LT(fastest_up, fastest_down);
  EXPECT_EQ(end.plate_moved, 0.0);  // rigid: prescribed zero velocity, exactly
}

TEST(MaterialContact, BlockSlidesOnTiltedRigidPlateWithContactFriction)
{
  const double theta = 30.0 * kPi / 180.0, g = 9.81, mu = 0.2;
  const double a = g * (std::sin(theta) - mu * std::cos(theta));
  // The block starts resting one cell above the plate (where node-based contact holds it).
  const Scene scene = plateScene({g * std::sin(theta), -g * std::cos(theta), 0}, kH);
  MpmOptions options;
  options.cfl = 0.4;
  options.contact_friction = mu;
  MpmSolver<2> solver(scene, scenes::layoutFor<2>(scene, Tpetra::getDefaultComm()), options);
  auto plate_start = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), solver.particles().position);
  const double x0 = blockState(solver, plate_start).centre[0];
  const double dt = solver.stableTimeStep().dt;
  double worst = 0;
  long long n = 0;
  for (double check : {0.2, 0.3, 0.4}) {
    while ((n + 1) * dt <= check + 1e-12) solver.step(dt), ++n;
    const double t = n * dt;
    const double travelled = blockState(solver, plate_start).centre[0] - x0;
    const double error = travelled / (0.5 * a * t * t) - 1;
    std::printf("[ contact  ] slide: t = %.4f s travelled %.5f m, a t^2/2 = %.5f m, relative error %+.3e\n", t,
                travelled, 0.5 * a * t * t, error);
    worst = std::max(worst, std::abs(error));
  }
  // 3 %: as the wall-friction test (2 %), plus the contact normal from mass gradients, which
  // is not exactly the plate's normal at the block's corners.
  EXPECT_LT(worst, 0.03);
}

// A rigid body at rest (the plate) adds the same to the nodes and the cells at every step, so its
// particles are summed once (MpmOptions::stationary_sums_once). Those sums are the full sum's to
// round-off (the order of the additions differs): at the start, after the block has fallen for a
// while, and after gravity changed (the plate's weight is in the node forces). Bound: 1e-12 of a
// column's largest entry, far above the round-off of reordering ~16 additions (~1e-15) and far
// below what one particle adds (~1e-2 of a node's sum).
TEST(MaterialContact, PlateAtRestSummedOnceAddsWhatAFullSumAdds)
{
  const Scene scene = plateScene({0, -9.81, 0}, 2 * kH);
  MpmOptions once, every;
  once.cfl = every.cfl = 0.4;
  every.stationary_sums_once = false;
  const auto layout = scenes::layoutFor<2>(scene, Tpetra::getDefaultComm());
  MpmSolver<2> a(scene, layout, once), b(scene, layout, every);
  const int columns = MpmSolver<2>::cellColumns(2);
  Field<2> cells_a(layout, Location::Cell, columns, "cells, plate summed once");
  Field<2> cells_b(layout, Location::Cell, columns, "cells, plate summed every time");
  const double dt = a.stableTimeStep().dt;
  const auto largestDifference = [](const Field<2>& x, const Field<2>& y) {
    const auto u = x.view(), w = y.view();
    double worst = 0;
    for (std::size_t j = 0; j < u.extent(1); ++j) {
      double scale = 0, difference = 0;
      for (std::size_t i = 0; i < u.extent(0); ++i) {
        scale = std::max(scale, std::abs(w(i, j)));
        difference = std::max(difference, std::abs(u(i, j) - w(i, j)));
      }
      if (scale > 0) worst = std::max(worst, difference / scale);
      else worst = std::max(worst, difference);
    }
    return worst;
  };
  const auto compare = [&](const char* when) {
    a.particlesToGrid();
    b.particlesToGrid();
    a.particlesToCells(cells_a, dt);
    b.particlesToCells(cells_b, dt);
    const double nodes = largestDifference(a.nodeSums(), b.nodeSums());
    const double cells = largestDifference(cells_a, cells_b);
    std::printf("[ contact  ] plate summed once, %s: node sums differ by %.1e, cell sums by %.1e of a column\n", when,
                nodes, cells);
    EXPECT_LE(nodes, 1e-12) << when;
    EXPECT_LE(cells, 1e-12) << when;
  };
  compare("at the start");
  for (int step = 0; step < 30; ++step) {
    a.step(dt);
    b.step(dt);
  }
  compare("after 30 steps");
  a.setGravity({0, -1.0, 0});
  b.setGravity({0, -1.0, 0});
  compare("with another gravity");
}
