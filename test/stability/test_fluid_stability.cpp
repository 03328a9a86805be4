// Stability cases of the fluid step (doc/stability.md, issue 14): (a) explicit against implicit
// pressure over acoustic Courant numbers 0.5 .. 100, (c) stiff drag (exchange coefficient 1e3 ..
// 1e17), (d) large density ratios, (e) vanishing materials. Every case runs the application's step
// (MpmIceStep: the fluid phases and the check that every value is finite), sweeps its parameter,
// asserts the numbers and writes its sweep as a CSV for utilities/stability_map.py.
#include "stability_support.hpp"
#include "ice/exchange.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cfloat>
#include <cmath>
#include <limits>
#include <vector>

namespace cfdmpm::test {
namespace {

Teuchos::RCP<const Teuchos::Comm<int>> world() { return Teuchos::DefaultComm<int>::getComm(); }

bool rank0() { return world()->getRank() == 0; }

// ------------------------------------------------------------------------------------------------
// (a) Pressure: explicit against implicit over the acoustic Courant number C = c Δt / h.
// ------------------------------------------------------------------------------------------------

constexpr double kBulkModulus = 2.15e9, kWaterDensity = 998.0, kCell = 0.005, kSlugSpeed = 0.1;

// Water at rest in a closed 1 m x 0.02 m channel (200 x 4 cells of 5 mm), no gravity, no viscosity,
// with a 0.1 m slug at 0.1 m/s in the middle: two acoustic pulses run out from it and reflect from
// the walls (the scene of test_ice_scenes' acoustic cases).
std::string acousticScene(const std::string& scheme)
{
  return R"(
cfdmpm:
  domain: {dimension: 2, lower: [0.0, 0.0], upper: [1.0, 0.02], cells: [200, 4], patch_cells: [25, 4], gravity: [0.0, 0.0]}
  materials:
    water:
      kind: fluid
      equation_of_state: {type: linear_water, bulk_modulus: 2.15e9, reference_density: 998.0, reference_pressure: 101325.0, reference_temperature: 293.15}
      viscosity: 0.0
      specific_heat: 4157.0
  initial_state: {background_material: water, temperature: 293.15, pressure: 101325.0, hydrostatic: false}
  regions:
    slug: {material: water, shape: box, lower: [0.45, 0.0], upper: [0.55, 0.02], velocity: [0.1, 0.0]}
)" + std::string(freeSlipBox()) +
         R"(  time: {end_time: 1.0}
  output: {directory: unused, interval: 1.0}
  ice: {pressure: )" + scheme + "}\n";
}

struct AcousticOutcome {
  bool failed = false;       // stopped by the step (StepFailure) or left the bound below
  double amplitude = 0;      // largest |u| over the run / the slug's speed
  double cross = 0;          // largest |u_y| over the run / the slug's speed (the 2-D modes)
  double mass_change = 0;    // relative
  int steps = 0;             // steps done
  std::string message;       // the step's failure message, if it stopped
};

// `steps` steps of Δt = C h / c. A run "fails" when the step stops (StepFailure: a value not finite,
// an outflux over a cell) or when a speed exceeds ten times the slug's: linear acoustics cannot
// raise the largest speed above the slug's (the pulses carry half of it each), so growth by ten is
// the scheme's instability, not physics. With `stop_at_bound` false the run goes on until the step
// itself stops (point 3 of the issue: a failure is named, never a silent NaN).
AcousticOutcome runAcoustic(const std::string& scheme, double courant, int steps, bool stop_at_bound = true)
{
  CoupledRun<2> run(sceneFromYaml(acousticScene(scheme)), world());
  const double c = std::sqrt(kBulkModulus / kWaterDensity);
  const double dt = courant * kCell / c;
  const double mass0 = run.fluidMass(0);
  AcousticOutcome out;
  for (int k = 0; k < steps; ++k) {
    try {
      run.stepper.step(run.state, dt);
    } catch (const StepFailure& failure) {
      out.failed = true;
      out.message = failure.what();
      break;
    }
    ++out.steps;
    out.amplitude = std::max(out.amplitude, run.maxFluidSpeed(0, 0.0) / kSlugSpeed);
    {
      const auto u = run.state.velocity.view();
      double largest = 0;
      for (LocalOrdinal c = 0; c < run.layout->ownedCells(); ++c) largest = std::max(largest, std::abs(u(c, 1)));
      out.cross = std::max(out.cross, globalMax(*world(), largest) / kSlugSpeed);
    }
    if (stop_at_bound && !(out.amplitude < 10.0)) {
      out.failed = true;
      out.message = "largest speed over ten times the slug's";
      break;
    }
  }
  out.mass_change = std::abs(run.fluidMass(0) / mass0 - 1);
  return out;
}

// The explicit scheme's limit, from a Fourier analysis of the step on this collocated grid (doc/
// stability.md, case a). In linear acoustics with the face velocity u_f = (u_L + u_R)/2 −
// Δt v (p_R − p_L)/h, the explicit pressure p' = p − ρc²Δt (div u_f) and the cell velocity from the
// mean face pressures, a mode e^{i(k·x)} has the amplification matrix (acoustic part) with
// determinant 1 − a and trace 2 − a − b², a = 4C² Σ_d sin²(k_d h/2), b² = C² Σ_d sin²(k_d h); it is
// stable while 4 − 2a − b² ≥ 0. The odd-even mode (k_d h = π) sets C ≤ 1/√2 in 1-D and C ≤ 1/2 in
// 2-D, where it grows by |1 − a| per step. In this channel the rows start identical and differ
// only by round-off (|u_y| ~ 1e-13 of the slug's speed), from which the 2-D modes grow.
constexpr int kAcousticSteps = 400;

