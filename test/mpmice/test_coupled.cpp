// The coupled step on cases with known answers (issue: the coupled MPMICE step).
#include "coupled_support.hpp"
#include "mpmice/run_state.hpp"
#include "common/mpi_comm.hpp"

#include <gtest/gtest.h>

#include <cstdio>

namespace cfdmpm::test {
namespace {

Teuchos::RCP<const Teuchos::Comm<int>> world() { return Teuchos::DefaultComm<int>::getComm(); }

const char* kElasticBlock = R"(    block:
      kind: solid
      density: DENSITY
      particles_per_cell: 2
      model: {type: linear_elastic, youngs_modulus: 1.0e6, poisson_ratio: 0.3}
)";

std::string withDensity(std::string text, double density)
{
  const std::size_t at = text.find("DENSITY");
  return text.replace(at, 7, std::to_string(density));
}

// (a) An elastic block of the water's density, submerged in still water in a closed tank, stays put.
// The bound comes from the same tank without the block: its largest water speed is the scheme's noise
// at rest. That tank's pressure residual is far below the outer iteration's tolerance, while the
// block's is not: a residual of `outer_tolerance` (a volume fraction per step) allows face velocities
// wrong by tolerance h / Δt (1.5e-6 m/s here), so the bound is the larger of ten times the still
// tank's noise and that. It holds after a start-up of 0.1 s (the first steps settle the discrete
// hydrostatic balance of a compressible liquid around a block of uniform density; the block's peak
// is 5e-7 m/s, g dt_initial / 200, and decays by a factor of 10 every ~0.03 s); over the whole run the
// block may move no farther than the bound times the duration.
TEST(CoupledStep, NeutrallyBuoyantBlockStaysPut)
{
  const double end = 0.5, start_up = 0.1;
  CoupledRun<2> still(sceneFromYaml(tankScene(0.2, 0.2, 20, 20, 0.2, "", "")), world());
  double noise = 0;
  still.runUntil(end, [&] {
    if (still.time > start_up) noise = std::max(noise, still.maxFluidSpeed(0));
  });

  // Neutral means the density of the water at the block's centre (y = 0.1 m, 0.1 m under the lid,
  // where the pressure is 101325 Pa): water is compressible, 1000 kg/m^3 + Δp / Kf with
  // Kf = 2.15e9 / 1000 m^2/s^2, and 4.6e-7 of buoyancy would move the block ~100 times faster than
  // the noise.
  const double neutral = 1000.0 + 1000.0 * 9.81 * 0.1 / 2.15e6;
  CoupledRun<2> run(sceneFromYaml(tankScene(0.2, 0.2, 20, 20, 0.2, withDensity(kElasticBlock, neutral),
                                            "    b: {material: block, shape: box, lower: [0.06, 0.06], upper: [0.14, 0.14]}")),
                    world());
  const auto start = run.positions();
  double fastest = 0, peak = 0;
  run.runUntil(end, [&] {
    const double speed = run.maxParticleSpeed(0);
    peak = std::max(peak, speed);
    if (run.time > start_up) fastest = std::max(fastest, speed);
  });
  const double moved = run.largestDisplacement(start);
  if (world()->getRank() == 0)
    std::printf("still-tank noise %.3e m/s, tolerance h / dt %.3e m/s; block: fastest particle after start-up %.3e "
                "m/s (peak %.3e), largest displacement %.3e m in %lld steps\n",
                noise, IceSettings::fromScene(run.scene).outer_tolerance * 0.01 / run.dt_previous, fastest, peak, moved,
                run.steps);
  const double tolerance_speed = IceSettings::fromScene(run.scene).outer_tolerance * 0.01 / run.dt_previous;
  const double bound = std::max(10 * noise, tolerance_speed);
  EXPECT_LE(fastest, bound);
  EXPECT_LE(moved, bound * end);
}

// (a) in three dimensions: the same block as a cube (0.05 m, 4 cells across) in a closed 0.2 m tank
// of 16^3 cells, water to 0.15 m and air above it, on 1 and 2 ranks; 0.1 s (~1200 steps) after a
// start-up of 0.02 s. The same bound as in 2-D (ten times the still tank's noise, or the outer
// tolerance's h / Δt), and every fluid's mass to round-off (4096 cells of summands, 1e-12). Measured
// (1 / 2 ranks): the cube's fastest particle 5.8e-8 / 4.7e-8 m/s against bounds of 2.0e-5 / 2.3e-5
// (the still tank's noise 2.0e-6 / 2.3e-6 m/s), displacement 3e-11 / 5e-11 m, the masses to 2.5e-14.
std::string cubeTank(const std::string& solids, const std::string& regions)
{
  return R"(
cfdmpm:
  domain: {dimension: 3, lower: [0.0, 0.0, 0.0], upper: [0.2, 0.2, 0.2], cells: [16, 16, 16], patch_cells: [8, 8, 8], gravity: [0.0, -9.81, 0.0]}
  materials:
)" + solids + "\n" + kTankWater + kTankAir + R"(  initial_state: {background_material: air, temperature: 293.15, pressure: 101325.0, hydrostatic: true}
  regions:
    level: {material: water, shape: half_plane, point: [0.0, 0.15, 0.0], normal: [0.0, 1.0, 0.0]}
)" + regions + R"(
  time: {end_time: 1.0, cfl: 0.25, dt_initial: 1.0e-5}
  output: {directory: unused, interval: 0.0}
)";
}

