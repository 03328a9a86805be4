// Stability cases (g) and (h) of doc/stability.md: frictional contact at rest and sliding, on a
// wall and on a rigid plate; contact between materials in the MUSL order.
//
// The incline is made as in test_mpm_sliding: the grid stays level and gravity is tilted,
// g (sin theta, -cos theta), so the floor (the y- wall, or a rigid plate) is the incline. The block
// is 0.1 m x 0.05 m, 10 mm cells, 2 x 2 particles per cell, E = 1 MPa, nu = 0.3, rho = 1000 kg/m^3
// (P-wave speed 36.7 m/s, shear 19.6 m/s; static strain 4e-4, so it is nearly rigid).
//
// Each case writes its numbers as stability_<g|h>_<case>_np<ranks>.csv (test/stability's
// writeSweep: parameter, value, method, status) for utilities/stability_map.py.
#include "mpm/mpm_solver.hpp"
#include "../stability/stability_support.hpp"
#include "disk_scene.hpp"
#include "mpm_scene_builder.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

using namespace cfdmpm;
using namespace cfdmpm::mpm;

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kG = 9.81;
constexpr double kH = 0.01;  // cell size (m)
constexpr double kYoungBlock = 1.0e6, kPoissonBlock = 0.3, kDensityBlock = 1000.0;
constexpr double kBlockHeight = 5 * kH;
constexpr double kPlateTop = 0.08;  // m

/// Mass-weighted centre and velocity of the particles of material `which`, and its lowest particle.
/// Collective.
struct Centre {
  double x[2] = {0, 0}, v[2] = {0, 0}, lowest = 1e300;
};
Centre centreOf(const MpmSolver<2>& solver, int which)
{
  const auto& particles = solver.particles();
  auto x = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), particles.position);
  auto v = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), particles.velocity);
  auto m = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), particles.mass);
  auto material = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), particles.material);
  double local[5] = {0, 0, 0, 0, 0}, total[5] = {0, 0, 0, 0, 0}, low = 1e300, lowest = 1e300;
  for (int p = 0; p < particles.count; ++p) {
    if (material(p) != which) continue;
    local[0] += m(p);
    for (int d = 0; d < 2; ++d) local[1 + d] += m(p) * x(p, d), local[3 + d] += m(p) * v(p, d);
    low = std::min(low, x(p, 1));
  }
  const auto& comm = *solver.layout().comm();
  Teuchos::reduceAll(comm, Teuchos::REDUCE_SUM, 5, local, total);
  Teuchos::reduceAll(comm, Teuchos::REDUCE_MIN, low, Teuchos::outArg(lowest));
  Centre c;
  for (int d = 0; d < 2; ++d) c.x[d] = total[1 + d] / total[0], c.v[d] = total[3 + d] / total[0];
  c.lowest = lowest;
  return c;
}

bool rankZero() { return Tpetra::getDefaultComm()->getRank() == 0; }

std::array<double, 3> tilted(double theta, double scale = 1.0)
{
  return {scale * kG * std::sin(theta), -scale * kG * std::cos(theta), 0};
}

/// The block on the floor wall (material 0); `refine` divides the cell size.
Scene wallScene(double theta, int refine = 1)
{
  Scene scene = scenes::dryScene<2>({0, 0, 0}, {1.0, 0.1, 0}, {100 * refine, 10 * refine, 1},
                                    {25 * refine, 10 * refine, 1}, tilted(theta));
  scenes::addLinearElastic(scene, "block", kDensityBlock, kYoungBlock, kPoissonBlock, 2);
  scenes::addBox(scene, "block", {5 * kH, 0, 0}, {15 * kH, kBlockHeight, 0});
  return scene;
}

