// Two elastic disks collide head-on (Sulsky, Zhou & Schreyer 1995, "Application of a
// particle-in-cell method to solid mechanics", Comput. Phys. Commun. 87): the grid's single velocity
// field makes them bounce without a contact algorithm. Total energy, kinetic plus elastic, must stay
// within a bound of its initial value through the collision.
#include "mpm/mpm_solver.hpp"
#include "mpm_scene_builder.hpp"

#include <gtest/gtest.h>

#include <cmath>

using namespace cfdmpm;

namespace {

constexpr double kYoung = 1000.0, kPoisson = 0.3, kDensity = 1000.0, kSpeed = 0.1, kRadius = 0.2;

void addDisk(Scene& scene, const std::string& material, double cx, double cy, double vx)
{
  RegionSpec disk;
  disk.name = "disk_" + std::to_string(scene.regions.size());
  disk.material = material;
  disk.shape = "polygon";
  for (int k = 0; k < 128; ++k) {
    const double a = 2 * M_PI * k / 128;
    disk.vertices.push_back({cx + kRadius * std::cos(a), cy + kRadius * std::sin(a)});
  }
  disk.velocity = {vx, vx, 0};
  disk.temperature = 293.15;
  scene.regions.push_back(disk);
}

// Elastic strain energy of a linear elastic particle from its stress (plane strain, σ_zz included):
// U = V / (2E) [(1 + ν) σ:σ − ν (tr σ)²].
double strainEnergy(const mpm::ParticleOutput& out)
{
  double energy = 0;
  for (std::size_t p = 0; p < out.count; ++p) {
    const double* s = &out.stress[9 * p];
    double ss = 0;
    for (int k = 0; k < 9; ++k) ss += s[k] * s[k];
    const double tr = s[0] + s[4] + s[8];
    energy += out.volume[p] / (2 * kYoung) * ((1 + kPoisson) * ss - kPoisson * tr * tr);
  }
  return energy;
}

}  // namespace

namespace {

struct Collision {
  double lowest, highest, least_kinetic, kinetic_end;  // fractions of the initial (kinetic) energy
};

Collision collide(long long cells)
{
  // Unit square, cells x cells, 2 x 2 particles per cell, disks at (0.2, 0.2) and (0.8, 0.8)
  // approaching along the diagonal at 0.1 m/s each component; no gravity, pure FLIP (no PIC
  // damping) and no contact algorithm, as in the reference.
  Scene scene = mpm::scenes::dryScene<2>({0, 0, 0}, {1, 1, 0}, {cells, cells, 1}, {10, 10, 1}, {0, 0, 0});
  mpm::scenes::addLinearElastic(scene, "rubber", kDensity, kYoung, kPoisson, 2);
  addDisk(scene, "rubber", 0.2, 0.2, kSpeed);
  addDisk(scene, "rubber", 0.8, 0.8, -kSpeed);
  const auto comm = Tpetra::getDefaultComm();
  mpm::MpmOptions options;
  options.flip_fraction = 1.0;
  options.contact = false;
  options.cfl = 0.2;
  mpm::MpmSolver<2> solver(scene, mpm::scenes::layoutFor<2>(scene, comm), options);

  auto totalEnergy = [&] {
    double local = strainEnergy(solver.output()), elastic = 0;
    Teuchos::reduceAll(*comm, Teuchos::REDUCE_SUM, local, Teuchos::outArg(elastic));
    return solver.kineticEnergy() + elastic;
  };
  const double initial = totalEnergy();
  const double kinetic0 = solver.kineticEnergy();
  double lowest = initial, highest = initial, least_kinetic = kinetic0, time = 0;
  const double dt = solver.stableTimeStep().dt;
  while (time < 3.0) {  // they touch at ~1.2 s, part again by ~2.5 s
    solver.step(dt);
    time += dt;
    const double e = totalEnergy();
    lowest = std::min(lowest, e), highest = std::max(highest, e);
    least_kinetic = std::min(least_kinetic, solver.kineticEnergy());
  }
  const double kinetic_end = solver.kineticEnergy();
  if (comm->getRank() == 0)
    std::cout << cells << " x " << cells << " cells: initial energy " << initial << " J/m; range ["
              << lowest / initial << ", " << highest / initial << "] of it; kinetic energy at its lowest "
              << least_kinetic / kinetic0 << ", at the end " << kinetic_end / kinetic0 << " of the initial\n";
  return {lowest / initial, highest / initial, least_kinetic / kinetic0, kinetic_end / kinetic0};
}

}  // namespace

TEST(MpmDisks, ElasticCollisionConservesEnergy)
{
  const Collision coarse = collide(20), fine = collide(40);
  for (const Collision& c : {coarse, fine}) {
    // The collision happened: most kinetic energy went into strain and came back.
    EXPECT_LT(c.least_kinetic, 0.5);
    EXPECT_GT(c.kinetic_end, 0.5);
    // No energy is created beyond the O(Δt) splitting error (~0.1 % at CFL 0.2).
    EXPECT_LE(c.highest, 1.01);
  }
  // The bound: Sulsky et al. report a total energy that stays within a few per cent through this
  // collision; on the finer grid (disks 16 cells across) it must stay within 5 %. Measured today:
  // 8.5 % lost at 20 x 20 and 6.5 % at 40 x 40 (the loss falls slower than first order), so this
  // test is in the "validation" label until the dissipation is understood.
  EXPECT_GT(fine.lowest, 0.95);
}