TEST(StabilityPressure, ExplicitFailsAboveItsCourantLimitImplicitHoldsTo100)
{
  const double limit = 1.0 / std::sqrt(2.0);
  const std::vector<double> courants = {0.4, 0.5, 0.55, 0.6, 0.65, 0.7, 0.72, 0.75, 0.8, 1.0, 1.5, 2.0, 5.0, 10.0, 20.0, 50.0, 100.0};
  std::vector<SweepRow> rows;
  double last_bounded = 0, first_failed = 1e300;
  for (double C : courants) {
    const AcousticOutcome implicit = runAcoustic("implicit", C, kAcousticSteps);
    const AcousticOutcome explicit_ = runAcoustic("explicit", C, kAcousticSteps);
    if (rank0())
      std::printf("C = %6.2f: implicit max|u|/u0 %.5f mass %.1e; explicit %s after %d steps, max|u|/u0 %.4g "
                  "(|u_y| %.3g)%s%s\n", C, implicit.amplitude, implicit.mass_change,
                  explicit_.failed ? "FAILED" : "bounded", explicit_.steps, explicit_.amplitude, explicit_.cross, explicit_.message.empty() ? "" : ": ", explicit_.message.c_str());
    rows.push_back({C, implicit.amplitude, "implicit (cfdmpm)", implicit.failed ? "failed" : "ok"});
    rows.push_back({C, explicit_.amplitude, "explicit", explicit_.failed ? "failed" : "ok"});
    // Implicit: backward Euler in the acoustic terms only damps, so no speed exceeds the slug's
    // (plus 1 % for the limited second-order advection's overshoot at the slug's edges), at every C.
    EXPECT_FALSE(implicit.failed) << "C = " << C << ": " << implicit.message;
    EXPECT_LE(implicit.amplitude, 1.01) << "C = " << C;
    // Conservative fluxes: the mass changes by round-off only (800 cells x 1e-16).
    EXPECT_LT(implicit.mass_change, 1e-12) << "C = " << C;
    if (explicit_.failed)
      first_failed = std::min(first_failed, C);
    else
      last_bounded = std::max(last_bounded, C);
    // Below the 2-D Fourier limit (1/2, comment above) the explicit scheme is stable: bounded like
    // the implicit one.
    if (C <= 0.5) {
      EXPECT_FALSE(explicit_.failed) << "C = " << C;
      EXPECT_LE(explicit_.amplitude, 1.01) << "C = " << C;
    }
    // From C = 0.72 even the 1-D odd-even mode grows, by 4C² − 1 ≥ 1.07 per step: from round-off
    // (1e-17 m/s) to 1 m/s in at most ln(1e17)/ln(1.07) = 580 steps, from the slug's sharp edges
    // (odd-even content ~1e-2 m/s) in ~70: within the 400 steps.
    if (C >= 0.72) {
      EXPECT_TRUE(explicit_.failed) << "C = " << C;
    }
  }
  // The threshold by bisection between the last bounded and the first failing Courant number.
  double lo = last_bounded, hi = first_failed;
  ASSERT_LT(lo, hi) << "a bounded Courant number above a failing one";
  for (int k = 0; k < 6; ++k) {
    const double mid = 0.5 * (lo + hi);
    const AcousticOutcome e = runAcoustic("explicit", mid, kAcousticSteps);
    rows.push_back({mid, e.amplitude, "explicit", e.failed ? "failed" : "ok"});
    (e.failed ? hi : lo) = mid;
  }
  if (rank0())
    std::printf("explicit pressure: bounded for %d steps up to C = %.4f, fails from C = %.4f (Fourier limits: 2-D "
                "0.5, 1-D %.4f)\n", kAcousticSteps, lo, hi, limit);
  // The measured threshold lies between the 2-D Fourier limit (below it no mode grows) and the
  // Courant number at which the 1-D odd-even mode alone grows from round-off to the bound within
  // the run: 4C² − 1 = (1e17)^(1/400) gives C = 0.725.
  EXPECT_GE(hi, 0.5);
  EXPECT_LE(hi, 0.725);
  writeSweep(*world(), "stability_a_pressure", "acoustic Courant number c dt / h",
             "largest |u| over 400 steps / slug speed", rows,
             {{"explicit fails above (measured)", hi}, {"Fourier limit 2-D", 0.5}, {"Fourier limit 1-D", limit}});
}

// Issue point 3: the explicit scheme's blow-up stops the step with a message that names the cell
// and what failed, not a NaN left in the state.
TEST(StabilityPressure, ExplicitBlowUpIsNamed)
{
  const AcousticOutcome e = runAcoustic("explicit", 2.0, 2000, false);
  if (rank0()) std::printf("explicit at C = 2 stopped after %d steps: %s\n", e.steps, e.message.c_str());
  ASSERT_TRUE(e.failed) << "the explicit run at C = 2 went 2000 steps without the step stopping";
  EXPECT_NE(e.message.find("cell"), std::string::npos) << e.message;
  EXPECT_NE(e.message.find("water"), std::string::npos) << e.message;
}

// ------------------------------------------------------------------------------------------------
// (c) Stiff drag: the momentum exchange over K = 1e3 .. 1e17 at Δt = 1e-4 s.
// ------------------------------------------------------------------------------------------------

constexpr double kGasConstant = 287.0, kTemperature = 293.15, kPressure = 101325.0;
constexpr double kDragDt = 1e-4;  // s: the order of the seed scene's steps at 20 mm

// Water and air in equal shares, at 1 atm: β = Δt K (v_w θ_a + v_a θ_w), the rate at which the
// implicit exchange closes the relative velocity w = u_w − u_a: w' = w / (1 + β) (two materials).
struct DragCell {
  double theta[2] = {0.5, 0.5};
  double v[2] = {1.0 / 1000.0, kGasConstant * kTemperature / kPressure};
  double beta(double K, double dt) const { return dt * K * (v[0] * theta[1] + v[1] * theta[0]); }
};

std::vector<double> dragCoefficients()
{
  std::vector<double> K;
  for (int e = 3; e <= 17; ++e) K.push_back(std::pow(10.0, e));
  return K;
}

// The pointwise exchange in one cell, one step: cfdmpm's implicit solve (ice::exchangeMomentumCC)
// and forward Euler (the explicit drag of simpler codes, u_m += Σ_n β_mn (u_n − u_m)) from the same
// velocities. Returns w'/w and the momentum change relative to Σ ρ|u|.
struct PointwiseDrag {
  double implicit_ratio, explicit_ratio, implicit_momentum, explicit_momentum;
};

PointwiseDrag pointwiseDrag(double K, double dt)
{
  const DragCell cell;
  ice::MaterialArray<double> theta, v, rho;
  ice::MaterialArray<Kokkos::Array<double, 2>> u;
  const double u0[2] = {0.3, -0.2};  // m/s, x components; y zero
  for (int m = 0; m < 2; ++m) {
    theta[m] = cell.theta[m];
    v[m] = cell.v[m];
    rho[m] = theta[m] / v[m];
    u[m] = {u0[m], 0.0};
  }
  const double p0 = rho[0] * u0[0] + rho[1] * u0[1], scale = rho[0] * std::abs(u0[0]) + rho[1] * std::abs(u0[1]);
  const double w0 = u0[0] - u0[1];
  PointwiseDrag out{};
  EXPECT_EQ(ice::exchangeMomentumCC<2>(2, dt, ice::ExchangeCoefficients::uniform(K), rho, theta, v, u),
            ice::ExchangeStatus::Ok);
  out.implicit_ratio = (u[0][0] - u[1][0]) / w0;
  out.implicit_momentum = std::abs(rho[0] * u[0][0] + rho[1] * u[1][0] - p0) / scale;
  double ue[2];
  for (int m = 0; m < 2; ++m) {
    const int n = 1 - m;
    ue[m] = u0[m] + dt * v[m] * theta[n] * K * (u0[n] - u0[m]);
  }
  out.explicit_ratio = (ue[0] - ue[1]) / w0;
  out.explicit_momentum = std::abs(rho[0] * ue[0] + rho[1] * ue[1] - p0) / scale;
  return out;
}