/// A rigid particle plate 3 cells thick (material 0) under the block (material 1), whose bottom is
/// `gap` above the plate (as test_mpm_contact).
Scene plateScene(const std::array<double, 3>& gravity, double gap)
{
  Scene scene = scenes::dryScene<2>({0, 0, 0}, {1.0, 0.2, 0}, {100, 20, 1}, {25, 20, 1}, gravity);
  scenes::addRigid(scene, "plate", 2000.0);
  scenes::addLinearElastic(scene, "block", kDensityBlock, kYoungBlock, kPoissonBlock, 2);
  scenes::addBox(scene, "plate", {0.0, kPlateTop - 3 * kH, 0}, {1.0, kPlateTop, 0});
  scenes::addBox(scene, "block", {0.05, kPlateTop + gap, 0}, {0.15, kPlateTop + gap + kBlockHeight, 0});
  return scene;
}

/// Steps to time t; with ramp > 0 gravity grows linearly from zero to `gravity` over `ramp` s.
void runTo(MpmSolver<2>& solver, double dt, long long& n, double t, const std::array<double, 3>& gravity,
           double ramp = 0.0)
{
  while ((n + 1) * dt <= t + 1e-12) {
    const double s = ramp > 0.0 ? std::min(1.0, (n + 1) * dt / ramp) : 1.0;
    solver.setGravity({s * gravity[0], s * gravity[1], 0});
    solver.step(dt);
    ++n;
  }
}

/// The elastic shear displacement of the block at rest on the incline, the scale of the at-rest
/// bounds: the shear stress at depth z is rho g sin(theta) z, so in simple shear the top moves
/// rho g sin(theta) H^2 / (2 G) (1.09e-5 m) and the centre of mass two thirds of that.
double elasticShearDisplacement(double theta)
{
  const double shear_modulus = kYoungBlock / (2 * (1 + kPoissonBlock));
  return kDensityBlock * kG * std::sin(theta) * kBlockHeight * kBlockHeight / (2 * shear_modulus);
}

/// A body at rest on a frictional surface inclined below its friction angle (20 degrees,
/// mu = 0.4 > tan 20 = 0.364): loaded gradually (gravity ramped from zero over 0.2 s, 37 periods of
/// the block's vertical mode 4 H / c_p = 5.4 ms) it reaches equilibrium and must not move after.
/// Returns the drift of the centre of mass from 0.5 s to 1.0 s and its displacement at 1.0 s.
struct Rest {
  double drift, displacement;
};
Rest restOf(const Scene& scene, const MpmOptions& options, int material, double theta)
{
  MpmSolver<2> solver(scene, scenes::layoutFor<2>(scene, Tpetra::getDefaultComm()), options);
  const double x0 = centreOf(solver, material).x[0], dt = solver.stableTimeStep().dt;
  long long n = 0;
  runTo(solver, dt, n, 0.5, tilted(theta), 0.2);
  const double x_half = centreOf(solver, material).x[0];
  runTo(solver, dt, n, 1.0, tilted(theta), 0.2);
  const double x_end = centreOf(solver, material).x[0];
  return {x_end - x_half, x_end - x0};
}

Rest restOnWall(double theta, double mu)
{
  MpmOptions options;
  options.wall_friction = mu;
  options.cfl = 0.4;
  return restOf(wallScene(theta), options, 0, theta);
}

/// Creep speed of the block released stress-free into full gravity (the state every test scene
/// starts from), over 0.3 .. 0.6 s.
double creepSpeed(MpmSolver<2>& solver, int material, double theta)
{
  const double dt = solver.stableTimeStep().dt;
  long long n = 0;
  runTo(solver, dt, n, 0.3, tilted(theta));
  const double x1 = centreOf(solver, material).x[0], t1 = n * dt;
  runTo(solver, dt, n, 0.6, tilted(theta));
  return (centreOf(solver, material).x[0] - x1) / (n * dt - t1);
}

