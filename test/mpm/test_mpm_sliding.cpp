// Test c: an elastic block sliding down a 30 degree incline with Coulomb friction mu = 0.2. The
// grid stays level and gravity is tilted instead, g (sin theta, -cos theta), so the floor is the
// y- wall. A rigid block slides with a = g (sin theta - mu cos theta): x(t) = a t^2 / 2.
#include "mpm/mpm_solver.hpp"
#include "mpm_scene_builder.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

using namespace cfdmpm;
using namespace cfdmpm::mpm;

namespace {

/// Centre of mass of all particles (collective).
std::array<double, 2> centreOfMass(const MpmSolver<2>& solver)
{
  const auto& particles = solver.particles();
  auto x = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), particles.position);
  auto m = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), particles.mass);
  double local[3] = {0, 0, 0}, total[3] = {0, 0, 0};
  for (int p = 0; p < particles.count; ++p) {
    local[0] += m(p) * x(p, 0);
    local[1] += m(p) * x(p, 1);
    local[2] += m(p);
  }
  Teuchos::reduceAll(*solver.layout().comm(), Teuchos::REDUCE_SUM, 3, local, total);
  return {total[0] / total[2], total[1] / total[2]};
}

}  // namespace

TEST(SlidingBlock, FollowsCoulombFrictionOnThirtyDegreeIncline)
{
  constexpr double kPi = 3.14159265358979323846;
  const double theta = 30.0 * kPi / 180.0, g = 9.81, mu = 0.2;
  const double a = g * (std::sin(theta) - mu * std::cos(theta));  // 3.206 m/s^2
  // Floor 1 m long, 10 mm cells; block 0.1 m x 0.05 m, E = 1 MPa (wave speed 37 m/s, so it stays
  // nearly rigid: the static compression is rho g H / M = 3.6e-4).
  const double h = 0.01;
  Scene scene = scenes::dryScene<2>({0, 0, 0}, {1.0, 0.1, 0}, {100, 10, 1}, {25, 10, 1},
                                    {g * std::sin(theta), -g * std::cos(theta), 0});
  scenes::addLinearElastic(scene, "block", 1000.0, 1.0e6, 0.3, 2);
  scenes::addBox(scene, "block", {5 * h, 0, 0}, {15 * h, 5 * h, 0});
  MpmOptions options;
  options.wall_friction = mu;  // the y- floor is free_slip, so it is a frictional wall
  options.cfl = 0.4;
  MpmSolver<2> solver(scene, scenes::layoutFor<2>(scene, Tpetra::getDefaultComm()), options);

  const double x0 = centreOfMass(solver)[0];
  const long long count = solver.particleCount();
  const double dt = solver.stableTimeStep().dt;
  const std::vector<double> checks{0.1, 0.2, 0.3, 0.4, 0.5};
  std::size_t next = 0;
  double t = 0, worst = 0;
  for (long long n = 1; next < checks.size(); ++n) {
    solver.step(dt);
    t = n * dt;
    if (t >= checks[next] - 1e-12) {
      const double travelled = centreOfMass(solver)[0] - x0;
      const double expected = 0.5 * a * t * t;
      const double error = travelled / expected - 1;
      if (Tpetra::getDefaultComm()->getRank() == 0)
        std::printf("[ sliding  ] t = %.4f s: travelled %.5f m, a t^2/2 = %.5f m, relative error %+.3e\n", t,
                    travelled, expected, error);
      worst = std::max(worst, std::abs(error));
      ++next;
    }
  }
  EXPECT_EQ(solver.particleCount(), count);
  // 2 % at every check (the brief's bound): the block is 40 times stiffer than it needs to be rigid
  // at this load, and the friction acts on whole node rows, so the remaining error is the settling
  // of the block onto the floor from zero initial stress.
  EXPECT_LT(worst, 0.02);
}