TEST(StabilityDrag, PointwiseImplicitNeverOvershootsExplicitFailsAtBetaTwo)
{
  const DragCell cell;
  std::vector<SweepRow> rows;
  for (double K : dragCoefficients()) {
    const double beta = cell.beta(K, kDragDt);
    const PointwiseDrag d = pointwiseDrag(K, kDragDt);
    rows.push_back({K, std::abs(d.implicit_ratio), "implicit, one cell (cfdmpm)", "ok"});
    rows.push_back({K, std::abs(d.explicit_ratio), "explicit, one cell",
                    std::abs(d.explicit_ratio) > 1 ? "failed" : d.explicit_ratio < 0 ? "overshoot" : "ok"});
    // Implicit: w' = w / (1 + β) exactly (two materials), so 0 < w'/w ≤ 1: no overshoot, monotone.
    // Its error against 1/(1 + β) is round-off of the elimination: a few ε of the larger velocity
    // over w (0.5 m/s), and ε relative to the tiny ratio itself.
    EXPECT_GT(d.implicit_ratio, 0.0) << "K = " << K;
    EXPECT_LE(d.implicit_ratio, 1.0) << "K = " << K;
    EXPECT_NEAR(d.implicit_ratio, 1.0 / (1.0 + beta), 8 * DBL_EPSILON * (0.3 / 0.5) + 4 * DBL_EPSILON / (1 + beta))
        << "K = " << K;
    // Momentum: the exchange's projection conserves Σ ρ u to a few roundings of Σ ρ|u| (test_exchange).
    EXPECT_LT(d.implicit_momentum, 10 * DBL_EPSILON) << "K = " << K;
    // Explicit: w' = (1 − β) w exactly: it overshoots (reverses w) for β > 1 and grows for β > 2.
    EXPECT_NEAR(d.explicit_ratio, 1.0 - beta, 4 * DBL_EPSILON * std::max(1.0, beta)) << "K = " << K;
  }
  const double overshoot = 1.0 / cell.beta(1.0, kDragDt), growth = 2.0 / cell.beta(1.0, kDragDt);
  if (rank0())
    std::printf("explicit drag at dt = %g s: overshoots from K = %.4g, grows from K = %.4g kg/(m^3 s)\n", kDragDt,
                overshoot, growth);
  writeSweep(*world(), "stability_c_drag_cell", "exchange coefficient K (kg/(m^3 s)), dt = 1e-4 s",
             "|w'/w| after one step (relative velocity water-air)", rows,
             {{"explicit overshoots (beta = 1)", overshoot}, {"explicit grows (beta = 2)", growth}});
}

// The same exchange in a scene: water and air in equal shares filling a closed 0.1 m box (10 x 10
// cells, free-slip walls, no gravity, no viscosity), the air circulating in the box's first mode
// (stream function ψ ∝ sin(πx/L) sin(πy/L), 0.01 m/s) and the water against it so that every cell's
// momentum is zero: the common velocity is zero everywhere, and drag must bring both materials to it
// without reversing their relative velocity.
std::string dragScene(double K)
{
  std::ostringstream k;
  k << std::scientific << std::setprecision(3) << K;
  return R"(
cfdmpm:
  domain: {dimension: 2, lower: [0.0, 0.0], upper: [0.1, 0.1], cells: [10, 10], patch_cells: [5, 10], gravity: [0.0, 0.0]}
  materials:
    water:
      kind: fluid
      equation_of_state: {type: linear_water, bulk_modulus: 2.15e9, reference_density: 1000.0, reference_pressure: 101325.0, reference_temperature: 293.15, thermal_expansion: 0.0}
      viscosity: 0.0
      specific_heat: 4180.0
    air:
      kind: fluid
      equation_of_state: {type: ideal_gas, gas_constant: 287.0, gamma: 1.4}
      viscosity: 0.0
  initial_state: {background_material: water, temperature: 293.15, pressure: 101325.0, hydrostatic: false}
)" + std::string(freeSlipBox()) +
         R"(  time: {end_time: 1.0}
  output: {directory: unused, interval: 1.0}
  ice: {exchange_coefficient: )" + k.str() + "}\n";
}

// Fills every owned cell with the mixture and the circulating velocities (ghosts refreshed).
void setDragState(CoupledRun<2>& run, double air_speed)
{
  const DragCell cell;
  const auto ijk = run.layout->cellIndex();
  auto theta = run.state.volume_fraction.view();
  auto rho = run.state.density.view();
  auto v = run.state.specific_volume.view();
  auto u = run.state.velocity.view();
  auto T = run.state.temperature.view();
  auto p = run.state.pressure.view();
  const double L = 0.1, h = 0.01;
  for (LocalOrdinal c = 0; c < run.layout->ownedCells(); ++c) {
    const double x = (ijk(c, 0) + 0.5) * h, y = (ijk(c, 1) + 0.5) * h;
    const double ua = air_speed * std::sin(M_PI * x / L) * std::cos(M_PI * y / L);
    const double va = -air_speed * std::cos(M_PI * x / L) * std::sin(M_PI * y / L);
    for (int m = 0; m < 2; ++m) {
      theta(c, m) = cell.theta[m];
      v(c, m) = cell.v[m];
      rho(c, m) = cell.theta[m] / cell.v[m];
      T(c, m) = kTemperature;
    }
    const double ratio = rho(c, 1) / rho(c, 0);  // water moves against the air: zero momentum per cell
    u(c, 2) = ua, u(c, 3) = va;
    u(c, 0) = -ratio * ua, u(c, 1) = -ratio * va;
    p(c, 0) = kPressure;
  }
  for (Field<2>* f : run.state.fields()) f->exchangeHalo();
}

struct DragSceneOutcome {
  double first_ratio = 0;        // max|w| after the first step / before
  bool reversed = false;         // some cell's w changed sign (beyond round-off)
  double worst_growth = 0;       // largest max|w|_{n+1} / max|w|_n over the steps
  double worst_bound = 0;        // largest max|w|_{n+1} / its implicit-exchange bound (see below)
  double momentum_error = 0;     // |ΔP − wall impulse| / Σ ρ|u| V, worst component
  std::string failure;
};

// The force of the walls of a square box of n x n cells of size h on what it holds, per unit depth,
// from the pressure of the cells along them (p − kPressure: a uniform pressure pushes both walls of
// a pair alike), summed over the ranks: x and y components.
std::array<double, 2> wallPressureForce(const CoupledRun<2>& run, double h, long long n)
{
  const auto ijk = run.layout->cellIndex();
  const auto p = run.state.pressure.view();
  double local[2] = {0, 0};
  for (LocalOrdinal c = 0; c < run.layout->ownedCells(); ++c)
    for (int d = 0; d < 2; ++d) {
      if (ijk(c, d) == 0) local[d] += (p(c, 0) - kPressure) * h;
      if (ijk(c, d) == n - 1) local[d] -= (p(c, 0) - kPressure) * h;
    }
  return {globalSum(*world(), local[0]), globalSum(*world(), local[1])};
}