TEST(CoupledStep, ThreeDNeutralCubeStaysPutAndKeepsItsWater)
{
  const double end = 0.1, start_up = 0.02;
  CoupledRun<3> still(sceneFromYaml(cubeTank("", "")), world());
  double noise = 0;
  still.runUntil(end, [&] {
    if (still.time > start_up) noise = std::max({noise, still.maxFluidSpeed(0), still.maxFluidSpeed(1)});
  });
  // Neutral at the cube's centre, 0.075 m under the surface (the air above adds ~0.6 Pa).
  const double neutral = 1000.0 + 1000.0 * 9.81 * 0.075 / 2.15e6;
  CoupledRun<3> run(sceneFromYaml(cubeTank(withDensity(kElasticBlock, neutral),
                                           "    b: {material: block, shape: box, lower: [0.075, 0.05, 0.075], upper: [0.125, 0.1, 0.125]}")),
                    world());
  const auto start = run.positions();
  const double mass0[2] = {run.fluidMass(1), run.fluidMass(2)};  // water, air (the block is material 0)
  double fastest = 0;
  run.runUntil(end, [&] {
    if (run.time > start_up) fastest = std::max(fastest, run.maxParticleSpeed(0));
  });
  const double moved = run.largestDisplacement(start);
  const double tolerance_speed = IceSettings::fromScene(run.scene).outer_tolerance * (0.2 / 16) / run.dt_previous;
  const double bound = std::max(10 * noise, tolerance_speed);
  const double water_change = run.fluidMass(1) / mass0[0] - 1, air_change = run.fluidMass(2) / mass0[1] - 1;  // collective
  if (world()->getRank() == 0)
    std::printf("3-D: still-tank noise %.3e m/s, tolerance h / dt %.3e m/s; cube: fastest particle after start-up %.3e "
                "m/s, largest displacement %.3e m in %lld steps; water mass change %.1e, air %.1e\n",
                noise, tolerance_speed, fastest, moved, run.steps, water_change, air_change);
  EXPECT_GT(run.steps, 100);  // the run took steps of its own (Δt from the particles' wave speed)
  EXPECT_LE(fastest, bound);
  EXPECT_LE(moved, bound * end);
  EXPECT_LT(std::abs(water_change), 1e-12);
  EXPECT_LT(std::abs(air_change), 1e-12);
}

// (b) A sand block resting on the floor under water: the water's pressure is not the skeleton's, so
// the block's skeleton carries its buoyant weight, (ρs − ρw) g per volume, and nothing more, and the
// block stays at rest. The reference is the same block dry (the particle step alone) under the
// gravity (1 − ρw/ρs) g, whose weight is that buoyant weight: the two must have the same vertical
// stress over the central half of the base (the lowest particle row), where an elastic block on a
// no-slip floor has a non-uniform stress that neither simple formula gives to 5 %. The wet one is
// averaged over the last 0.1 s: the settling excites a sloshing of the water (period ~0.1 s). Bound
// 3 %: the sloshing's and the pore pressure's deviations at the base (±10 Pa measured inside the
// block against the water beside it, 2 % of the 590 Pa buoyant weight there) and the air's
// expansion (below).
// extra_mpm: more keys of the wet run's mpm section. Returns the most particle steps the wet run
// took in one step.
int expectSandBlockRestsOnItsBuoyantWeight(const std::string& extra_mpm)
{
  const double rho_s = 2000.0, rho_w = 1000.0;
  const std::string block = "    b: {material: block, shape: box, lower: [0.05, 0.0], upper: [0.15, 0.06]}";
  const auto baseStress = [&](CoupledRun<2>& run) {
    auto& p = run.particles().particles();
    auto x = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), p.position);
    auto sigma = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), p.stress);
    double sums[2] = {0, 0}, total[2] = {0, 0};
    for (int i = 0; i < p.count; ++i)
      if (x(i, 1) < 0.005 && x(i, 0) > 0.075 && x(i, 0) < 0.125) sums[0] += sigma(i, 1, 1), sums[1] += 1;
    Teuchos::reduceAll(*world(), Teuchos::REDUCE_SUM, 2, sums, total);
    return total[0] / total[1];
  };
  // Mass-proportional damping brings the elastic block to rest within ~0.1 s (its first mode has a
  // period of ~9 ms); it acts on the particles' motion only, not on the static stress.
  CoupledRun<2> dry(sceneFromYaml(tankScene(0.2, 0.5, 20, 50, 0.15, withDensity(kElasticBlock, rho_s), block,
                                            "  mpm: {velocity_damping: 100.0}\n  ice: {enabled: false}",
                                            -9.81 * (1 - rho_w / rho_s))),
                    world());
  dry.runUntil(0.3);
  const double dry_stress = baseStress(dry);
  // Air above the water, as in the slide's scene, holds the water's pressure: the block's skeleton
  // compresses by ~1.3e-6 m^3/m as it takes its load, and the air that fills this room expands by
  // that much. Under 0.05 m of air that lowers every pressure by 13 Pa (2 % of the buoyant weight at
  // the base), which the pore pressure inside the block, held at the still-water reference, does not
  // follow (doc/mpmice.md); under 0.35 m of air, as here, by 2 Pa (0.3 %).
  CoupledRun<2> run(sceneFromYaml(tankScene(0.2, 0.5, 20, 50, 0.15, withDensity(kElasticBlock, rho_s), block,
                                            "  mpm: {velocity_damping: 100.0" + extra_mpm + "}")),
                    world());
  double stress_sum = 0, samples = 0, speed = 0;
  int particle_steps = 1;
  run.runUntil(0.4, [&] {
    particle_steps = std::max(particle_steps, run.last.particle_steps);
    if (run.time > 0.3) {
      stress_sum += baseStress(run), samples += 1;
      speed = std::max(speed, run.maxParticleSpeed(0));
    }
  });
  const double ratio = stress_sum / samples / dry_stress;
  if (world()->getRank() == 0)
    std::printf("base stress: dry under the buoyant weight %.2f Pa (%.4f of (ρs − ρw) g h), wet %.2f Pa (mean of %g "
                "steps), ratio %.4f; fastest particle %.3e m/s in the last 0.1 s\n",
                dry_stress, dry_stress / (-(rho_s - rho_w) * 9.81 * (0.06 - 0.0025)), stress_sum / samples, samples, ratio,
                speed);
  EXPECT_NEAR(ratio, 1.0, 0.03);
  // At rest but for the sloshing: slower than a free fall over one damping time, g / α = 0.1 m/s,
  // by two orders of magnitude.
  EXPECT_LT(speed, 1e-3 * 9.81);
  return particle_steps;
}