/// Largest relative error of the travelled distance against a t^2 / 2 at 0.2, 0.3, 0.4 s.
double slideError(MpmSolver<2>& solver, int material, double a, const char* label)
{
  const double x0 = centreOf(solver, material).x[0], dt = solver.stableTimeStep().dt;
  const std::array<double, 3> g = solver.gravity();
  double worst = 0;
  long long n = 0;
  for (double check : {0.2, 0.3, 0.4}) {
    runTo(solver, dt, n, check, g);
    const double t = n * dt, travelled = centreOf(solver, material).x[0] - x0;
    const double error = travelled / (0.5 * a * t * t) - 1;
    if (rankZero())
      std::printf("[ slide    ] %s: t = %.4f s travelled %.5f m, a t^2/2 = %.5f m, relative error %+.3e\n", label, t,
                  travelled, 0.5 * a * t * t, error);
    worst = std::max(worst, std::abs(error));
  }
  return worst;
}

}  // namespace

// (g) The fastest case, also in the default suite: at rest on the wall, 1 and 2 ranks.
TEST(FrictionAtRest, WallHoldsBlockBelowFrictionAngle)
{
  const double theta = 20 * kPi / 180, mu = 0.4;
  const Rest rest = restOnWall(theta, mu);
  const double u = elasticShearDisplacement(theta);  // 1.1e-5 m
  if (rankZero())
    std::printf("[ at rest  ] wall, 20 deg, mu 0.4, gravity ramped: displacement %.3e m at 1 s (elastic shear scale "
                "%.3e m), drift 0.5 .. 1 s %+.3e m\n",
                rest.displacement, u, rest.drift);
  // The drift as a speed over 0.5 .. 1 s, at the cell size (mm), beside the stress-free release's creep.
  test::writeSweep(*Tpetra::getDefaultComm(), "stability_g_rest_wall", "cell size (mm)",
                   "speed along the incline at rest (m/s)",
                   {{kH * 1e3, std::abs(rest.drift) / 0.5, "cfdmpm: gravity ramped, wall", "ok"}});
  // Stuck: after 0.5 s only the elastic settling remains. Drift bound: 1 % of the elastic shear
  // displacement in 0.5 s (2e-7 m/s; released stress-free, the block creeps at 2.7e-2 m/s).
  EXPECT_LT(std::abs(rest.drift), 0.01 * u);
  // And it moved no more than its elastic deformation (the block shears by about u).
  EXPECT_LT(std::abs(rest.displacement), 2 * u);
}

TEST(FrictionAtRest, PlateHoldsBlockBelowFrictionAngle)
{
  const double theta = 20 * kPi / 180, mu = 0.4;
  // The block set on the plate (gap 0: contact from the first step).
  MpmOptions options;
  options.contact_friction = mu;
  options.cfl = 0.4;
  const Rest rest = restOf(plateScene(tilted(theta), 0.0), options, 1, theta);
  const double u = elasticShearDisplacement(theta);
  if (rankZero())
    std::printf("[ at rest  ] plate, 20 deg, mu 0.4, gravity ramped: displacement %.3e m at 1 s, drift 0.5 .. 1 s "
                "%+.3e m\n",
                rest.displacement, rest.drift);
  test::writeSweep(*Tpetra::getDefaultComm(), "stability_g_rest_plate", "cell size (mm)",
                   "speed along the incline at rest (m/s)",
                   {{kH * 1e3, std::abs(rest.drift) / 0.5, "cfdmpm: gravity ramped, plate", "ok"}});
  EXPECT_LT(std::abs(rest.drift), 0.01 * u);  // as on the wall
  EXPECT_LT(std::abs(rest.displacement), 2 * u);
}

