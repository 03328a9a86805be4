#pragma once
// Helpers for tests of the coupled step on small scenes written inline as YAML.
#include "../ice/ice_scene_support.hpp"
#include "mpmice/mpmice_step.hpp"

#include <array>
#include <cmath>
#include <map>
#include <vector>

namespace cfdmpm::test {

/// The tanks' fluids as YAML materials: water (compressible, K = 2.15e9 Pa) and air.
inline const char* kTankWater = R"(    water:
      kind: fluid
      equation_of_state: {type: linear_water, bulk_modulus: 2.15e9, reference_density: 1000.0, reference_pressure: 101325.0, reference_temperature: 293.15, thermal_expansion: 0.0}
      viscosity: 1.0e-3
      specific_heat: 4180.0
)";
inline const char* kTankAir = R"(    air:
      kind: fluid
      equation_of_state: {type: ideal_gas, gas_constant: 287.0, gamma: 1.4}
      viscosity: 1.8e-5
)";

/// A tank of water (and air above when `water_top` < the tank's top) on nx x ny cells with
/// `solids` (YAML of the solid materials) and `regions` (YAML of their regions), closed by no-slip
/// walls. `extra` is appended inside `cfdmpm:` (e.g. an `mpm:` or `ice:` section).
inline std::string tankScene(double width, double height, long long nx, long long ny, double water_top,
                             const std::string& solids, const std::string& regions, const std::string& extra = "",
                             double gravity = -9.81)
{
  const bool air = water_top < height;
  std::string text = R"(
cfdmpm:
  domain: {dimension: 2, lower: [0.0, 0.0], upper: [)" + std::to_string(width) + ", " + std::to_string(height) +
                     "], cells: [" + std::to_string(nx) + ", " + std::to_string(ny) + "], patch_cells: [10, 10], gravity: [0.0, " +
                     std::to_string(gravity) + R"(]}
  materials:
)" + solids + "\n" + kTankWater;
  if (air) text += kTankAir;
  text += std::string("  initial_state: {background_material: ") + (air ? "air" : "water") +
          ", temperature: 293.15, pressure: 101325.0}\n  regions:\n";
  if (air)
    text += "    water_level: {material: water, shape: half_plane, point: [0.0, " + std::to_string(water_top) +
            "], normal: [0.0, 1.0]}\n";
  text += regions + "\n  time: {end_time: 1.0, cfl: 0.25, dt_initial: 1.0e-5}\n  output: {directory: unused, interval: 0.0}\n" +
          extra + "\n";
  return text;
}

/// A polygon approximating a disk (n vertices), as a YAML flow sequence.
inline std::string diskVertices(double cx, double cy, double radius, int n = 64)
{
  std::string out = "[";
  for (int k = 0; k < n; ++k) {
    const double a = 2 * M_PI * k / n;
    out += (k ? ", [" : "[") + std::to_string(cx + radius * std::cos(a)) + ", " + std::to_string(cy + radius * std::sin(a)) + "]";
  }
  return out + "]";
}

/// The added-mass disk (test_coupled's case (c), stability case (b)): an elastic disk 0.05 m across
/// (E = 1e6 Pa) of `density`, released from rest in the middle of a closed tank of water ten
/// diameters across and deep (the walls add ~1 %: the image of a dipole at five diameters). No
/// exchange: potential flow slips along the disk (K = 1e15 would hold the water of its boundary
/// cells to it, a ring of ~h/2 that adds its mass). `mpm` is the scene's `mpm` section, if any
/// (e.g. "{coupling: staggered}").
inline std::string addedMassDiskScene(double density, int cells_per_diameter, const std::string& mpm = "")
{
  const double diameter = 0.05, tank = 10 * diameter;
  const long long cells = 10 * cells_per_diameter;
  const std::string disk = "    disk:\n      kind: solid\n      density: " + std::to_string(density) +
                           "\n      particles_per_cell: 2\n"
                           "      model: {type: linear_elastic, youngs_modulus: 1.0e6, poisson_ratio: 0.3}\n";
  const std::string regions = "    d: {material: disk, shape: polygon, vertices: " +
                              diskVertices(tank / 2, tank / 2, diameter / 2, 96) + "}";
  std::string extra = "  ice: {exchange_coefficient: 0.0}";
  if (!mpm.empty()) extra += "\n  mpm: " + mpm;
  std::string text = tankScene(tank, tank, cells, cells, tank, disk, regions, extra);
  text.replace(text.find("patch_cells: [10, 10]"), 21, "patch_cells: [25, 25]");
  return text;
}