TEST(CoupledStep, SandBlockRestsOnItsBuoyantWeight) { EXPECT_EQ(expectSandBlockRestsOnItsBuoyantWeight(""), 1); }

// The same with up to four particle steps in each step of the fluids (mpm.substeps: 4): the fluids'
// force on the block, spread over its particle steps, carries the same share of its weight.
TEST(CoupledStep, ParticleStepsInsideAFluidStepKeepTheBlocksBuoyantWeight)
{
  EXPECT_GE(expectSandBlockRestsOnItsBuoyantWeight(", substeps: 4"), 2);
}

// The same with the solids' volume from their particles (mpm.solid_volume: particles): the pressure
// equation's view of the block changes, its load must not.
TEST(CoupledStep, ParticleVolumesKeepTheBlocksBuoyantWeight)
{
  expectSandBlockRestsOnItsBuoyantWeight(", solid_volume: particles");
}

// (c) Added mass: a circular disk (a 2-D cylinder) released from rest in still water accelerates at
// a = g (ρs − ρw) / (ρs + ρw): potential flow gives a circular cylinder an added mass equal to the
// mass of the water it displaces. The tank is ten diameters across and deep, so that the walls add
// ~1 % (the image of a dipole at five diameters); the acceleration is the slope of the disk's mean
// velocity from 5 to 20 ms, before its speed (~0.05 m/s) makes drag matter. Bound 10 % at 20 cells
// per diameter (the issue's), for a sinking (2000 kg/m^3) and a rising (500 kg/m^3) disk.
double diskAcceleration(double density, int cells_per_diameter)
{
  CoupledRun<2> run(sceneFromYaml(addedMassDiskScene(density, cells_per_diameter)), world());
  std::vector<double> times, speeds;
  run.sampleMeanVerticalVelocity(0, 0.005, 0.02, times, speeds);
  return fitLine(times, speeds).slope;
}

TEST(CoupledStep, DiskAcceleratesWithTheAddedMassOfPotentialFlow)
{
  for (const double density : {2000.0, 500.0}) {
    const double expected = -9.81 * (density - 1000.0) / (density + 1000.0);
    const double a = diskAcceleration(density, 20);
    if (world()->getRank() == 0)
      std::printf("disk of %.0f kg/m^3, 20 cells per diameter: a = %.4f m/s^2, potential flow %.4f (ratio %.3f)\n",
                  density, a, expected, a / expected);
    EXPECT_NEAR(a / expected, 1.0, 0.10) << density;
  }
}

// The lightest body: the same disk at 10 kg/m^3, whose own inertia is 1 % of its added mass, so that
// 99 % of its motion is the pressure's. It rises with the acceleration of potential flow only if the
// pressure that moves its particles is the one the pressure equation solved for with the disk's
// motion in it (`interior_pressure: cell`, an elastic body's default): with the still water's
// hydrostatic pressure acting inside it (`reference`), its interior feels the buoyancy against its
// own weight alone (99 g), and at 10 cells per diameter its mean velocity over [2, 6] ms departs
// from a line by 2.7 times the speed it should reach (1.5 MPa equilibration jumps; at 20 cells per
// diameter the run stopped, doc/stability.md case (b)). 10 cells per diameter over [2, 6] ms keeps
// the case to ~1800 steps (the disk's elastic wave sets the step). Bounds: the acceleration within
// the issue's 10 % of potential flow (0.92 measured); the velocity's RMS departure from the fitted
// line within 5 % of the speed reached at 6 ms (measured 1 %: the start-up's pressure waves ringing
// in the tank).
TEST(CoupledStep, LightBodyRisesWithTheAddedMassOfPotentialFlow)
{
  const double density = 10.0, expected = -9.81 * (density - 1000.0) / (density + 1000.0);
  CoupledRun<2> run(sceneFromYaml(addedMassDiskScene(density, 10)), world());
  std::vector<double> times, speeds;
  run.sampleMeanVerticalVelocity(0, 0.002, 0.006, times, speeds);
  const LineFit fit = fitLine(times, speeds);
  double square = 0;
  for (std::size_t k = 0; k < times.size(); ++k) square += std::pow(speeds[k] - (fit.offset + fit.slope * times[k]), 2);
  const double departure = std::sqrt(square / double(times.size())), reached = expected * 0.006;
  if (world()->getRank() == 0)
    std::printf("disk of %.0f kg/m^3, 10 cells per diameter: a = %.4f m/s^2, potential flow %.4f (ratio %.3f), "
                "RMS departure from the line %.3e m/s (%.3f of the speed reached)\n",
                density, fit.slope, expected, fit.slope / expected, departure, departure / reached);
  EXPECT_NEAR(fit.slope / expected, 1.0, 0.10);
  EXPECT_LT(departure, 0.05 * reached);
}