// (g) Sliding above the friction angle: a = g (sin theta - mu cos theta), released stress-free.
TEST(FrictionSliding, FollowsCoulombOnWallAndOnPlate)
{
  const double theta = 30 * kPi / 180;
  std::vector<test::SweepRow> rows;
  {
    const double mu = 0.4, a = kG * (std::sin(theta) - mu * std::cos(theta));  // 1.507 m/s^2
    const Scene scene = wallScene(theta);
    MpmOptions options;
    options.wall_friction = mu;
    options.cfl = 0.4;
    MpmSolver<2> solver(scene, scenes::layoutFor<2>(scene, Tpetra::getDefaultComm()), options);
    // 2 %, test_mpm_sliding's bound (settling of the stress-free block onto the floor).
    const double error = slideError(solver, 0, a, "wall, 30 deg, mu 0.4");
    rows.push_back({1, error, "wall, mu 0.4", error < 0.02 ? "ok" : "failed"});
    EXPECT_LT(error, 0.02);
  }
  {
    // Set on the plate (gap 0). With each material's own mass gradient as its contact normal,
    // the block's front corner node (normal 45 degrees down) stopped it dead: 1.6e-4 m in 0.4 s.
    const double mu = 0.2, a = kG * (std::sin(theta) - mu * std::cos(theta));  // 3.206 m/s^2
    const Scene scene = plateScene(tilted(theta), 0.0);
    MpmOptions options;
    options.contact_friction = mu;
    options.cfl = 0.4;
    MpmSolver<2> solver(scene, scenes::layoutFor<2>(scene, Tpetra::getDefaultComm()), options);
    const double error = slideError(solver, 1, a, "plate, 30 deg, mu 0.2");
    rows.push_back({2, error, "plate, mu 0.2", error < 0.02 ? "ok" : "failed"});
    EXPECT_LT(error, 0.02);
  }
  test::writeSweep(*Tpetra::getDefaultComm(), "stability_g_sliding", "surface (1 wall, 2 rigid plate)",
                   "largest |travelled / (a t^2/2) - 1| at 0.2-0.4 s", rows);
}

// (g) What makes a body "at rest" creep: released stress-free into full gravity it is not at rest
// but falls into its own compression, and its base starts a stick-slip pulse that runs down the
// interface (doc/stability.md). The creep is the same on the wall and on the plate (the two
// friction paths) and on a grid of half the cell size: a property of the released elastic block
// with Coulomb friction, not of the grid or of one boundary treatment.
TEST(FrictionAtRest, StressFreeReleaseCreepsAlikeOnWallPlateAndFinerGrid)
{
  const double theta = 20 * kPi / 180, mu = 0.4;
  MpmOptions options;
  options.wall_friction = mu;
  options.contact_friction = mu;
  options.cfl = 0.4;
  const Scene wall = wallScene(theta), fine = wallScene(theta, 2), plate = plateScene(tilted(theta), 0.0);
  MpmSolver<2> on_wall(wall, scenes::layoutFor<2>(wall, Tpetra::getDefaultComm()), options);
  MpmSolver<2> on_fine(fine, scenes::layoutFor<2>(fine, Tpetra::getDefaultComm()), options);
  MpmSolver<2> on_plate(plate, scenes::layoutFor<2>(plate, Tpetra::getDefaultComm()), options);
  const double v_wall = creepSpeed(on_wall, 0, theta), v_fine = creepSpeed(on_fine, 0, theta),
               v_plate = creepSpeed(on_plate, 1, theta);
  if (rankZero())
    std::printf("[ creep    ] released stress-free, 20 deg, mu 0.4: wall %.4f m/s, wall at h/2 %.4f m/s, plate %.4f m/s\n",
                v_wall, v_fine, v_plate);
  test::writeSweep(*Tpetra::getDefaultComm(), "stability_g_release", "cell size (mm)",
                   "speed along the incline at rest (m/s)",
                   {{kH * 1e3, v_wall, "released stress-free, wall", "failed"},
                    {kH * 1e3 / 2, v_fine, "released stress-free, wall", "failed"},
                    {kH * 1e3, v_plate, "released stress-free, plate", "failed"}});
  // It creeps: faster than 1 cm/s, against 2e-7 m/s loaded gradually.
  EXPECT_GT(v_wall, 0.01);
  // Within 10 % of each other: the spread of this speed over CFL 0.4 / 0.2 / 0.1 is 6 %.
  EXPECT_NEAR(v_fine / v_wall, 1.0, 0.1);
  EXPECT_NEAR(v_plate / v_wall, 1.0, 0.1);
}

