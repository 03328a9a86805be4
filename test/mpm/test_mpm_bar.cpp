// Test a: axial vibration of a free-free elastic bar. The first mode of a bar of length L with wave
// speed c = sqrt(E / rho) has the period T = 2 L / c; MPM with 32 cells along the bar must give it
// within 1 %.
#include "mpm/mpm_solver.hpp"
#include "mpm_scene_builder.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

using namespace cfdmpm;
using namespace cfdmpm::mpm;

namespace {

struct BarRun {
  double period_measured = 0;
  double period_analytic = 0;
  int crossings = 0;
};

BarRun vibrateBar(ShapeFunction shape)
{
  constexpr double kPi = 3.14159265358979323846;
  // Bar: L = 1 m, 32 cells along it, 2 cells thick, 4 cells of free space around it.
  // Poisson's ratio 0, so plane strain adds no lateral stiffness: c = sqrt(E / rho) = 100 m/s.
  const double L = 1.0, h = L / 32, E = 1.0e7, rho = 1000.0;
  const double c = std::sqrt(E / rho);
  const double x0 = 4 * h;
  Scene scene = scenes::dryScene<2>({0, 0, 0}, {L + 8 * h, 10 * h, 0}, {40, 10, 1}, {40, 10, 1}, {0, 0, 0});
  scenes::addLinearElastic(scene, "bar", rho, E, 0.0, 2);
  scenes::addBox(scene, "bar", {x0, 4 * h, 0}, {x0 + L, 6 * h, 0});
  MpmOptions options;
  options.shape_function = shape;
  options.cfl = 0.4;
  MpmSolver<2> solver(scene, scenes::layoutFor<2>(scene, Tpetra::getDefaultComm()), options);

  // First free-free mode: u = A cos(pi X / L) sin(omega t), so v(X, 0) = v0 cos(pi X / L).
  // v0 = 1e-2 m/s gives a strain amplitude v0 / c = 1e-4: linear.
  const double v0 = 1e-2;
  auto& particles = solver.particles();
  auto x = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), particles.position);
  auto v = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), particles.velocity);
  std::vector<int> end;  // the last column of particles, at X = L - h / 4
  for (int p = 0; p < particles.count; ++p) {
    v(p, 0) = v0 * std::cos(kPi * (x(p, 0) - x0) / L);
    v(p, 1) = 0.0;
    if (x(p, 0) > x0 + L - h / 2) end.push_back(p);
  }
  Kokkos::deep_copy(particles.velocity, v);
  EXPECT_EQ(end.size(), 4u);

  BarRun run;
  run.period_analytic = 2 * L / c;
  const double dt = solver.stableTimeStep().dt;
  // The end velocity goes as -cos(omega t): it crosses zero at T/4, 3T/4, 5T/4, ...
  std::vector<double> crossings;
  double t = 0, previous = 0;
  for (int p : end) previous += v(p, 0) / end.size();
  while (t < 2.4 * run.period_analytic) {
    solver.step(dt);
    t += dt;
    // One rank and no particle leaves it, so indices are stable.
    auto vh = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), particles.velocity);
    double mean = 0;
    for (int p : end) mean += vh(p, 0) / end.size();
    if ((previous > 0) != (mean > 0)) crossings.push_back(t - dt * mean / (mean - previous));  // linear
    previous = mean;
  }
  run.crossings = int(crossings.size());
  // Zero crossings are half a period apart: average over all of them.
  if (crossings.size() >= 2)
    run.period_measured = 2 * (crossings.back() - crossings.front()) / double(crossings.size() - 1);
  return run;
}

}  // namespace

TEST(ElasticBar, FreeFreePeriodWithinOnePercentAtThirtyTwoCells)
{
  for (ShapeFunction shape : {ShapeFunction::Gimp, ShapeFunction::Linear}) {
    const BarRun run = vibrateBar(shape);
    const double error = run.period_measured / run.period_analytic - 1;
    std::printf("[ bar      ] %s: period %.6f s, analytic 2L/c = %.6f s, relative error %+.3e (%d zero crossings)\n",
                shape == ShapeFunction::Gimp ? "GIMP  " : "linear", run.period_measured, run.period_analytic, error,
                run.crossings);
    ASSERT_EQ(run.crossings, 5);  // T/4 ... 9T/4 in 2.4 T
    // 1 %: the brief's bound; the lumped-mass dispersion error at 32 cells is (pi/32)^2/24 = 4e-4.
    EXPECT_LT(std::abs(error), 0.01);
  }
}