// A heavy elastic block (3000 kg/m^3, 4 x 4 cells of 10 mm, its top and bottom on cell faces) falls
// from rest through the air of a tank above a shallow pool, for 0.08 s. The air's forces on it are
// below 1e-3 of its weight (buoyancy ρ_air/ρ_s = 4e-4; drag at 0.8 m/s ~6e-4 g), so its mean
// velocity is −g t to 1 % (bound) throughout. The air moves as the block displaces it: in
// potential flow its kinetic energy is ½ C_a ρ_air a² V² with C_a = 1.19 for a square, and the
// tank, five blocks wide, raises that by a factor of order one (measured before any crossing:
// 2.0-2.55 times). Bound: ten times potential flow's over the whole fall, which holds three face
// crossings of the block's top and bottom together (at 0.045, 0.064 and 0.078 s; measured 3.47
// times at most, the same on 1 and 2 ranks). Each crossing has failed before (doc/mpmice.md, "the
// fluids' room on a face"): with the room taken from the donor's layer alone the air crossed into
// the block's cells at the first and was trapped there (1.9e5 times the bound, the block 20 %
// slower than g t); with the cover ramped in by the lesser of the layers beside the face, the face
// the top left within a step stayed covered for the whole step, and the air that had to follow the
// block reached 1220 and 440 times potential flow's at the second and third.
TEST(CoupledStep, BlockFallingThroughAirKeepsTheAirToItsOwnFlow)
{
  const double a = 0.04, rho_air = 101325.0 / (287.0 * 293.15), g = 9.81, end = 0.08;
  const char* block = R"(    block:
      kind: solid
      density: 3000.0
      particles_per_cell: 2
      model: {type: linear_elastic, youngs_modulus: 5.0e6, poisson_ratio: 0.3}
)";
  // The pressure solves stop at a relative residual of 1e-10 here (by default each stops at half
  // the outer test's allowance, weighted per cell): at the crossings the faces the block opens and
  // closes within a step make the air's flow sensitive to the pressure's last digits, and the
  // default stop differs between 1 and 2 ranks (2 ranks reached 7.9 and 19 times potential flow at
  // the second and third crossings where 1 rank gives 3.4 and 3.5); at 1e-10 both give the same
  // numbers to three digits.
  CoupledRun<2> run(sceneFromYaml(tankScene(0.2, 0.3, 20, 30, 0.03, block,
                                            "    b: {material: block, shape: box, lower: [0.08, 0.2], upper: [0.12, 0.24]}",
                                            "  ice: {solver_tolerance: 1.0e-10}")),
                    world());
  const int air = 2;  // block, water, air
  double worst_fall = 0, worst_air = 0;
  run.runUntil(end, [&] {
    const double v = run.meanParticleVelocity(0, 1), free_fall = -g * run.time;
    worst_fall = std::max(worst_fall, std::abs(v / free_fall - 1.0));
    const double potential = 0.5 * 1.19 * rho_air * a * a * v * v;
    const double air_energy = run.fluidKineticEnergy(air);  // collective: every step on every rank
    worst_air = std::max(worst_air, air_energy / potential);
  });
  if (world()->getRank() == 0)
    std::printf("falling block: mean velocity within %.2e of -g t to %.2f s; air kinetic energy at most %.2f times "
                "potential flow's added mass (%lld steps)\n",
                worst_fall, end, worst_air, run.steps);
  EXPECT_LT(worst_fall, 0.01);
  EXPECT_LT(worst_air, 10.0);
}

// (d) Displacement: a rigid plunger, a block of width w centred in a tank of width L, moves
// straight down at a constant speed V from the air into still water (depth H0 = 0.2 m) and sinks to a
// depth d below the initial level. Water is incompressible here (the hydrostatic pressure changes its
// volume by 1e-6) and its volume is conserved, so with the water under the plunger filling the
// columns up to its bottom the level in the open part is
//   η = H0 + w d / (L − w),   d = H0 − y_bottom(t_end)
// (no part of the plunger is in the water at t = 0: its bottom starts at the surface; started two
// cells above it, the program needs one retried step as the bottom closes the last row of air, which
// this in-process run does not make, and the air cushion trapped under the flat bottom, ~3 mm,
// raises the level by 0.1 cell more). The fluid beside the plunger sees the faces it closes as
// walls: the pressure of the cells it fills, set by a trace of fluid and its stiffness, reached
// the water beside and under it through the face pressures and drove it at up to 70 m/s (the run
// then took 6720 steps instead of 93 and ended 0.7 cell low). The level
// of a column is its water volume per unit width, Σ_j θ_w h; the test averages it over the open
// columns except the one next to each side of the plunger, where the water it pushes out rises
// first. Bound: one cell height (the issue's). The air the plunger leaves behind fills the room it
// leaves: it comes in through the faces the plunger opens (doc/mpmice.md, rigid solids).
// The water's mass is conserved to round-off (relative 1e-12): the advection moves it in fluxes
// between cells, what leaves one cell enters the next, and the walls pass none; the sums over ~1e3
// steps and 1600 cells add round-off of order 1e-16 each.
TEST(CoupledStep, PlungerRaisesTheLevelByTheDisplacedVolume)
{
  const double L = 0.4, H0 = 0.2, w = 0.1, V = 0.1, bottom0 = 0.2, end = 0.6;
  const long long n = 40;
  const double h = L / n;
  const char* plunger = R"(    plunger:
      kind: solid
      density: 1000.0
      particles_per_cell: 2
      model: {type: rigid, velocity: [0.0, -0.1]}
)";
  char region[200];
  std::snprintf(region, sizeof region, "    p: {material: plunger, shape: box, lower: [%.6f, %.6f], upper: [%.6f, %.6f]}",
                0.5 * (L - w), bottom0, 0.5 * (L + w), bottom0 + 0.15);
  CoupledRun<2> run(sceneFromYaml(tankScene(L, L, n, n, H0, plunger, region)), world());
  const int water = 1;  // plunger, water, air
  // Water volume per unit width of every column (collective).
  const auto levels = [&] {
    std::vector<double> local(n, 0.0), total(n, 0.0);
    const auto theta = run.state.volume_fraction.view();
    const auto ijk = run.layout->cellIndex();
    for (LocalOrdinal c = 0; c < run.state.volume_fraction.ownedCount(); ++c) local[ijk(c, 0)] += theta(c, water) * h;
    Teuchos::reduceAll(*world(), Teuchos::REDUCE_SUM, int(n), local.data(), total.data());
    return total;
  };
  // Open columns: outside the plunger (columns 15..24) and one column away from it.
  const long long first_under = (long long)std::lround(0.5 * (L - w) / h), last_under = first_under + (long long)std::lround(w / h) - 1;
  const auto openMean = [&](const std::vector<double>& level, long long margin, double* lowest, double* highest) {
    double sum = 0, count = 0;
    *lowest = 1e30, *highest = -1e30;
    for (long long i = 0; i < n; ++i)
      if (i < first_under - margin || i > last_under + margin) {
        sum += level[i], count += 1;
        *lowest = std::min(*lowest, level[i]), *highest = std::max(*highest, level[i]);
      }
    return sum / count;
  };
  double lo = 0, hi = 0;
  const double level0 = openMean(levels(), 1, &lo, &hi);
  const double mass0 = run.fluidMass(water);
  run.runUntil(end);
  const double mass1 = run.fluidMass(water);
  const std::vector<double> level = levels();
  const double away = openMean(level, 1, &lo, &hi);
  double lo_all = 0, hi_all = 0;
  const double all_open = openMean(level, 0, &lo_all, &hi_all);
  const double d = H0 - (bottom0 - V * end);
  const double expected = w * d / (L - w);
  if (world()->getRank() == 0)
    std::printf("plunger sunk %.4f m into the water after %.2f s (%lld steps): level rise away from it %.5f m "
                "(columns %.5f to %.5f), over all open columns %.5f m, expected w d / (L - w) = %.5f m; "
                "error %.2e m = %.3f cell; initial level %.6f m; water mass %.12e -> %.12e (relative change %.2e)\n",
                d, run.time, run.steps, away - level0, lo - level0, hi - level0, all_open - level0, expected,
                away - level0 - expected, (away - level0 - expected) / h, level0, mass0, mass1,
                (mass1 - mass0) / mass0);
  EXPECT_NEAR(away - level0, expected, h);
  EXPECT_NEAR(mass1, mass0, 1e-12 * mass0);
}