/// Least-squares line v = offset + slope t through the samples.
struct LineFit {
  double slope = 0, offset = 0;
};
inline LineFit fitLine(const std::vector<double>& t, const std::vector<double>& v)
{
  const double n = double(t.size());
  double st = 0, sv = 0, stt = 0, stv = 0;
  for (std::size_t k = 0; k < t.size(); ++k) st += t[k], sv += v[k], stt += t[k] * t[k], stv += t[k] * v[k];
  LineFit fit;
  fit.slope = (n * stv - st * sv) / (n * stt - st * st);
  fit.offset = (sv - fit.slope * st) / n;
  return fit;
}

/// The coupled step on a scene: layout, state, stepper, and a clock.
template <int Dim>
struct CoupledRun {
  CoupledRun(const Scene& s, const Teuchos::RCP<const Teuchos::Comm<int>>& comm)
      : CoupledRun(s, comm, partitionPatches(Grid<Dim>(s.domain), comm->getSize()))
  {
  }
  /// On a given division of the grid's patches.
  CoupledRun(const Scene& s, const Teuchos::RCP<const Teuchos::Comm<int>>& comm, const Decomposition& division)
      : scene(s),
        layout(std::make_shared<const Layout<Dim>>(Grid<Dim>(s.domain), division, s.domain.ghost_width, comm)),
        state(layout, int(s.materials.size())),
        stepper(((void)setInitialState(scene, densityFunctions(scene), state), s), layout, state)
  {
  }

  /// One step with the stepper's own Δt (dt_initial first), at most up to `until`.
  void step(double until)
  {
    double dt = steps == 0 ? std::min(scene.time.dt_initial, stepper.stableTimeStep(state, 0).dt)
                           : stepper.stableTimeStep(state, dt_previous).dt;
    dt_previous = dt;
    // As the program does: two equal steps to the end rather than a full one and a sliver.
    if (time + 2 * dt > until) dt = time + dt > until ? until - time : 0.5 * (until - time);
    last = stepper.step(state, dt);
    time += dt;
    ++steps;
  }
  template <class Observe>
  void runUntil(double end_time, Observe&& observe)
  {
    while (time < end_time * (1 - 1e-12)) {
      step(end_time);
      observe();
    }
  }
  void runUntil(double end_time)
  {
    runUntil(end_time, [] {});
  }

  mpm::MpmSolver<Dim>& particles() { return *stepper.particles(); }