// (h) MUSL with contact: a block dropped two cells onto the rigid plate (test_mpm_contact's drop).
TEST(MuslContact, DroppedBlockDoesNotReboundFasterThanItHit)
{
  const double gap = 2 * kH;
  const Scene scene = plateScene({0, -kG, 0}, gap);
  double ratio[2] = {0, 0};
  for (int musl = 0; musl < 2; ++musl) {
    MpmOptions options;
    options.cfl = 0.4;
    options.stress_update = musl ? StressUpdate::ModifiedLast : StressUpdate::Last;
    MpmSolver<2> solver(scene, scenes::layoutFor<2>(scene, Tpetra::getDefaultComm()), options);
    const double dt = solver.stableTimeStep().dt;
    double down = 0, up = 0, lowest = 1e300;
    for (long long n = 1; n * dt <= 0.2; ++n) {
      solver.step(dt);
      const Centre c = centreOf(solver, 1);
      down = std::max(down, -c.v[1]), up = std::max(up, c.v[1]), lowest = std::min(lowest, c.lowest);
    }
    ratio[musl] = up / down;
    if (rankZero())
      std::printf("[ drop     ] %s: impact %.4f m/s, rebound %.4f m/s (centre of mass), ratio %.4f; lowest particle "
                  "%.5f m (plate top %.3f)\n",
                  musl ? "MUSL" : "USL ", down, up, up / down, lowest, kPlateTop);
    // The stress-free block falls without vibrating, so its kinetic energy at impact is all in
    // the centre of mass; after the bounce some is in vibration. Energy is not created: the
    // centre of mass cannot leave faster than it came (before the fix MUSL left at 1.11 times).
    EXPECT_LT(up, down);
    // It bounced (elastic, free to separate) and stayed out of the plate.
    EXPECT_GT(up, 0.5 * down);
    EXPECT_GT(lowest, kPlateTop);
  }
  test::writeSweep(*Tpetra::getDefaultComm(), "stability_h_drop", "stress update (0 USL, 1 MUSL)",
                   "rebound / impact speed of the centre of mass",
                   {{0, ratio[0], "USL", ratio[0] < 1 ? "ok" : "failed"},
                    {1, ratio[1], "cfdmpm: MUSL, contact held on v*", ratio[1] < 1 ? "ok" : "failed"}});
  // MUSL and USL differ in the strain rate only; their bounces agree to 5 % (0.884 and 0.882).
  EXPECT_NEAR(ratio[1], ratio[0], 0.05 * ratio[0]);
}

TEST(MuslContact, BlockSlidesOnPlateAsCoulomb)
{
  // test_mpm_contact's slide in the MUSL order: 30 degrees, mu 0.2, the block starting one cell
  // above the plate. MUSL ran 16-21 % ahead before the fix.
  const double theta = 30 * kPi / 180, mu = 0.2, a = kG * (std::sin(theta) - mu * std::cos(theta));
  const Scene scene = plateScene(tilted(theta), kH);
  MpmOptions options;
  options.cfl = 0.4;
  options.contact_friction = mu;
  options.stress_update = StressUpdate::ModifiedLast;
  MpmSolver<2> solver(scene, scenes::layoutFor<2>(scene, Tpetra::getDefaultComm()), options);
  const double error = slideError(solver, 1, a, "MUSL, plate, 30 deg, mu 0.2");
  test::writeSweep(*Tpetra::getDefaultComm(), "stability_h_slide", "stress update (1 MUSL)",
                   "largest |travelled / (a t^2/2) - 1| at 0.2-0.4 s",
                   {{1, error, "cfdmpm: MUSL, plate, mu 0.2", error < 0.03 ? "ok" : "failed"}});
  EXPECT_LT(error, 0.03);  // test_mpm_contact's USL bound
}