// (c') Cells that a rigid body fills are walls (IceSolver::closedCells): a rigid block aligned with
// the cells in the lower left quarter of a water tank closes exactly its 200 cells (two particles per
// cell and direction, whose boxes tile each cell); the still water beside and above it stays still,
// to the same bound as the neutrally buoyant block (the still tank's noise without the block, or what
// the outer tolerance allows), and keeps its mass to round-off; the closed cells keep the pressure of
// the still water that the block displaces, which the initial equilibration gave them (within 1 % of
// a cell's hydrostatic step, ρ g h = 98 Pa: the initial state integrates the hydrostatic pressure of a
// compressible liquid, the check takes it incompressible). The block's cells whose neighbours are
// all closed or walls (19 x 9: all but its right column and top row) have no row in the pressure
// matrix (IceSolver::cellsWithoutPressureRow); the others keep theirs.
const char* kRigidBlock = R"(    bed:
      kind: solid
      density: 2000.0
      particles_per_cell: 2
      model: {type: rigid, velocity: [0.0, 0.0]}
)";
const char* kRigidBlockRegion = "    b: {material: bed, shape: box, lower: [0.0, 0.0], upper: [0.2, 0.1]}";

TEST(CoupledStep, CellsThatARigidBodyFillsAreWalls)
{
  const double end = 0.3, start_up = 0.1, h = 0.01, top = 0.2, rho_w = 1000.0, g = 9.81;
  CoupledRun<2> still(sceneFromYaml(tankScene(0.4, top, 40, 20, top, "", "")), world());
  double noise = 0;
  still.runUntil(end, [&] {
    if (still.time > start_up) noise = std::max(noise, still.maxFluidSpeed(0));
  });
  CoupledRun<2> run(sceneFromYaml(tankScene(0.4, top, 40, 20, top, kRigidBlock, kRigidBlockRegion)), world());
  const int water = 1;  // bed, water
  const double mass0 = run.fluidMass(water);
  double fastest = 0;
  long long closed = -1;
  run.runUntil(end, [&] {
    if (closed < 0) closed = run.stepper.fluids()->closedCellCount();
    if (run.time > start_up) fastest = std::max(fastest, run.maxFluidSpeed(water));
  });
  const double mass1 = run.fluidMass(water);
  // The pressure of the closed cells against the still water's at their centres.
  const auto shut = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), run.stepper.fluids()->closedCells());
  const auto p = run.state.pressure.view();
  const auto ijk = run.layout->cellIndex();
  const auto without_row =
      Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), run.stepper.fluids()->cellsWithoutPressureRow());
  double worst = 0, local_closed = 0, local_without_row = 0, without_row_open = 0;
  for (LocalOrdinal c = 0; c < run.state.pressure.ownedCount(); ++c) {
    if (without_row(c)) {
      local_without_row += 1;
      if (!shut(c)) without_row_open += 1;
    }
    if (!shut(c)) continue;
    local_closed += 1;
    const double y = (ijk(c, 1) + 0.5) * h;
    worst = std::max(worst, std::abs(p(c, 0) - (101325.0 + rho_w * g * (top - y))));
  }
  worst = globalMax(*world(), worst);
  const double tolerance_speed = IceSettings::fromScene(run.scene).outer_tolerance * h / run.dt_previous;
  const double bound = std::max(10 * noise, tolerance_speed);
  if (world()->getRank() == 0)
    std::printf("closed cells %lld (owned here %g); still-tank noise %.3e m/s, bound %.3e; water beside the block: "
                "fastest %.3e m/s after start-up, %lld steps; mass change %.2e; closed cells' pressure off the "
                "still water's by at most %.3f Pa\n",
                closed, local_closed, noise, bound, fastest, run.steps, (mass1 - mass0) / mass0, worst);
  EXPECT_EQ(closed, 200);
  EXPECT_EQ(run.stepper.fluids()->closedCellCount(), 200);
  EXPECT_EQ(globalSum(*world(), local_without_row), 19.0 * 9.0);
  EXPECT_EQ(globalSum(*world(), without_row_open), 0.0);
  EXPECT_EQ(run.stepper.fluids()->pressureRows(), 800 - 19 * 9);
  EXPECT_LE(fastest, bound);
  EXPECT_NEAR(mass1, mass0, 1e-12 * mass0);
  EXPECT_LE(worst, 0.01 * rho_w * g * h);
}

