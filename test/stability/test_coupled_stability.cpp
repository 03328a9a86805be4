// Stability case (b) (doc/stability.md, issue 14): the added-mass instability of a partitioned
// fluid-solid coupling. A circular disk released from rest in still water accelerates at
// a = g (ρs − ρw) / (ρs + ρw): potential flow gives a circular cylinder an added mass equal to the
// water it displaces, m_a = ρw V. A staggered coupling (mpm.coupling: staggered) fixes the disk's
// motion over a step before the pressure and lets the pressure act on it a step later; the
// pressure's reaction to the disk's acceleration (−m_a a) then comes a step late, so each step's
// acceleration error is the last one's times −m_a / m_s = −ρw / ρs, which grows for a disk lighter
// than the water (Causin, Gerbeau & Nobile 2005, for the same ratio in a pipe). The monolithic
// coupling (the default) has the disk's response to the pressure inside the pressure equation.
#include "stability_support.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace cfdmpm::test {
namespace {

Teuchos::RCP<const Teuchos::Comm<int>> world() { return Teuchos::DefaultComm<int>::getComm(); }

bool rank0() { return world()->getRank() == 0; }

struct DiskOutcome {
  double ratio = 0;        // fitted acceleration / potential flow's
  double oscillation = 0;  // RMS of the mean velocity about the fitted line / (|a| × 20 ms)
  double growth = 0;       // that RMS over the window's second half / over its first half
  std::string failure;     // what stopped the run, if it stopped
};

// The disk of test_coupled's added-mass case (addedMassDiskScene: 20 cells per diameter, no
// exchange) with the given coupling, released from rest. The acceleration is the least-squares slope
// of the disk's mean vertical velocity over [5, 20] ms.
DiskOutcome runDisk(double density, const std::string& coupling)
{
  DiskOutcome out;
  const double expected = -9.81 * (density - 1000.0) / (density + 1000.0);
  std::vector<double> times, speeds;
  try {
    CoupledRun<2> run(sceneFromYaml(addedMassDiskScene(density, 20, "{coupling: " + coupling + "}")), world());
    run.sampleMeanVerticalVelocity(0, 0.005, 0.02, times, speeds);
  } catch (const std::exception& e) {
    out.failure = e.what();
    return out;
  }
  const std::size_t n = times.size();
  const LineFit fit = fitLine(times, speeds);
  double first = 0, second = 0;
  for (std::size_t k = 0; k < n; ++k) (k < n / 2 ? first : second) += std::pow(speeds[k] - (fit.offset + fit.slope * times[k]), 2);
  out.ratio = fit.slope / expected;
  out.oscillation = std::sqrt((first + second) / n) / (std::abs(expected) * 0.02);
  out.growth = std::sqrt(second / (n - n / 2)) / std::sqrt(first / (n / 2));
  return out;
}

void report(double density, const std::string& coupling, const DiskOutcome& d)
{
  if (rank0())
    std::printf("disk %6.0f kg/m^3 (ρs/ρw %.3g), %-10s: a / potential flow %.4f, oscillation %.3g, growth %.3g%s%s\n",
                density, density / 1000.0, coupling.c_str(), d.ratio, d.oscillation, d.growth,
                d.failure.empty() ? "" : ", stopped: ", d.failure.c_str());
}

// A run that stops says what failed: a cell or a particle (issue 14, point 3).
bool namesCellOrParticle(const std::string& failure)
{
  return failure.find("cell (") != std::string::npos || failure.find("particle") != std::string::npos;
}

// A run holds when it does not stop, the velocity's departure from uniform acceleration does not
// grow over the window, and it stays below the speed the disk reaches: the staggered step
// multiplies an acceleration error by ρw / ρs per step, so below ρs = ρw it grows by orders of
// magnitude within the window's ~1000 steps, while a stable run's departure (the start-up's
// pressure waves, the disk's elastic ringing) stays or decays, at 1e-3 .. 2e-2 of that speed.
// Bounds: growth ≤ 2 between the window's halves; oscillation ≤ 1 (an instability that has grown
// to its full size within the first half no longer grows: the staggered 100 kg/m³ disk at c20a984
// departed by 22.7 times its speed with a growth of 0.97).
constexpr double kGrowthBound = 2.0;
constexpr double kOscillationBound = 1.0;

TEST(StabilityAddedMass, LightDiskMonolithicHoldsStaggeredFails)
{
  std::vector<SweepRow> rows;
  double staggered_fails_below = 0;
  for (const double density : {2000.0, 500.0, 100.0, 10.0}) {
    const double ratio = density / 1000.0;
    for (const std::string coupling : {"monolithic", "staggered"}) {
      const DiskOutcome d = runDisk(density, coupling);
      const bool holds = d.failure.empty() && d.growth <= kGrowthBound && d.oscillation <= kOscillationBound;
      report(density, coupling, d);
      const double error = d.failure.empty() ? std::abs(d.ratio - 1.0) + d.oscillation : 10.0;
      rows.push_back({ratio, error, coupling == "monolithic" ? "monolithic (cfdmpm)" : "staggered",
                      holds ? "ok" : "failed"});
      if (coupling == "monolithic") {
        EXPECT_TRUE(holds) << density << ": growth " << d.growth << ", oscillation " << d.oscillation << " " << d.failure;
        // The 10 % on the acceleration holds for the disks heavier than a fifth of the
        // water (test_coupled's bound); the lighter disks' is reported (doc/stability.md, case b):
        // at 20 cells per diameter the 100 kg/m³ disk slows as its top crosses a face and the
        // 10 kg/m³ one grows an elastic mode inside (m/s), which the fitted acceleration does not
        // bound. The 10 kg/m³ disk at 10 cells per diameter is test_coupled's LightBody case (10 %).
        if (ratio >= 0.5) {
          EXPECT_NEAR(d.ratio, 1.0, 0.10) << density;
        }
      } else {
        if (!holds && staggered_fails_below == 0) staggered_fails_below = ratio;
        // The staggered step holds for the heavy disk and fails for every disk lighter than the water.
        if (ratio > 1.0) {
          EXPECT_TRUE(holds) << density << ": growth " << d.growth << ", oscillation " << d.oscillation << " " << d.failure;
        } else {
          EXPECT_FALSE(holds) << density;
        }
        if (!d.failure.empty()) {
          EXPECT_TRUE(namesCellOrParticle(d.failure)) << "a failure that names nothing: " << d.failure;
        }
      }
    }
  }
  std::vector<std::pair<std::string, double>> thresholds;
  if (staggered_fails_below > 0) thresholds.push_back({"staggered fails", staggered_fails_below});
  writeSweep(*world(), "stability_b_added_mass", "density ratio solid / water",
             "|a / potential flow - 1| + velocity oscillation (failed: 10)", rows, thresholds);
}

}  // namespace
}  // namespace cfdmpm::test