DragSceneOutcome runDragScene(double K, int steps)
{
  const double beta = DragCell().beta(K, kDragDt);
  CoupledRun<2> run(sceneFromYaml(dragScene(K)), world());
  const double air_speed = 0.01;
  setDragState(run, air_speed);
  const LocalOrdinal owned = run.layout->ownedCells();
  const double h = 0.01, V = h * h;
  auto relative = [&](std::vector<double>& w) {
    const auto u = run.state.velocity.view();
    w.resize(2 * owned);
    double largest = 0;
    for (LocalOrdinal c = 0; c < owned; ++c)
      for (int d = 0; d < 2; ++d) {
        w[2 * c + d] = u(c, d) - u(c, 2 + d);
        largest = std::max(largest, std::abs(w[2 * c + d]));
      }
    return globalMax(*world(), largest);
  };
  auto momentum = [&](int d) {
    const auto u = run.state.velocity.view();
    const auto rho = run.state.density.view();
    double sum = 0, magnitude = 0;
    for (LocalOrdinal c = 0; c < owned; ++c)
      for (int m = 0; m < 2; ++m) sum += rho(c, m) * u(c, 2 * m + d) * V, magnitude += rho(c, m) * std::abs(u(c, 2 * m + d)) * V;
    return std::pair<double, double>(globalSum(*world(), sum), globalSum(*world(), magnitude));
  };
  std::vector<double> w_old, w_new;
  double largest_old = relative(w_old);
  const auto [px0, scale_x] = momentum(0);
  const auto [py0, scale_y] = momentum(1);
  double impulse[2] = {0, 0};
  DragSceneOutcome out;
  for (int k = 0; k < steps; ++k) {
    try {
      run.stepper.step(run.state, kDragDt);
    } catch (const StepFailure& failure) {
      out.failure = failure.what();
      break;
    }
    const std::array<double, 2> force = wallPressureForce(run, h, 10);
    for (int d = 0; d < 2; ++d) impulse[d] += kDragDt * force[d];
    const double largest_new = relative(w_new);
    if (k == 0) out.first_ratio = largest_new / largest_old;
    // The bound of an exchange that never amplifies. Within a step the pressure force gives the two
    // materials different accelerations, v_m ∇p (force θ_m ∇p on a bulk density θ_m / v_m), so the
    // relative velocity the exchange receives is w + Δt (v_a − v_w) ∇p; the implicit exchange divides
    // it by 1 + β. |∇p| is at most the largest difference of neighbouring cells' pressures over h
    // (the face pressures are their means, and the walls' the cells'). Advection moves w between
    // cells: by at most 2 Δt max|u| / h of it. Round-off: 4 ε of the largest velocity, and the
    // pressure's own round-off, a few ulps of p = 1e5 Pa between the pressures a step uses (the
    // equilibration's, the corrected, the face means), which acts as a gradient 4 ε p / h: once the
    // initial w has decayed, the velocities of both materials are ~1e-15 m/s and drift by
    // 2.9e-16 m/s per step in the same direction (measured with K = 1e8, the pressure differences
    // between cells exactly zero), and w settles at that drift's Δt (v_a − v_w) a / β.
    {
      const std::vector<double> pressure = gatherField(run.state.pressure);
      double gradient = 0;
      for (int j = 0; j < 10; ++j)
        for (int i = 0; i < 10; ++i) {
          if (i < 9) gradient = std::max(gradient, std::abs(pressure[j * 10 + i + 1] - pressure[j * 10 + i]) / h);
          if (j < 9) gradient = std::max(gradient, std::abs(pressure[(j + 1) * 10 + i] - pressure[j * 10 + i]) / h);
        }
      const auto v = run.state.specific_volume.view();
      const auto u = run.state.velocity.view();
      double dv = 0, fastest = 0;
      for (LocalOrdinal c = 0; c < owned; ++c) {
        dv = std::max(dv, std::abs(v(c, 1) - v(c, 0)));
        for (int col = 0; col < 4; ++col) fastest = std::max(fastest, std::abs(u(c, col)));
      }
      dv = globalMax(*world(), dv);
      fastest = globalMax(*world(), fastest);
      double p_max = 0;
      for (double pc : pressure) p_max = std::max(p_max, std::abs(pc));
      gradient += 4 * DBL_EPSILON * p_max / h;
      const double bound = (largest_old + kDragDt * dv * gradient) / (1 + beta) * (1 + 2 * kDragDt * fastest / h) +
                           4 * DBL_EPSILON * fastest;
      out.worst_bound = std::max(out.worst_bound, largest_new / bound);
    }
    out.worst_growth = std::max(out.worst_growth, largest_new / largest_old);
    // A reversal counts where w was above round-off of the velocities (ε × 0.01 m/s ~ 1e-18).
    int reversed = 0;
    for (std::size_t i = 0; i < w_new.size(); ++i)
      if (std::abs(w_old[i]) > 1e-16 && w_new[i] * w_old[i] < 0) reversed = 1;
    out.reversed = out.reversed || globalMax(*world(), reversed) > 0;
    std::swap(w_old, w_new);
    largest_old = largest_new;
  }
  const auto [px, sx] = momentum(0);
  const auto [py, sy] = momentum(1);
  (void)sx, (void)sy;
  out.momentum_error = std::max(std::abs(px - px0 - impulse[0]) / scale_x, std::abs(py - py0 - impulse[1]) / scale_y);
  return out;
}

TEST(StabilityDrag, SceneApproachesTheCommonVelocityWithoutOvershoot)
{
  const DragCell cell;
  std::vector<SweepRow> rows;
  const int steps = 10;
  for (double K : dragCoefficients()) {
    const double beta = cell.beta(K, kDragDt);
    const DragSceneOutcome s = runDragScene(K, steps);
    if (rank0())
      std::printf("K = %.0e (beta %.3g): first step max|w| ratio %.6g (x(1+beta) - 1 = %.2e), worst step ratio %.6g, "
                  "worst / bound %.6g, %s, momentum error %.2e%s%s\n",
                  K, beta, s.first_ratio, s.first_ratio * (1 + beta) - 1, s.worst_growth, s.worst_bound, s.reversed ? "REVERSED" : "no reversal",
                  s.momentum_error, s.failure.empty() ? "" : ", stopped: ", s.failure.c_str());
    rows.push_back({K, s.first_ratio, "implicit, scene (cfdmpm)", s.failure.empty() ? "ok" : "failed"});
    EXPECT_TRUE(s.failure.empty()) << "K = " << K << ": " << s.failure;
    // The first step: the initial relative velocity (0.01 m/s) is the only one of size; what the
    // pressure force adds in one step is below 1e-6 of it, so max|w| falls by 1/(1 + β).
    EXPECT_NEAR(s.first_ratio * (1 + beta), 1.0, 1e-6) << "K = " << K;
    // Every step: no more relative velocity than the implicit exchange leaves of what it received
    // (the bound above); an exchange that overshot would reverse w and leave |1 − β| of it. (Once the
    // initial w has decayed to the drift that the pressure, or its round-off, drives, w follows that
    // drift's sign: a reversal there is not an overshoot, so reversals are reported, not asserted.)
    EXPECT_LE(s.worst_bound, 1.0) << "K = " << K;
    // Momentum: the change of Σ ρ u V equals the walls' pressure impulse to round-off (the exchange
    // conserves each cell's momentum to a few ε of its Σ ρ|u|; 100 cells, 10 steps: 1e3 ε).
    EXPECT_LT(s.momentum_error, 1000 * DBL_EPSILON) << "K = " << K;
  }
  writeSweep(*world(), "stability_c_drag_scene", "exchange coefficient K (kg/(m^3 s)), dt = 1e-4 s",
             "max|w| after one step / before (scene)", rows);
}

}  // namespace
}  // namespace cfdmpm::test