// The solids' face shares and covers that the fluids take are the particles' sums of the step
// (MpmSolver::particlesToCells) in every local cell, also where the coupled step passes over the
// cells that only a rigid body at rest reaches (their sums and shares are the same at every step;
// MpmIceStep::cellsFromParticles keeps them). An elastic block slides at 1 m/s along a rigid bed
// under water, so that the cells at its trailing edge go from the block and the bed to the bed
// alone; after every step the shares and covers must equal the sums' columns exactly (each is a
// copy of one of them), on 1 and 2 ranks.
TEST(CoupledStep, FaceSharesAreTheParticlesSumsWhereABedAloneIs)
{
  const std::string solids = std::string(kRigidBlock) + R"(    block:
      kind: solid
      density: 1500.0
      particles_per_cell: 2
      model: {type: linear_elastic, youngs_modulus: 1.0e6, poisson_ratio: 0.3}
)";
  const std::string regions = "    b: {material: bed, shape: box, lower: [0.0, 0.0], upper: [0.4, 0.05]}\n"
                              "    k: {material: block, shape: box, velocity: [1.0, 0.0], lower: [0.05, 0.05], upper: [0.12, 0.09]}";
  CoupledRun<2> run(sceneFromYaml(tankScene(0.4, 0.2, 40, 20, 0.2, solids, regions)), world());
  const int nm = 2, touch = mpm::MpmSolver<2>::touchColumn(nm);
  const int scene_index[2] = {0, 1};  // bed, block (then water)
  long long compared = 0, differing = 0, bed_alone = 0;
  run.runUntil(0.03, [&] {
    const auto sums = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), run.stepper.cellSums()->view());
    const auto stationary = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), run.stepper.particles()->stationaryCellSums());
    ASSERT_GT(stationary.extent(0), 0u);  // the bed's sums are made once
    for (int d = 0; d < 2; ++d) {
      const auto share = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), run.stepper.fluids()->solidFaceShares().direction(d).view());
      const auto cover = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), run.stepper.fluids()->solidFaceCovers().direction(d).view());
      for (std::size_t c = 0; c < sums.extent(0); ++c) {
        if (d == 0 && stationary(c, touch) > 0 && sums(c, touch) == stationary(c, touch)) ++bed_alone;
        for (int a = 0; a < nm; ++a)
          for (int side = 0; side < 2; ++side) {
            const int m = scene_index[a];
            ++compared;
            if (share(c, 2 * m + side) != sums(c, mpm::MpmSolver<2>::faceColumn(nm, a, d, side))) ++differing;
            if (cover(c, 2 * m + side) != sums(c, mpm::MpmSolver<2>::roomColumn(nm, a, d, side))) ++differing;
          }
      }
    }
  });
  compared = globalSum(*world(), double(compared));
  differing = globalSum(*world(), double(differing));
  bed_alone = globalSum(*world(), double(bed_alone));
  if (world()->getRank() == 0)
    std::printf("[ shares   ] %lld steps, %lld values compared, %lld differ; cells of the bed alone over the steps %lld\n",
                run.steps, compared, differing, bed_alone);
  EXPECT_EQ(differing, 0);
  EXPECT_GT(bed_alone, 100 * run.steps);  // most of the bed's cells: the passed-over path was taken
  EXPECT_GE(run.steps, 10);
}

// The division of the patches by their open cells (divisionByOpenCells): the same tank in 32
// patches of 5 x 5 cells, 8 of them inside the block. By cell counts 2 ranks get the left and the
// right half, the block's patches all on the left (work 8 x 0.5 + 8 against 16 patches: imbalance
// 1/7 = 0.143 with kClosedCellWork = 0.5); by open cells each gets 14 patches' work. (On 8 patches
// of 10 x 10 METIS's bisection found no better division than the halves.)
TEST(CoupledStep, PatchesAreDividedByTheirOpenCells)
{
  std::string text = tankScene(0.4, 0.2, 40, 20, 0.2, kRigidBlock, kRigidBlockRegion);
  text.replace(text.find("patch_cells: [10, 10]"), 21, "patch_cells: [5, 5]");
  const Scene scene = sceneFromYaml(text);
  const Grid<2> grid(scene.domain);
  const auto comm = world();
  const RunState<2> run = buildRunState(scene, grid, partitionPatches(grid, comm->getSize()), comm);
  const Division division = divisionByOpenCells(run, 0.02);
  if (comm->getRank() == 0)
    std::printf("%d rank(s): %lld closed cells; imbalance by cells %.4f, by open cells %.4f\n", comm->getSize(),
                division.closed_cells, division.imbalance_before, division.imbalance_after);
  EXPECT_EQ(division.closed_cells, 200);
  if (comm->getSize() == 1) {
    EXPECT_EQ(division.decomposition.patch_owner, run.layout->decomposition().patch_owner);
    return;
  }
  EXPECT_LE(division.imbalance_after, division.imbalance_before);
  if (comm->getSize() != 2) return;
  EXPECT_NEAR(division.imbalance_before, 1.0 / 7.0, 1e-12);
  EXPECT_LE(division.imbalance_after, 0.03);
}