// (h) The energy two elastic materials lose when they touch: the disks of test_mpm_disks, each its
// own material, frictionless contact on, MUSL, pure FLIP.
namespace {

using namespace cfdmpm::mpm::scenes::disks;

/// The stored energy of all ranks' particles.
double storedEnergy(const MpmSolver<2>& solver)
{
  double local = scenes::disks::storedEnergy(solver.particles()), total = 0;
  Teuchos::reduceAll(*solver.layout().comm(), Teuchos::REDUCE_SUM, local, Teuchos::outArg(total));
  return total;
}

struct Touch {
  double lowest, highest;  // total energy over 3 s, fractions of the initial
};

Touch collideWithContact(long long cells)
{
  Scene scene = scenes::dryScene<2>({0, 0, 0}, {1, 1, 0}, {cells, cells, 1}, {10, 10, 1}, {0, 0, 0});
  scenes::addNeoHookean(scene, "left", kDensity, kBulk, kShear, 2);
  scenes::addNeoHookean(scene, "right", kDensity, kBulk, kShear, 2);
  addDisk(scene, "left", 0.2, 0.2, kSpeed);
  addDisk(scene, "right", 0.8, 0.8, -kSpeed);
  MpmOptions options;
  options.stress_update = StressUpdate::ModifiedLast;
  options.flip_fraction = 1.0;
  options.cfl = 0.2;
  MpmSolver<2> solver(scene, scenes::layoutFor<2>(scene, Tpetra::getDefaultComm()), options);
  const double initial = solver.kineticEnergy() + storedEnergy(solver), dt = solver.stableTimeStep().dt;
  Touch touch{1.0, 1.0};
  for (long long n = 1; n * dt < 3.0; ++n) {
    solver.step(dt);
    const double e = (solver.kineticEnergy() + storedEnergy(solver)) / initial;
    touch.lowest = std::min(touch.lowest, e), touch.highest = std::max(touch.highest, e);
  }
  if (rankZero())
    std::printf("[ touch    ] %lld x %lld cells: total energy within [%.4f, %.4f] of the initial over 3 s\n", cells, cells,
                touch.lowest, touch.highest);
  return touch;
}

}  // namespace

TEST(ContactEnergy, LossAtTouchFallsWithTheCellSize)
{
  // Contact between materials acts at the nodes both have mass on, and makes their normal
  // velocities equal there in one step: a perfectly inelastic collision of those nodes' masses.
  // The continuum loses nothing (the interface layer has no mass); the grid loses the kinetic
  // energy of the relative normal motion of a layer about one cell thick, a mass ~ h, so the loss
  // falls in proportion to h (doc/stability.md).
  const Touch coarse = collideWithContact(20), medium = collideWithContact(40), fine = collideWithContact(80);
  const double loss[3] = {1 - coarse.lowest, 1 - medium.lowest, 1 - fine.lowest};
  const double order = std::log2(loss[0] / loss[2]) / 2;
  if (rankZero())
    std::printf("[ touch    ] losses %.4f, %.4f, %.4f at 20, 40, 80 cells: observed order %.2f\n", loss[0], loss[1],
                loss[2], order);
  std::vector<test::SweepRow> rows;
  const double cells[3] = {20, 40, 80};
  const Touch touches[3] = {coarse, medium, fine};
  for (int k = 0; k < 3; ++k) {
    rows.push_back({cells[k], loss[k], "cfdmpm: MUSL contact, energy lost", "ok"});
    rows.push_back({cells[k], std::max(touches[k].highest - 1, 0.0), "cfdmpm: energy gained above the initial",
                    touches[k].highest < 1.01 ? "ok" : "failed"});
  }
  test::writeSweep(*Tpetra::getDefaultComm(), "stability_h_touch", "cells across the unit square",
                   "total energy lost (lowest over 3 s) / gained, fractions of the initial", rows);
  // No energy gained: MUSL without contact stays within 1 % above (test_mpm_disks, 20 x 20).
  for (const Touch& t : {coarse, medium, fine}) EXPECT_LT(t.highest, 1.01);
  // The loss falls at every refinement and at least at first order over the two halvings
  // (an O(h) layer; measured 1.1).
  EXPECT_LT(loss[1], loss[0]);
  EXPECT_LT(loss[2], loss[1]);
  EXPECT_GT(order, 1.0);
}