namespace cfdmpm::test {
namespace {

// ------------------------------------------------------------------------------------------------
// (d) Density ratio: a liquid under a gas lighter by 1:10 .. 1:100 000.
// ------------------------------------------------------------------------------------------------

// The gas constant that gives a gas of density `density` at 1 atm and 293.15 K.
double gasConstantFor(double density) { return kPressure / (density * kTemperature); }

// A closed 0.2 m box (20 x 20 cells of 10 mm, free-slip walls, gravity) with a liquid of density
// `liquid` and bulk modulus `bulk` below y = `level` and a gas of density `gas` above; `regions`
// replaces the level with other shapes of liquid (the dam break).
std::string twoFluidScene(double liquid, double bulk, double gas, const std::string& domain, const std::string& regions,
                          const std::string& time, const std::string& ice = "{}")
{
  std::ostringstream text;
  text << std::setprecision(12) << R"(
cfdmpm:
  domain: )" << domain << R"(
  materials:
    liquid:
      kind: fluid
      equation_of_state: {type: linear_water, bulk_modulus: )"
       << bulk << ", reference_density: " << liquid << R"(, reference_pressure: 101325.0, reference_temperature: 293.15, thermal_expansion: 0.0}
      viscosity: 1.0e-3
      specific_heat: 4180.0
    gas:
      kind: fluid
      equation_of_state: {type: ideal_gas, gas_constant: )"
       << gasConstantFor(gas) << R"(, gamma: 1.4}
      viscosity: 1.8e-5
  initial_state: {background_material: gas, temperature: 293.15, pressure: 101325.0}
  regions:
)" << regions << freeSlipBox()
       << "  time: " << time << R"(
  output: {directory: unused, interval: 1.0}
  ice: )" << ice << "\n";
  return text.str();
}

struct StillOutcome {
  double worst_speed = 0;    // largest speed of either fluid where it fills over 1e-3 of a cell (m/s)
  double surface_motion = 0; // largest change of a column's liquid depth (m)
  double mass_change = 0;    // largest relative change of a fluid's mass
  long long steps = 0;
  double worst_residual = 0;  // largest outer residual of the pressure equation at a step's end
  int unconverged = 0;        // steps whose outer iteration did not reach its tolerance
  std::string failure;
};

StillOutcome runStill(double liquid, double bulk, double gas, double end, const std::string& ice = "{}")
{
  CoupledRun<2> run(sceneFromYaml(twoFluidScene(
                        liquid, bulk, gas,
                        "{dimension: 2, lower: [0.0, 0.0], upper: [0.2, 0.2], cells: [20, 20], patch_cells: [10, 10], gravity: [0.0, -9.81]}",
                        "    level: {material: liquid, shape: half_plane, point: [0.0, 0.1], normal: [0.0, 1.0]}\n",
                        "{end_time: 1.0, cfl: 0.25, dt_initial: 1.0e-4}", ice)),
                    world());
  auto depth = [&] {
    const auto theta = run.state.volume_fraction.view();
    const auto ijk = run.layout->cellIndex();
    std::vector<double> local(20, 0.0), total(20, 0.0);
    for (LocalOrdinal c = 0; c < run.layout->ownedCells(); ++c) local[ijk(c, 0)] += theta(c, 0) * 0.01;
    Teuchos::reduceAll(*world(), Teuchos::REDUCE_SUM, 20, local.data(), total.data());
    return total;
  };
  const std::vector<double> depth0 = depth();
  const double mass0[2] = {run.fluidMass(0), run.fluidMass(1)};
  StillOutcome out;
  try {
    run.runUntil(end, [&] {
      out.worst_speed = std::max({out.worst_speed, run.maxFluidSpeed(0), run.maxFluidSpeed(1)});
      out.worst_residual = std::max(out.worst_residual, run.last.ice.outer_residual);
      if (!run.last.ice.converged) ++out.unconverged;
    });
  } catch (const StepFailure& failure) {
    out.failure = failure.what();
  }
  out.steps = run.steps;
  const std::vector<double> d = depth();
  for (int i = 0; i < 20; ++i) out.surface_motion = std::max(out.surface_motion, std::abs(d[i] - depth0[i]));
  for (int m = 0; m < 2; ++m) out.mass_change = std::max(out.mass_change, std::abs(run.fluidMass(m) / mass0[m] - 1));
  return out;
}