// (e) Exchange: a disk moving through water without gravity, with K = 1e15 between the disk and the
// water, in a closed box with free-slip walls. The water slows the disk; the momentum the disk loses
// is what the water gains plus the impulse of the walls' pressure (the only external force: the
// implicit pressure reaches the walls at once), to round-off: the exchange, the pressure force on
// each material and its way back to the particles, and the advection conserve momentum. The walls'
// impulse is summed from the pressure of each step's momentum phase on the boundary cells.
// extra_mpm: an `mpm` section for the scene, or empty. Returns (total change - wall impulse) / the
// disk's initial momentum, and the most particle steps taken in one step.
std::pair<double, int> exchangeMomentumBalance(const std::string& extra_mpm)
{
  const char* disk = R"(    disk:
      kind: solid
      density: 2000.0
      particles_per_cell: 2
      model: {type: linear_elastic, youngs_modulus: 1.0e7, poisson_ratio: 0.3}
)";
  const std::string regions = "    d: {material: disk, shape: polygon, velocity: [0.5, 0.0], vertices: " +
                              diskVertices(0.5, 0.5, 0.1) + "}";
  const std::string extra = R"(  boundary_conditions:
    x-: {velocity: free_slip}
    x+: {velocity: free_slip}
    y-: {velocity: free_slip}
    y+: {velocity: free_slip}
  ice: {exchange_coefficient: 1.0e15})" + extra_mpm;
  // Inviscid: the viscous force θ_m μ_m ∇²u of each material is not a divergence where θ varies (at
  // the disk's edge it moves ~1e-6 of the disk's momentum in these 100 steps); the rest is exact.
  std::string text = tankScene(1.0, 1.0, 40, 40, 1.0, disk, regions, extra, 0.0);
  text.replace(text.find("viscosity: 1.0e-3"), 17, "viscosity: 0.0");
  CoupledRun<2> run(sceneFromYaml(text), world());
  const double h = 1.0 / 40;
  const int water = 1;  // the solids come first in the scene
  const auto total = [&] { return run.fluidMomentum(water, 0) + run.particles().momentum()[0]; };
  const double disk0 = run.particles().momentum()[0], start = total();
  double impulse = 0;
  int particle_steps = 1;
  const auto boundary = run.layout->cellIndex();
  for (int k = 0; k < 100; ++k) {
    run.step(1.0);
    particle_steps = std::max(particle_steps, run.last.particle_steps);
    // Wall pressure on the x- wall pushes +x, on the x+ wall -x (per metre of depth: p h per cell).
    const auto p = run.state.pressure.view();
    double local = 0;
    for (LocalOrdinal c = 0; c < run.state.pressure.ownedCount(); ++c) {
      if (boundary(c, 0) == 0) local += p(c, 0) * h;
      if (boundary(c, 0) == 39) local -= p(c, 0) * h;
    }
    impulse += run.dt_previous * globalSum(*world(), local);
  }
  // dt_previous is the step's own Δt here: no step was shortened (the end time is far).
  const double disk1 = run.particles().momentum()[0], end = total();
  if (world()->getRank() == 0)
    std::printf("disk momentum %.6f -> %.6f kg m/s per m; total change %.3e, wall impulse %.3e\n", disk0, disk1,
                end - start, impulse);
  EXPECT_LT(disk1, 0.99 * disk0);  // slowed by the water (added mass alone takes a third of it)
  return {(end - start - impulse) / std::abs(disk0), particle_steps};
}

TEST(CoupledStep, ExchangeConservesMomentum)
{
  const auto [imbalance, particle_steps] = exchangeMomentumBalance("");
  EXPECT_EQ(particle_steps, 1);
  EXPECT_NEAR(imbalance, 0.0, 1e-10);
}

// The same with up to four particle steps in each step of the fluids (mpm.substeps: 4).
TEST(CoupledStep, ParticleStepsInsideAFluidStepConserveMomentum)
{
  const auto [imbalance, particle_steps] = exchangeMomentumBalance("\n  mpm: {substeps: 4}");
  if (world()->getRank() == 0) std::printf("momentum imbalance %.3e of the disk's, up to %d particle steps per step\n", imbalance, particle_steps);
  EXPECT_GE(particle_steps, 2);
  EXPECT_NEAR(imbalance, 0.0, 1e-10);
}

// `ice.solid_exchange_coefficient` is the K between a solid and a fluid, apart from the fluids' own
// `exchange_coefficient`. In the added-mass disk's tank of water alone the only pair is the disk's
// with the water, so the key alone at 0 (the fluids' K left at its default, 1e15) must step exactly
// as `exchange_coefficient: 0` does, bit for bit (the face and the cell exchange, and the viscous
// limit, take it); left out, it follows `exchange_coefficient`, and the default K = 1e15 holds the
// water of the disk's boundary cells to it, which changes the disk's velocity at the first step.
TEST(CoupledStep, ExchangeWithSolidsHasItsOwnCoefficient)
{
  const auto diskVelocityAfter = [](const std::string& exchange, int steps) {
    const std::string none = "  ice: {exchange_coefficient: 0.0}";  // addedMassDiskScene's
    std::string text = addedMassDiskScene(500.0, 10);
    text.replace(text.find(none), none.size(), "  ice: " + exchange);
    CoupledRun<2> run(sceneFromYaml(text), world());
    for (int k = 0; k < steps; ++k) run.step(1.0);
    return run.meanParticleVelocity(0, 1);
  };
  const int steps = 20;
  const double fluids_and_solids_zero = diskVelocityAfter("{exchange_coefficient: 0.0}", steps);
  const double solids_zero = diskVelocityAfter("{solid_exchange_coefficient: 0.0}", steps);
  const double follows = diskVelocityAfter("{}", steps);
  if (world()->getRank() == 0)
    std::printf("disk velocity after %d steps: K = 0 %.17g, solid K = 0 %.17g, default %.17g\n", steps,
                fluids_and_solids_zero, solids_zero, follows);
  EXPECT_EQ(solids_zero, fluids_and_solids_zero);
  // The boundary ring's water (~h/2 around the disk, a fifth of the disk's mass at 10 cells per
  // diameter) slows it by far more than round-off.
  EXPECT_GT(std::abs(follows - fluids_and_solids_zero), 1e-3 * std::abs(fluids_and_solids_zero));
}