  /// Mass-weighted mean velocity component d of the particles of MPM material a (collective).
  double meanParticleVelocity(int a, int d)
  {
    auto& p = particles().particles();
    auto v = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), p.velocity);
    auto m = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), p.mass);
    auto mat = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), p.material);
    double sums[2] = {0, 0}, total[2] = {0, 0};
    for (int i = 0; i < p.count; ++i)
      if (mat(i) == a) sums[0] += m(i) * v(i, d), sums[1] += m(i);
    Teuchos::reduceAll(*layout->comm(), Teuchos::REDUCE_SUM, 2, sums, total);
    return total[0] / total[1];
  }

  /// The mean vertical velocity of MPM material a after every step from `from` to `to` (s), with the
  /// times (a step that fails throws, as the stepper does).
  void sampleMeanVerticalVelocity(int a, double from, double to, std::vector<double>& times, std::vector<double>& speeds)
  {
    runUntil(to, [&] {
      if (time < from) return;
      times.push_back(time);
      speeds.push_back(meanParticleVelocity(a, Dim - 1));
    });
  }

  /// Largest particle speed of MPM material a (collective).
  double maxParticleSpeed(int a)
  {
    auto& p = particles().particles();
    auto v = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), p.velocity);
    auto mat = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), p.material);
    double fastest = 0;
    for (int i = 0; i < p.count; ++i)
      if (mat(i) == a) {
        double s2 = 0;
        for (int d = 0; d < Dim; ++d) s2 += v(i, d) * v(i, d);
        fastest = std::max(fastest, std::sqrt(s2));
      }
    return globalMax(*layout->comm(), fastest);
  }

  /// Particle positions by id (host copies of this rank's particles).
  std::map<long long, std::array<double, 3>> positions()
  {
    auto& p = particles().particles();
    auto x = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), p.position);
    auto id = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), p.id);
    std::map<long long, std::array<double, 3>> out;
    for (int i = 0; i < p.count; ++i) {
      std::array<double, 3> xi{0, 0, 0};
      for (int d = 0; d < Dim; ++d) xi[d] = x(i, d);
      out[id(i)] = xi;
    }
    return out;
  }

  /// Largest distance of any particle from its position in `start` (from positions(); collective).
  double largestDisplacement(const std::map<long long, std::array<double, 3>>& start)
  {
    double moved = 0;
    for (const auto& [id, x] : positions()) {
      const auto& x0 = start.at(id);
      moved = std::max(moved, std::hypot(x[0] - x0[0], x[1] - x0[1], x[2] - x0[2]));
    }
    return globalMax(*layout->comm(), moved);
  }

  /// Largest speed of fluid material m over owned cells where it fills more than `share` (collective).
  double maxFluidSpeed(int m, double share = 1e-3)
  {
    const auto u = state.velocity.view();
    const auto theta = state.volume_fraction.view();
    double fastest = 0;
    for (LocalOrdinal c = 0; c < state.velocity.ownedCount(); ++c) {
      if (!(theta(c, m) > share)) continue;
      double s2 = 0;
      for (int d = 0; d < Dim; ++d) s2 += u(c, m * Dim + d) * u(c, m * Dim + d);
      fastest = std::max(fastest, std::sqrt(s2));
    }
    return globalMax(*layout->comm(), fastest);
  }

  /// Kinetic energy (per metre in 2-D) of fluid material m over owned cells (collective).
  double fluidKineticEnergy(int m)
  {
    const auto rho = state.density.view();
    const auto u = state.velocity.view();
    double sum = 0;
    for (LocalOrdinal c = 0; c < state.density.ownedCount(); ++c)
      for (int d = 0; d < Dim; ++d) sum += 0.5 * rho(c, m) * u(c, m * Dim + d) * u(c, m * Dim + d);
    return globalSum(*layout->comm(), sum * layout->grid().cellVolume());
  }

  /// Total mass (per metre in 2-D) and momentum component d of fluid material m (collective).
  double fluidMass(int m)
  {
    const auto rho = state.density.view();
    double sum = 0;
    for (LocalOrdinal c = 0; c < state.density.ownedCount(); ++c) sum += rho(c, m);
    return globalSum(*layout->comm(), sum * layout->grid().cellVolume());
  }
  double fluidMomentum(int m, int d)
  {
    const auto rho = state.density.view();
    const auto u = state.velocity.view();
    double sum = 0;
    for (LocalOrdinal c = 0; c < state.density.ownedCount(); ++c) sum += rho(c, m) * u(c, m * Dim + d);
    return globalSum(*layout->comm(), sum * layout->grid().cellVolume());
  }

  Scene scene;
  std::shared_ptr<const Layout<Dim>> layout;
  CellState<Dim> state;
  MpmIceStep<Dim> stepper;
  CoupledStepReport last;
  double time = 0, dt_previous = 0;
  long long steps = 0;
};

}  // namespace cfdmpm::test