TEST(StabilityDensityRatio, StillSurfaceStaysStill)
{
  struct Case {
    double liquid, bulk, gas;
    const char* name;
  };
  const double air = kPressure / (kGasConstant * kTemperature);  // 1.204 kg/m^3: water/air 1:830
  const std::vector<Case> cases = {{1000.0, 2.15e9, 100.0, "water, gas 1:10"},
                                   {1000.0, 2.15e9, 10.0, "water, gas 1:100"},
                                   {1000.0, 2.15e9, air, "water, air 1:830"},
                                   {1000.0, 2.15e9, 0.1, "water, gas 1:10 000"},
                                   {12040.0, 2.85e10, air, "dense liquid, air 1:10 000"},
                                   {1000.0, 2.15e9, 0.01, "water, gas 1:100 000"}};
  std::vector<SweepRow> rows;
  // Twice: with the default outer tolerance of the pressure equation (1e-8 of a cell's volume per
  // step) and with 1e-12, where what the solver leaves is below what the discretization does.
  for (const char* tolerance : {"1.0e-8", "1.0e-12"}) {
    for (const Case& c : cases) {
      const StillOutcome s = runStill(c.liquid, c.bulk, c.gas, 1.0, std::string("{outer_tolerance: ") + tolerance + "}");
      const double ratio = c.liquid / c.gas;
      if (rank0())
        std::printf("tolerance %s, %-28s (1:%.0f): %lld steps, max |u| %.3e m/s, surface moved %.2e m, mass change "
                    "%.1e, largest outer residual %.1e, %d steps unconverged%s%s\n",
                    tolerance, c.name, ratio, s.steps, s.worst_speed, s.surface_motion, s.mass_change, s.worst_residual,
                    s.unconverged, s.failure.empty() ? "" : ", stopped: ", s.failure.c_str());
      rows.push_back({ratio, s.worst_speed,
                      std::string(c.liquid > 1000.0 ? "dense liquid under air" : "water under a gas") + ", tolerance " +
                          tolerance + " (cfdmpm)",
                      s.failure.empty() ? "ok" : "failed"});
      EXPECT_TRUE(s.failure.empty()) << c.name << ": " << s.failure;
      // The bound. A discretization whose pressure gradient and gravity are out of balance at the
      // interface by a fraction f of g accelerates the gas by f g each step: f g Δt, 0.1 m/s per step
      // at Δt_max = 1e-2 s for the one-fluid form with an arithmetic face density (f ~ 1). Requiring
      // f ≤ 1e-3 gives 1e-4 m/s, the bound of test_ice_scenes' still water. Measured (1 rank / 2 ranks):
      // with 1e-8, 8e-9 .. 2.4e-6 / 1.4e-6 .. 9.7e-5 m/s, the light gases' part set by the solver's
      // tolerance (it falls with it and depends on the partition; the largest, the dense liquid's air
      // on 2 ranks, grows steadily over the run at ~6e-6 g); with 1e-12, 2e-9 .. 2.3e-6 m/s on both,
      // proportional to the gas's density (the start-up of the gas's own stratification). Before the
      // outer test's density factor (doc/ice.md, [5]) the gases at 1:10 000 and 1:100 000 moved at
      // 2.5e-4 .. 2.1e-2 m/s here.
      EXPECT_LT(s.worst_speed, 1e-4) << c.name << ", tolerance " << tolerance;
      EXPECT_LT(s.surface_motion, 1e-4 * 1.0) << c.name;  // at most the bound times the 1 s run
      EXPECT_LT(s.mass_change, 1e-12) << c.name;  // conservative advection: round-off (400 cells x 1e-16)
    }
  }
  writeSweep(*world(), "stability_d_still_surface", "density ratio liquid / gas", "largest speed over 1 s (m/s)", rows);
}

// A small dam break: a 0.1 m x 0.1 m liquid column in the corner of a closed 0.4 m x 0.2 m box
// (80 x 40 cells of 5 mm, free-slip walls) under a gas, 0.25 s: the front reaches the far wall and
// runs up it. The kinetic energy may never exceed what the descent released (the potential energy
// of both fluids, PE(0) − PE(t)) plus what the liquid stored by its hydrostatic compression,
// Σ (p − p0)² / (2 K) θ V (2e-6 J/m here, against ~1 J/m released): viscosity and the scheme only
// dissipate. A method that is unstable at the density ratio gains energy at the interface.
// The potential energy is measured with each cell's mass at its centre; in a cell the liquid only
// partly fills, its centre of mass lies anywhere from the cell's centre to half a cell away (a
// layer θ h thick at the bottom of the cell: (1 − θ) h / 2 below the centre), so the measured
// PE(t) is uncertain by U = Σ ρ_l θ (1 − θ) g (h/2) V over the cells (the initial column fills whole
// cells: PE(0) is exact). The thin surge layer makes U a few per cent of the energy released; the
// test asserts KE ≤ released + stored + U. Measured largest KE / (released + stored) at 10, 5 and
// 2.5 mm: 1.025, 1.005, 1.000 (water/air): the excess is the measure's, and goes with h.
struct DamBreakOutcome {
  double worst_excess = 0;  // largest (KE − released − stored) / U over the run
  double worst_share = 0;   // largest KE / (released + stored) over the run (from 0.01 s)
  double worst_bounded = 0; // largest KE / (released + stored + U) over the run: at most 1
  double final_share = 0;   // at the end
  double mass_change = 0;
  long long steps = 0;
  std::string failure;
};

DamBreakOutcome runDamBreak(double liquid, double bulk, double gas, double end)
{
  CoupledRun<2> run(sceneFromYaml(twoFluidScene(
                        liquid, bulk, gas,
                        "{dimension: 2, lower: [0.0, 0.0], upper: [0.4, 0.2], cells: [80, 40], patch_cells: [20, 20], gravity: [0.0, -9.81]}",
                        "    column: {material: liquid, shape: box, lower: [0.0, 0.0], upper: [0.1, 0.1]}\n",
                        "{end_time: 1.0, cfl: 0.25, dt_initial: 1.0e-4}")),
                    world());
  const double h = 0.005, V = h * h, g = 9.81;
  const auto ijk = run.layout->cellIndex();
  auto energies = [&](double& kinetic, double& potential, double& stored, double& uncertain) {
    const auto rho = run.state.density.view();
    const auto u = run.state.velocity.view();
    const auto theta = run.state.volume_fraction.view();
    const auto p = run.state.pressure.view();
    double local[4] = {0, 0, 0, 0}, total[4];
    for (LocalOrdinal c = 0; c < run.layout->ownedCells(); ++c) {
      const double y = (ijk(c, 1) + 0.5) * h;
      for (int m = 0; m < 2; ++m) {
        local[0] += 0.5 * rho(c, m) * (u(c, 2 * m) * u(c, 2 * m) + u(c, 2 * m + 1) * u(c, 2 * m + 1)) * V;
        local[1] += rho(c, m) * g * y * V;
      }
      local[2] += (p(c, 0) - kPressure) * (p(c, 0) - kPressure) / (2 * bulk) * theta(c, 0) * V;
      const double fill = std::min(1.0, std::max(0.0, theta(c, 0)));
      local[3] += rho(c, 0) * (1 - fill) * g * 0.5 * h * V;  // ρ_l θ (1 − θ) g h/2 V, ρ(c, 0) = ρ_l θ
    }
    Teuchos::reduceAll(*world(), Teuchos::REDUCE_SUM, 4, local, total);
    kinetic = total[0], potential = total[1], stored = total[2], uncertain = total[3];
  };
  double ke0, pe0, stored0, uncertain0;
  energies(ke0, pe0, stored0, uncertain0);
  const double mass0[2] = {run.fluidMass(0), run.fluidMass(1)};
  DamBreakOutcome out;
  try {
    run.runUntil(end, [&] {
      double ke, pe, stored, uncertain;
      energies(ke, pe, stored, uncertain);
      const double share = ke / (pe0 - pe + stored0);
      if (run.time >= 0.01) out.worst_share = std::max(out.worst_share, share);
      out.worst_excess = std::max(out.worst_excess, (ke - (pe0 - pe + stored0)) / (uncertain + uncertain0));
      if (run.time >= 0.01)
        out.worst_bounded = std::max(out.worst_bounded, ke / (pe0 - pe + stored0 + uncertain + uncertain0));
      out.final_share = share;
    });
  } catch (const StepFailure& failure) {
    out.failure = failure.what();
  }
  out.steps = run.steps;
  for (int m = 0; m < 2; ++m) out.mass_change = std::max(out.mass_change, std::abs(run.fluidMass(m) / mass0[m] - 1));
  return out;
}

