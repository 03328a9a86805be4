// Test b: an elastic column under its own weight, loaded gradually. In the static state every
// particle carries the weight of the material above it, sigma_yy = -rho0 g (H0 - Y), with Y the
// particle's initial height and rho0, H0 the initial density and height (the mass above a material
// point does not change, whatever the deformation and the constitutive law). GIMP must match it
// closely; linear hat functions, whose gradients jump when particles cross cell faces, must be at
// least 3 times worse.
#include "mpm/mpm_solver.hpp"
#include "mpm_scene_builder.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>

using namespace cfdmpm;
using namespace cfdmpm::mpm;

namespace {

struct ColumnResult {
  double rms_error = 0;   // RMS over particles of (sigma_yy - exact) / (rho g H)
  double max_error = 0;   // max over particles of the same
  double top_drop = 0;    // settlement of the top particles (m)
  double kinetic = 0;     // kinetic energy at the end (J/m)
};

ColumnResult settleColumn(ShapeFunction shape)
{
  // Column 1 m high, 2 cells wide between free-slip walls (uniaxial strain), 32 cells over its height.
  // E = 8e4 Pa makes the constrained modulus M = E (1 - nu) / ((1 + nu)(1 - 2 nu)) = 1.08e5 Pa, so
  // the bottom strain is rho g H / M = 9 % and the top settles by rho g H^2 / (2M) = 1.5 cells:
  // the particles cross cell faces.
  const double H = 1.0, h = H / 32, rho = 1000.0, g = 9.81, E = 8.0e4, nu = 0.3;
  Scene scene = scenes::dryScene<2>({0, 0, 0}, {2 * h, 36 * h, 0}, {2, 36, 1}, {2, 36, 1}, {0, 0, 0});
  scenes::addLinearElastic(scene, "column", rho, E, nu, 2);
  scenes::addBox(scene, "column", {0, 0, 0}, {2 * h, H, 0});
  scenes::setWall(scene, "y-", "no_slip");
  MpmOptions options;
  options.shape_function = shape;
  // Courant number 0.1 for both kernels: with the linear hat, a node that a particle has just
  // reached holds a tiny mass but a full-size gradient, so its frequency is high; at 0.4 the linear
  // run inverts a particle at t = 0.53 s (GIMP's gradients vanish with its weights and run at 0.4).
  options.cfl = 0.1;
  // Mass-proportional damping of 10/s (damping ratio 0.3 in the first mode, omega_1 = 16.6/s)
  // lets the column come to rest; it adds no force at rest, so the static state is unchanged.
  options.velocity_damping = 10.0;
  MpmSolver<2> solver(scene, scenes::layoutFor<2>(scene, Tpetra::getDefaultComm()), options);

  auto& particles = solver.particles();
  std::map<long long, double> initial_height;
  {
    auto x = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), particles.position);
    auto id = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), particles.id);
    for (int p = 0; p < particles.count; ++p) initial_height[id(p)] = x(p, 1);
  }

  // Gravity ramps up over 1 s (2.6 periods of the first mode, 2 pi / omega_1 = 0.38 s) and holds
  // for 2 s more.
  const double ramp = 1.0, end = 3.0;
  const double dt = solver.stableTimeStep().dt;
  for (double t = 0; t < end; t += dt) {
    solver.setGravity({0, -g * std::min(1.0, (t + dt) / ramp), 0});
    solver.step(dt);
  }

  ColumnResult result;
  auto x = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), particles.position);
  auto id = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), particles.id);
  auto sigma = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), particles.stress);
  double sum2 = 0, top = 0;
  for (int p = 0; p < particles.count; ++p) {
    const double Y = initial_height.at(id(p));
    const double exact = -rho * g * (H - Y);
    const double error = (sigma(p, 1, 1) - exact) / (rho * g * H);
    sum2 += error * error;
    result.max_error = std::max(result.max_error, std::abs(error));
    if (Y > H - h / 2) top = std::max(top, Y - x(p, 1));
  }
  result.rms_error = std::sqrt(sum2 / particles.count);
  result.top_drop = top;
  result.kinetic = solver.kineticEnergy();
  return result;
}

}  // namespace

TEST(ElasticColumn, GimpMatchesSelfWeightStressAndLinearHatIsNoisier)
{
  const ColumnResult gimp = settleColumn(ShapeFunction::Gimp);
  const ColumnResult linear = settleColumn(ShapeFunction::Linear);
  for (const auto& [name, r] : {std::pair{"GIMP  ", gimp}, std::pair{"linear", linear}})
    std::printf("[ column   ] %s: sigma_yy error / (rho g H): RMS %.3e, max %.3e; top settles %.4f m "
                "(%.2f cells); kinetic energy at the end %.2e J/m\n",
                name, r.rms_error, r.max_error, r.top_drop, r.top_drop * 32, r.kinetic);
  std::printf("[ column   ] linear / GIMP: RMS %.1f x, max %.1f x\n", linear.rms_error / gimp.rms_error,
              linear.max_error / gimp.max_error);
  // The particles really crossed cell faces.
  EXPECT_GT(gimp.top_drop, 1.0 / 32);
  // GIMP: 2 % of the bottom stress, RMS (the discrete equilibrium of a column resolved by 32 cells
  // and 2 particles per cell differs from the continuum by O(h) at the free top and the wall).
  EXPECT_LT(gimp.rms_error, 0.02);
  // and 5 % at worst (the particles next to the free top and the bottom wall).
  EXPECT_LT(gimp.max_error, 0.05);
  // Cell-crossing noise of the linear hat: at least 3 times the GIMP error (brief's criterion).
  EXPECT_GT(linear.rms_error, 3 * gimp.rms_error);
}