// No silent failures: a cell whose materials admit no common pressure (here air at a temperature
// below zero, whose ideal-gas density has no positive root, next to water) stops the step with the
// cell named, as a failed step that the driver can retry (StepFailure), not a pressure left
// unconverged.
TEST(CoupledStep, FailedEquilibrationNamesTheCell)
{
  CoupledRun<2> run(sceneFromYaml(tankScene(0.2, 0.2, 20, 20, 0.15, withDensity(kElasticBlock, 1500.0),
                                            "    b: {material: block, shape: box, lower: [0.07, 0.08], upper: [0.13, 0.12]}")),
                    world());
  run.step(1.0);  // a healthy first step
  const int air = 2;  // block, water, air
  const auto ijk = run.layout->cellIndex();
  auto T = run.state.temperature.view();
  for (LocalOrdinal c = 0; c < run.state.temperature.ownedCount(); ++c)
    if (ijk(c, 0) == 4 && ijk(c, 1) == 17) T(c, air) = -100.0;  // in the air above the water (y = 0.175 m)
  bool named = false, failed = false;
  try {
    run.step(1.0);
  } catch (const StepFailure& failure) {
    failed = true;
    const std::string message = failure.what();
    named = message.find("equilibration pressure did not converge in 1 cell(s), the first at cell (4, 17)") !=
            std::string::npos;
    if (!named && world()->getRank() == 0) std::printf("message: %s\n", message.c_str());
  }
  EXPECT_TRUE(failed);
  EXPECT_TRUE(named);
}

// (f) The same coupled scene (a dense block sinking through water under air) on rank 0 alone and on
// all ranks: particle positions (matched by id) and the water's volume fraction agree to 1e-8 of their
// scales (the tank's width; a full cell). Partitions change only the order of sums in the linear
// solver and the reductions; with the solver's tolerance at 1e-14 the runs differ by round-off that
// the 200 steps grow to well below that. The outer iterations go to 1e-12: their test weighs a cell
// of the block (softer than water) down, so where a step stops one outer iteration earlier on one
// partition than on the other, the block's cells could differ by more than 1e-8 of a cell while
// the pressure differs by a pascal (measured with the default 1e-8 and particle volumes: 1.4e-8).
// extra: more scene options (the block sinks through the water; 200 steps).
void expectSameAnswerOnOneAndSeveralRanks(const std::string& extra)
{
  const Scene scene = sceneFromYaml(tankScene(0.2, 0.2, 20, 20, 0.15, withDensity(kElasticBlock, 1500.0),
                                              "    b: {material: block, shape: box, lower: [0.07, 0.08], upper: [0.13, 0.12]}",
                                              "  ice: {solver_tolerance: 1.0e-14, outer_tolerance: 1.0e-12}" + extra));
  const auto comm = world();
  struct Result {
    std::map<long long, std::array<double, 3>> positions;
    std::vector<double> water;
  };
  auto runOn = [&](const Teuchos::RCP<const Teuchos::Comm<int>>& c) {
    CoupledRun<2> run(scene, c);
    for (int k = 0; k < 200; ++k) run.step(1.0);
    Result r;
    // Every rank's particles to rank 0 of c.
    auto local = run.positions();
    std::vector<double> mine;
    for (const auto& [id, x] : local) mine.insert(mine.end(), {double(id), x[0], x[1]});
    int count = int(mine.size()), total = 0;
    std::vector<int> counts(c->getSize()), offsets(c->getSize());
    const MPI_Comm raw = rawMpiComm(c);
    MPI_Gather(&count, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, raw);
    for (int q = 0; q < c->getSize(); ++q) offsets[q] = total, total += counts[q];
    std::vector<double> all(std::max(1, total));
    MPI_Gatherv(mine.data(), count, MPI_DOUBLE, all.data(), counts.data(), offsets.data(), MPI_DOUBLE, 0, raw);
    for (int i = 0; i + 2 < total; i += 3) r.positions[(long long)all[i]] = {all[i + 1], all[i + 2], 0.0};
    r.water = gatherField(run.state.volume_fraction);
    return r;
  };
  const auto alone = comm->split(comm->getRank() == 0 ? 0 : 1, comm->getRank());
  Result serial;
  if (comm->getRank() == 0) serial = runOn(alone);
  const Result parallel = runOn(comm);
  if (comm->getRank() != 0) return;
  ASSERT_EQ(serial.positions.size(), parallel.positions.size());
  double worst = 0;
  for (const auto& [id, x] : serial.positions)
    worst = std::max(worst, std::hypot(x[0] - parallel.positions.at(id)[0], x[1] - parallel.positions.at(id)[1]));
  double worst_fraction = 0;
  for (std::size_t i = 0; i < serial.water.size(); ++i)
    worst_fraction = std::max(worst_fraction, std::abs(serial.water[i] - parallel.water[i]));
  std::printf("%d rank(s): largest particle position difference %.3e m, volume fraction %.3e\n", comm->getSize(), worst,
              worst_fraction);
  EXPECT_LE(worst, 1e-8 * 0.2);
  EXPECT_LE(worst_fraction, 1e-8);
}

TEST(CoupledStep, SameAnswerOnOneAndSeveralRanks) { expectSameAnswerOnOneAndSeveralRanks(""); }

// The solids' volume from their particles moved on a copy (mpm.solid_volume: particles): the trial
// moves' boxes are summed over ranks like the step's own.
TEST(CoupledStep, SameAnswerOnOneAndSeveralRanksWithParticleVolumes)
{
  expectSameAnswerOnOneAndSeveralRanks("\n  mpm: {solid_volume: particles}");
}

}  // namespace
}  // namespace cfdmpm::test