TEST(StabilityDensityRatio, DamBreakStaysBounded)
{
  struct Case {
    double liquid, bulk, gas;
    const char* name;
  };
  const double air = kPressure / (kGasConstant * kTemperature);
  const std::vector<Case> cases = {{1000.0, 2.15e9, 10.0, "water, gas 1:100"},
                                   {1000.0, 2.15e9, air, "water, air 1:830"},
                                   {1000.0, 2.15e9, 0.1, "water, gas 1:10 000"},
                                   {12040.0, 2.85e10, air, "dense liquid, air 1:10 000"}};
  std::vector<SweepRow> rows;
  for (const Case& c : cases) {
    const DamBreakOutcome d = runDamBreak(c.liquid, c.bulk, c.gas, 0.25);
    const double ratio = c.liquid / c.gas;
    if (rank0())
      std::printf("%-28s (1:%.0f): %lld steps, KE / released: largest %.4f, at 0.25 s %.4f; largest (KE - released) / U "
                  "%.3f; mass change %.1e%s%s\n",
                  c.name, ratio, d.steps, d.worst_share, d.final_share, d.worst_excess, d.mass_change,
                  d.failure.empty() ? "" : ", stopped: ", d.failure.c_str());
    const bool dense = c.liquid > 1000.0;
    rows.push_back({ratio, d.worst_share, dense ? "KE / released, dense liquid (cfdmpm)" : "KE / released, water (cfdmpm)",
                    d.failure.empty() ? "ok" : "failed"});
    rows.push_back({ratio, d.worst_bounded,
                    dense ? "KE / (released + U), dense liquid (cfdmpm)" : "KE / (released + U), water (cfdmpm)",
                    d.failure.empty() ? "ok" : "failed"});
    EXPECT_TRUE(d.failure.empty()) << c.name << ": " << d.failure;
    EXPECT_LE(d.worst_excess, 1.0) << c.name;  // no energy from nothing, within what PE's measure can tell
    EXPECT_LT(d.mass_change, 1e-12) << c.name;  // conservative advection: round-off
  }
  writeSweep(*world(), "stability_d_dam_break", "density ratio liquid / gas",
             "largest kinetic energy / energy released (from 0.01 s to 0.25 s)", rows);
}

// ------------------------------------------------------------------------------------------------
// (e) Vanishing materials: cells emptied and refilled by advection.
// ------------------------------------------------------------------------------------------------

// A water slug (0.2 m) in a closed air-filled channel 0.6 m x 0.01 m (120 x 2 cells of 5 mm,
// free-slip walls, no gravity), started at `speed`: the air on both sides is a spring (isothermal:
// ω = sqrt(2 p0 / (L_air ρ L_slug)) = 71 rad/s, period 0.088 s), and the slug oscillates with an
// amplitude speed / ω (7 mm at 0.5 m/s, 28 mm at 2 m/s), emptying the cells behind it of water and
// filling them again twice a period.
struct VanishingOutcome {
  double smallest_fraction = 1;  // smallest positive water volume fraction seen
  long long cells_below = 0;     // cell-steps with 0 < θ_water < 1e-12
  long long refilled = 0;        // cells that fell below 1e-12 and later held over half water
  double mass_change = 0;        // largest relative change of either fluid's mass
  long long steps = 0;
  std::string failure;
};

VanishingOutcome runVanishing(double speed, double end)
{
  std::ostringstream text;
  text << R"(
cfdmpm:
  domain: {dimension: 2, lower: [0.0, 0.0], upper: [0.6, 0.01], cells: [120, 2], patch_cells: [20, 2], gravity: [0.0, 0.0]}
  materials:
    water:
      kind: fluid
      equation_of_state: {type: linear_water, bulk_modulus: 2.15e9, reference_density: 1000.0, reference_pressure: 101325.0, reference_temperature: 293.15, thermal_expansion: 0.0}
      viscosity: 1.0e-3
      specific_heat: 4180.0
    air:
      kind: fluid
      equation_of_state: {type: ideal_gas, gas_constant: 287.0, gamma: 1.4}
      viscosity: 1.8e-5
  initial_state: {background_material: air, temperature: 293.15, pressure: 101325.0, hydrostatic: false}
  regions:
    slug: {material: water, shape: box, lower: [0.2, 0.0], upper: [0.4, 0.01], velocity: [)"
       << speed << R"(, 0.0]}
)" << freeSlipBox()
       << R"(  time: {end_time: 1.0, cfl: 0.25, dt_initial: 1.0e-5}
  output: {directory: unused, interval: 1.0}
)";
  CoupledRun<2> run(sceneFromYaml(text.str()), world());
  const double mass0[2] = {run.fluidMass(0), run.fluidMass(1)};
  VanishingOutcome out;
  std::vector<int> emptied(run.layout->ownedCells(), 0), refilled(run.layout->ownedCells(), 0);
  try {
    run.runUntil(end, [&] {
      const auto theta = run.state.volume_fraction.view();
      double smallest = 1;
      long long below = 0;
      for (LocalOrdinal c = 0; c < run.layout->ownedCells(); ++c) {
        if (theta(c, 0) < 1e-12) emptied[c] = 1;
        if (emptied[c] && theta(c, 0) > 0.5) refilled[c] = 1;
        if (theta(c, 0) > 0) {
          smallest = std::min(smallest, theta(c, 0));
          if (theta(c, 0) < 1e-12) ++below;
        }
      }
      Teuchos::RCP<const Teuchos::Comm<int>> comm = world();
      double global_smallest = 1;
      long long global_below = 0;
      Teuchos::reduceAll(*comm, Teuchos::REDUCE_MIN, smallest, Teuchos::outArg(global_smallest));
      Teuchos::reduceAll(*comm, Teuchos::REDUCE_SUM, below, Teuchos::outArg(global_below));
      out.smallest_fraction = std::min(out.smallest_fraction, global_smallest);
      out.cells_below += global_below;
      for (int m = 0; m < 2; ++m) out.mass_change = std::max(out.mass_change, std::abs(run.fluidMass(m) / mass0[m] - 1));
    });
  } catch (const StepFailure& failure) {
    out.failure = failure.what();
  }
  out.steps = run.steps;
  long long local = 0;
  for (int r : refilled) local += r;
  Teuchos::reduceAll(*world(), Teuchos::REDUCE_SUM, local, Teuchos::outArg(out.refilled));
  return out;
}

