// The same solver in 3-D: a block sliding down a 30 degree incline with wall friction mu = 0.2
// (gravity tilted, as in the 2-D test), on 1 and 2 ranks: x(t) = g (sin theta - mu cos theta) t^2 / 2.
#include "mpm/mpm_solver.hpp"
#include "mpm_scene_builder.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

using namespace cfdmpm;
using namespace cfdmpm::mpm;

TEST(SlidingBlock3D, FollowsCoulombFrictionAndKeepsItsParticles)
{
  constexpr double kPi = 3.14159265358979323846;
  const double theta = 30.0 * kPi / 180.0, g = 9.81, mu = 0.2;
  const double a = g * (std::sin(theta) - mu * std::cos(theta));
  // 20 mm cells, 2 x 2 x 2 particles per cell; the block (0.1 x 0.06 x 0.06 m) stays clear of the
  // z walls, which are frictional too. E = 2.5e5 Pa keeps it nearly rigid (static strain 1e-3).
  const double h = 0.02;
  Scene scene = scenes::dryScene<3>({0, 0, 0}, {0.6, 0.1, 0.1}, {30, 5, 5}, {10, 5, 5},
                                    {g * std::sin(theta), -g * std::cos(theta), 0});
  scenes::addLinearElastic(scene, "block", 1000.0, 2.5e5, 0.3, 2);
  scenes::addBox(scene, "block", {2 * h, 0, 1 * h}, {7 * h, 3 * h, 4 * h});
  MpmOptions options;
  options.wall_friction = mu;
  options.cfl = 0.4;
  MpmSolver<3> solver(scene, scenes::layoutFor<3>(scene, Tpetra::getDefaultComm()), options);
  const long long count = solver.particleCount();
  EXPECT_EQ(count, 5 * 3 * 3 * 8);
  const double mass = solver.materialMasses()[0];
  const auto centre = [&]() {  // collective
    auto x = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), solver.particles().position);
    auto m = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), solver.particles().mass);
    double local = 0, total = 0;
    for (int q = 0; q < solver.particles().count; ++q) local += m(q) * x(q, 0);
    Teuchos::reduceAll(*solver.layout().comm(), Teuchos::REDUCE_SUM, local, Teuchos::outArg(total));
    return total / mass;
  };
  const double x0 = centre();
  const double dt = solver.stableTimeStep().dt;
  long long n = 0;
  double worst = 0;
  for (double check : {0.25, 0.5}) {
    while ((n + 1) * dt <= check + 1e-12) solver.step(dt), ++n;
    const double t = n * dt;
    const double travelled = centre() - x0;
    const double error = travelled / (0.5 * a * t * t) - 1;
    if (solver.layout().comm()->getRank() == 0)
      std::printf("[ 3-D      ] %d rank(s), t = %.4f s: travelled %.5f m, a t^2/2 = %.5f m, relative error %+.3e\n",
                  solver.layout().comm()->getSize(), t, travelled, 0.5 * a * t * t, error);
    worst = std::max(worst, std::abs(error));
  }
  EXPECT_EQ(solver.particleCount(), count);
  EXPECT_LT(worst, 0.02);  // the 2-D test's bound
}
