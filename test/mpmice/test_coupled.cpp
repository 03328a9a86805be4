// The coupled step on cases with known answers (issue: the coupled MPMICE step).
#include "coupled_support.hpp"

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
// at rest. After a start-up of 0.1 s (the first steps settle the discrete hydrostatic balance of a
// compressible liquid around a block of uniform density; the block's peak is 5e-7 m/s, g dt_initial
// / 200, and decays by a factor of 10 every ~0.03 s), the block's particles may move no faster than
// ten times that noise, and over the whole run no farther than the noise speed times the duration.
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
  double moved = 0;
  for (const auto& [id, x] : run.positions()) moved = std::max(moved, std::hypot(x[0] - start.at(id)[0], x[1] - start.at(id)[1]));
  moved = globalMax(*world(), moved);
  if (world()->getRank() == 0)
    std::printf("still-tank noise %.3e m/s; block: fastest particle after start-up %.3e m/s (peak %.3e), "
                "largest displacement %.3e m in %lld steps\n",
                noise, fastest, peak, moved, run.steps);
  EXPECT_LE(fastest, 10 * noise);
  EXPECT_LE(moved, noise * end);
}

}  // namespace
}  // namespace cfdmpm::test