TEST(StabilityVanishing, EmptiedAndRefilledCellsStayFiniteAndConserveMass)
{
  std::vector<SweepRow> rows;
  for (double speed : {0.5, 1.0, 2.0}) {
    const VanishingOutcome v = runVanishing(speed, 0.18);  // two periods
    if (rank0())
      std::printf("slug at %.1f m/s: %lld steps, smallest water fraction %.3e, %lld cell-steps below 1e-12, %lld cells "
                  "emptied and refilled, mass change %.2e%s%s\n",
                  speed, v.steps, v.smallest_fraction, v.cells_below, v.refilled, v.mass_change,
                  v.failure.empty() ? "" : ", stopped: ", v.failure.c_str());
    rows.push_back({speed, v.mass_change, "mass change (cfdmpm)", v.failure.empty() ? "ok" : "failed"});
    rows.push_back({speed, v.smallest_fraction, "smallest water volume fraction", v.failure.empty() ? "ok" : "failed"});
    EXPECT_TRUE(v.failure.empty()) << speed << " m/s: " << v.failure;  // no value that is not finite
    // The case does what it claims: water fractions below 1e-12, and cells emptied and filled again.
    EXPECT_LT(v.smallest_fraction, 1e-12) << speed << " m/s";
    EXPECT_GT(v.refilled, 0) << speed << " m/s";
    EXPECT_LT(v.mass_change, 1e-12) << speed << " m/s";  // conservative advection: round-off
  }
  writeSweep(*world(), "stability_e_vanishing", "slug speed (m/s)",
             "relative mass change; smallest water volume fraction", rows);
}

// (c) in the coupled step: a solid disk (2000 kg/m^3, radius 0.1 m, E = 1e7 Pa) moving at 0.5 m/s
// through water in a closed 0.5 m box (20 x 20 cells of 25 mm, free-slip walls, no gravity,
// inviscid), 20 steps of Δt = 1e-4 s for each K. The exchange acts between the disk's cell velocity
// (from its particles) and the water's in the cells they share.
struct CoupledDragOutcome {
  double first_ratio = 0;     // max |u_disk − u_water| over shared cells after step 1 / 0.5 m/s
  double last_ratio = 0;      // after the last step
  double momentum_error = 0;  // |ΔP − wall impulse| / P_disk(0)
  std::string failure;
};

CoupledDragOutcome runCoupledDrag(double K, int steps)
{
  const char* disk = R"(    disk:
      kind: solid
      density: 2000.0
      particles_per_cell: 2
      model: {type: linear_elastic, youngs_modulus: 1.0e7, poisson_ratio: 0.3}
)";
  std::ostringstream k;
  k << std::scientific << std::setprecision(3) << K;
  const std::string regions = "    d: {material: disk, shape: polygon, velocity: [0.5, 0.0], vertices: " +
                              diskVertices(0.25, 0.25, 0.1) + "}";
  const std::string extra = std::string(freeSlipBox()) + "  ice: {exchange_coefficient: " + k.str() + "}";
  std::string text = tankScene(0.5, 0.5, 20, 20, 0.5, disk, regions, extra, 0.0);
  text.replace(text.find("viscosity: 1.0e-3"), 17, "viscosity: 0.0");
  CoupledRun<2> run(sceneFromYaml(text), world());
  const double h = 0.025;
  const int water = 1;  // the solids come first
  const auto total = [&] { return run.fluidMomentum(water, 0) + run.particles().momentum()[0]; };
  const double disk0 = run.particles().momentum()[0], start = total();
  auto relative = [&] {
    const auto u = run.state.velocity.view();
    const auto theta = run.state.volume_fraction.view();
    double largest = 0;
    for (LocalOrdinal c = 0; c < run.layout->ownedCells(); ++c)
      if (theta(c, 0) > 0.1 && theta(c, water) > 0.1)
        for (int d = 0; d < 2; ++d) largest = std::max(largest, std::abs(u(c, d) - u(c, 2 * water + d)));
    return globalMax(*world(), largest);
  };
  CoupledDragOutcome out;
  double impulse = 0;
  for (int n = 0; n < steps; ++n) {
    try {
      run.stepper.step(run.state, kDragDt);
    } catch (const StepFailure& failure) {
      out.failure = failure.what();
      break;
    }
    impulse += kDragDt * wallPressureForce(run, h, 20)[0];
    const double w = relative() / 0.5;
    if (n == 0) out.first_ratio = w;
    out.last_ratio = w;
  }
  out.momentum_error = std::abs(total() - start - impulse) / std::abs(disk0);
  return out;
}

TEST(StabilityDrag, CoupledDiskInWaterAtEveryK)
{
  std::vector<SweepRow> rows;
  double previous = 1e300;
  for (double K : {1e3, 1e5, 1e7, 1e9, 1e11, 1e13, 1e15, 1e17}) {
    const CoupledDragOutcome c = runCoupledDrag(K, 20);
    if (rank0())
      std::printf("K = %.0e: relative velocity disk-water after 1 step %.6g, after 20 %.6g of 0.5 m/s; momentum error "
                  "%.2e%s%s\n",
                  K, c.first_ratio, c.last_ratio, c.momentum_error, c.failure.empty() ? "" : ", stopped: ",
                  c.failure.c_str());
    rows.push_back({K, c.first_ratio, "implicit, disk in water (cfdmpm)", c.failure.empty() ? "ok" : "failed"});
    EXPECT_TRUE(c.failure.empty()) << "K = " << K << ": " << c.failure;
    // Stronger drag never leaves more slip: the first step's relative velocity does not rise with K
    // (an overshooting exchange would reverse it and, past β = 2, amplify it). Allowance: what the
    // pressure solve leaves, outer tolerance 1e-8 × h / Δt = 2.5e-6 m/s, 5e-6 of 0.5 m/s. (At small K
    // the slip exceeds 0.5 m/s: the water flows round the disk, at its sides against it.)
    EXPECT_LE(c.first_ratio, previous + 5e-6) << "K = " << K;
    previous = c.first_ratio;
    // Stiff drag (β = Δt K v θ ≥ 1e3 for θ ≥ 0.1 from K = 1e11): the disk and the water in a shared cell
    // move together, up to what the water's advection after the exchange changes: Δt |u| / h of the
    // velocity jump across a cell (2 × 0.5 m/s at most where the water flows round the disk), twice
    // for both directions: 2 × 1e-4 × 1 / 0.025 × 1 m/s = 8e-3 m/s, 0.016 of 0.5 m/s.
    if (K >= 1e11) {
      EXPECT_LE(c.first_ratio, 0.016) << "K = " << K;
      EXPECT_LE(c.last_ratio, 0.016) << "K = " << K;
    }
    // Momentum: the disk's and the water's change is the walls' impulse. At K ≥ 1e11 to 1e-14 of the
    // disk's momentum (round-off); at K ≤ 1e9, with the disk slipping through the water, to ~2e-11,
    // which is not round-off and whose cause is not known; the bound is test_coupled's for the same
    // balance (ExchangeConservesMomentum, 1e-10 of the disk's momentum).
    EXPECT_LT(c.momentum_error, 1e-10) << "K = " << K;
  }
  writeSweep(*world(), "stability_c_drag_coupled", "exchange coefficient K (kg/(m^3 s)), dt = 1e-4 s",
             "max |u_disk - u_water| in shared cells after one step / 0.5 m/s", rows);
}

}  // namespace
}  // namespace cfdmpm::test
