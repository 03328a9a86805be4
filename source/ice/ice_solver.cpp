#include "ice/ice_solver.hpp"

#include "common/error.hpp"
#include "common/kernel_math.hpp"

#include "ice/equilibration.hpp"
#include "ice/exchange.hpp"
#include "ice/material_eos.hpp"

#include <Teuchos_TimeMonitor.hpp>

#include <cfloat>
#include <climits>
#include <optional>
#include <cmath>
#include <iomanip>
#include <limits>
#include <sstream>
#include <type_traits>

namespace cfdmpm {

namespace {

constexpr double kTiny = 1e-100;  // guards divisions by a vanishing mass or density

// A material holding less than this share of a cell's mass has no velocity of its own: it moves
// with the mixture (its own momentum equation would divide by a vanishing mass).
constexpr double kNegligibleMassShare = 1e-12;
// Likewise on a face: a material filling less than this share of both neighbours has no face
// velocity of its own (a denormal volume fraction would leave it uncoupled by the exchange).
constexpr double kNegligibleVolumeShare = 1e-12;
// The share of its volume a material loses to a pressure change, v_L = v (1 − s(κ Σδp)): x to
// first order (Uintah's computeLagrangianSpecificVolume), but for a compression the isothermal
// gas's x / (1 + x) (v_L = v / (1 + x)), which has the same value and slope at x = 0 and leaves the
// volume positive. The linear form makes a gas's volume negative once one step raises its pressure
// by more than γ times itself: in the slide a trace of air (θ ~ 1e-9) in a cell the sand had just
// left did so at 0.465 s; its negative volume then made room for water 11 % over its density in the
// pressure equation, the pressure fell to zero and the run failed within 30 steps. Both the
// Lagrangian volumes and the pressure equation's residual use it (its matrix: below).
KOKKOS_INLINE_FUNCTION double volumeLoss(double x) { return x > 0 ? x / (1.0 + x) : x; }
KOKKOS_INLINE_FUNCTION double volumeLossSlope(double x) { return x > 0 ? 1.0 / ((1.0 + x) * (1.0 + x)) : 1.0; }
// A cavitating liquid (ice::LinearWater below its cavitation pressure) is compressed by its own law:
// its vapour behaves as an isothermal gas (the loss above, while the pressure stays below p_c), but
// once the vapour is gone the liquid is stiff again, so the loss stops near the vapour's share,
// 1 − ρ/ρ_c. With the gas's law alone the pressure equation let a boiling cell take in water far
// beyond its vapour, which the next equilibration found as a compression of 1-3 GPa (the seed slide
// at 5 mm). A pressure fall keeps the linear form.
KOKKOS_INLINE_FUNCTION bool cavitating(const ice::Eos& eos, double p)
{
  return eos.kind == ice::EosKind::LinearWater && p < eos.linear_water.cavitation_pressure;
}
/// A liquid that boils (a cavitation pressure) at a pressure where its law's density, p ρ_c / p_c,
/// is not positive.
KOKKOS_INLINE_FUNCTION bool boilsWithoutDensity(const ice::Eos& eos, double p)
{
  return eos.kind == ice::EosKind::LinearWater && eos.linear_water.cavitation_pressure > 0 && !(p > 0);
}
/// The share of its volume material m (EOS `eos`, temperature T, compressibility κ at the
/// equilibration pressure p) loses when the pressure rises by Σδp.
KOKKOS_INLINE_FUNCTION double materialVolumeLoss(const ice::Eos& eos, double p, double T, double kappa, double sum_dp)
{
  if (sum_dp > 0 && cavitating(eos, p)) {
    // At p <= 0 (a cell whose root a solid set, the liquid a trace there) a boiling liquid's law
    // has no density: its volume does not change.
    if (boilsWithoutDensity(eos, p)) return 0.0;
    return 1.0 - eos.density(p, T) / eos.density(p + sum_dp, T);
  }
  return volumeLoss(kappa * sum_dp);
}
/// θ times its derivative with respect to Σδp (1/Pa): the material's term of the matrix's Σθκ.
KOKKOS_INLINE_FUNCTION double materialVolumeLossSlope(const ice::Eos& eos, double p, double T, double theta,
                                                      double kappa, double sum_dp)
{
  if (sum_dp > 0 && cavitating(eos, p)) {
    if (boilsWithoutDensity(eos, p)) return 0.0;  // (materialVolumeLoss)
    const double rho = eos.density(p + sum_dp, T);
    return theta * (eos.density(p, T) / (rho * rho * eos.dp_drho(rho, T)));
  }
  return theta * kappa * volumeLossSlope(kappa * sum_dp);
}
// The pressure matrix's Σθκ is the slope of that loss at Σδp = 0. Where a gas is compressed
// strongly in one step the slope falls (by 1/(1 + x)²), and an outer iteration with the old one
// takes steps too short to converge: the matrix follows the slope once it has fallen by more than
// this share somewhere (then each outer iteration contracts by at least as much).
constexpr double kCompressibilityChange = 0.1;

// Next to a solid the fluids fill the room it leaves on a face (fluidFaceFractions) where the donor
// holds more than kSolidPresent of solids and its fluids' profiles more than kFillMinimum of the face.
constexpr double kSolidPresent = 1e-6;
constexpr double kFillMinimum = 1e-3;
// A deformable solid's share of a face's layer at which it lies fully on that side of the face
// (fluidFaceFractions): below it the face's cover ramps linearly down to none at a share of 0. A
// gate at 1e-6 flipped the cover of a resting elastic block's side faces between 0 and 1 as its side
// particles bulged past the face by a trace and back, and drove a circulation beside the block that
// grew (0.019 to 0.031 J/m from 0.1 to 0.42 s); a gate at 1e-2 let it decay but, being a jump, turned
// the round-off of another decomposition into a visible difference; the ramp is continuous.
constexpr double kFaceCoverRamp = 1e-2;
// The pressure of a cell that a deformable solid nearly fills is not a fluid's: the particles' boxes
// cover a cell of a shearing sand only to within ~1 % (extremes of several %), and the solid's bulk
// modulus turns that into pressure (3e5 Pa per 1 % at E = 5e7 Pa), which would act on the solid
// and on the fluid beside it. Where the fluids' share of the volume of fluids (their mass's at the
// reference pressure) and of the solids with `interior_pressure: reference` is below kPoreShareLow the solids and fluids feel the
// reference pressure there (the still fluid's, whose gradient is the buoyancy); above
// kPoreShareHigh the cell's own pressure; linear between. An elastic body (`cell`, its default)
// feels its cells' own pressure: a light body moves mostly by the pressure the pressure equation
// solved for with its motion in it, which inside it is far from hydrostatic (doc/mpmice.md).
// Measured (a submerged sand column, E = 5e7 Pa, 20 mm): with both bounds at 0.01 it failed between
// 0.24 and 0.28 s, at 0.1 and with these it held to 0.4 s; the pressure it had let act failed it
// at 0.14 s (doc/mpmice.md).
constexpr double kPoreShareLow = 0.05;
constexpr double kPoreShareHigh = 0.15;
// With solids, the outer iterations of the pressure equation up to this one take the face
// coefficient from the upwind side of each face velocity (Newton's step); later ones the larger of
// the two sides' shares (carriedFaceBeta).
constexpr int kNewtonOuterIterations = 4;

// Gives every material of a cell that holds a negligible share of its mass the mixture's
// (mass-weighted) velocity, so that its meaningless own value can neither limit the time step nor
// leak into advection when it arrives. rho(m): the material's mass density; u(m, d): its velocity
// component, a reference. Returns the cell's mass density.
template <int Dim, class Density, class Velocity>
KOKKOS_INLINE_FUNCTION double followMixtureVelocity(int n, const Density& rho, const Velocity& u)
{
  double mass = 0, momentum[3] = {0, 0, 0};
  for (int m = 0; m < n; ++m) {
    mass += rho(m);
    for (int d = 0; d < Dim; ++d) momentum[d] += rho(m) * u(m, d);
  }
  for (int m = 0; m < n; ++m)
    if (!(rho(m) > kNegligibleMassShare * mass))
      for (int d = 0; d < Dim; ++d) u(m, d) = momentum[d] / (mass + kTiny);
  return mass;
}

// A rigid material moves at its prescribed velocity whatever the forces on it: in the cell-centred
// exchange it enters with its specific volume divided (its mass density multiplied) by this factor,
// i.e. with an inertia so large that the other materials relax to its velocity and it keeps its
// own. (On faces it takes no part in the exchange; faceVelocities closes its share of the face.)
constexpr double kRigidInertia = 1e30;

// The exchange coefficients between every pair: the scene's K between fluids, its solid K between
// a fluid and a solid; zero between two solids (MPM's contact acts between them, with friction and
// free separation; a drag would make a sliding body stick to the bed).
// On faces a rigid body takes no part in the exchange: it closes the share of the face it covers
// instead (faceVelocities), so that fluid still flows through the open part of a cut cell's face.
ice::ExchangeCoefficients pairCoefficients(const IceSettings& settings, int materials, const MaterialRoles& roles,
                                           bool on_faces = false)
{
  ice::ExchangeCoefficients K = ice::ExchangeCoefficients::uniform(settings.exchange_coefficient);
  for (int m = 0; m < materials; ++m)
    for (int n = 0; n < materials; ++n) {
      if (m == n) continue;
      if ((roles.lagrangian[m] && roles.lagrangian[n]) || (on_faces && (roles.rigid[m] || roles.rigid[n])))
        K.set(m, n, 0.0);
      else if (roles.solid(m) != roles.solid(n))
        K.set(m, n, settings.solid_exchange_coefficient);
    }
  return K;
}

// The share of a face that the rigid materials close: each closes its larger share of the face's
// two sides (`share` of the face's upper cell: column 2 m just below the face, 2 m + 1 just above),
// summed and at most 1. The face velocities let no fluid through it, and the momentum phase's face
// pressure takes it as a wall.
template <class Shares>
KOKKOS_INLINE_FUNCTION double rigidClosedShare(int materials, const MaterialRoles& roles, const Shares& share,
                                               LocalOrdinal upper)
{
  double closed = 0;
  for (int m = 0; m < materials; ++m)
    if (roles.rigid[m])
      closed += math::max(math::min(1.0, share(upper, 2 * m)), math::min(1.0, share(upper, 2 * m + 1)));
  return math::min(1.0, closed);
}

// Whether the face between cells c and l (l < 0: none) is shut because either cell is closed
// (IceSolver::closedCells): nothing but the rigid bodies moves across it.
template <class Mask>
KOKKOS_INLINE_FUNCTION bool shutFace(const Mask& closed, LocalOrdinal c, LocalOrdinal l)
{
  return closed(c) || (l >= 0 && closed(l));
}

// Whether a solid is on the face between cells c and l (l < 0: none) by IceSolver::markSolidCells:
// either cell is marked. On a face without one that is open the fluids cross with the upwind
// cell's volume fraction, as without solids (fluidFaceFractions sets no fraction there, and its
// readers take the volume fractions themselves).
template <class Mask>
KOKKOS_INLINE_FUNCTION bool solidOnFace(const Mask& solid_cells, LocalOrdinal c, LocalOrdinal l)
{
  return solid_cells(c) || (l >= 0 && solid_cells(l));
}

// An owned cell that no solid reaches, nor any of its faces (IceSolver::markSolidCells: neither it
// nor a face neighbour is marked). Without the mask (a scene without solids never makes one) no
// cell is quiet.
template <class Mask>
KOKKOS_INLINE_FUNCTION bool quietCell(const Mask& quiet_cells, LocalOrdinal c)
{
  return quiet_cells.extent(0) > 0 && quiet_cells(c);
}

// What the materials on a face move with where one of them is absent on both sides (faceVelocities):
// the mean of the others' face velocities and specific volumes weighted by (θ_L + θ_R) / v_f, and
// β = Σ_m ½ (f_L + f_R) v_f with each material's shares f of the face. Materials `skip` says (the
// rigid ones) take no part.
struct FaceMixture {
  double velocity, specific_volume, beta;
};
template <class Skip>
KOKKOS_INLINE_FUNCTION FaceMixture faceMixture(int count, const ice::MaterialArray<double>& theta_left,
                                               const ice::MaterialArray<double>& theta_right,
                                               const ice::MaterialArray<double>& share_left,
                                               const ice::MaterialArray<double>& share_right,
                                               const ice::MaterialArray<double>& velocity,
                                               const ice::MaterialArray<double>& specific_volume, const Skip& skip)
{
  double b = 0, weight = 0, momentum = 0, volume = 0;
  for (int m = 0; m < count; ++m) {
    if (skip(m)) continue;
    const double w = (theta_left[m] + theta_right[m]) / specific_volume[m];
    weight += w;
    momentum += w * velocity[m];
    volume += w * specific_volume[m];
    b += 0.5 * (share_left[m] + share_right[m]) * specific_volume[m];
  }
  return {momentum / (weight + kTiny), weight > 0 ? volume / weight : b, b};
}

// A deformable solid's weight in the face exchange on a face between two cells that it fills: at
// least the lesser of its two volume fractions to the 8th power (1 where both are full, 0.92 at
// 0.99, half at 0.917, below 1e-4 at 0.3). Its share of the face is measured in thin layers beside
// the face (mpm.face_layer: h/128 in the seed scene), and where its particles' boxes have drawn
// apart at the face by more than a layer, a crack that the particles do not resolve, the share
// reads 0 inside the body: the fluid there, a trace in the gaps of the particles' coverage, was then
// tied to nothing on the face and took its own acceleration from the pressure difference that the
// solid's stress keeps across it, v ∇p with the air's v = 0.79 m^3/kg, up to 170 m/s in a sand that
// slides in air, 4.6 times its cell in a step, and the step was refused (939 of 3871 steps at
// 20 mm; doc/mpmice.md, "A slide that starts in air"). A front inside a cell has a small volume
// fraction on one side at least, so the fluid between the front and the face stays free of it.
KOKKOS_INLINE_FUNCTION double filledFaceWeight(double left, double right)
{
  const double lesser = math::max(0.0, math::min(1.0, math::min(left, right)));
  const double l2 = lesser * lesser, l4 = l2 * l2;
  return l4 * l4;
}

// Whether cell c is closed and every face neighbour it has is closed too (domain walls count as
// closed): such a cell has no row in the pressure matrix (IceSolver::updatePressureRows).
template <int Dim, class Mask, class Neighbours>
KOKKOS_INLINE_FUNCTION bool closedTwoDeep(const Mask& closed, const Neighbours& neighbours, LocalOrdinal c)
{
  if (!closed(c)) return false;
  for (int f = 0; f < 2 * Dim; ++f) {
    const LocalOrdinal n = neighbours(c, f);
    if (n >= 0 && !closed(n)) return false;
  }
  return true;
}

// Calls f(std::integral_constant<int, N>()): N = 2 for two materials (two fluids; the exchange then
// takes its two-material form) and N = 4 for four (two fluids and two solids, as the seed scene's
// water, air, sand and bed), so that the kernels' loops over materials have constant bounds, else
// N = 0 (the count is read at run time).
template <class F>
void forMaterialCount(int materials, F&& f)
{
  if (materials == 2)
    f(std::integral_constant<int, 2>());
  else if (materials == 4)
    f(std::integral_constant<int, 4>());
  else
    f(std::integral_constant<int, 0>());
}

}  // namespace

// The scene reader has checked every key of `cfdmpm.ice` (name, type, allowed values; the valid list
// in input/valid_parameters.cpp, also the source of doc/input.md) and filled in the defaults.
IceSettings IceSettings::fromScene(const Scene& scene)
{
  IceSettings s;
  const Teuchos::ParameterList& ice = scene.parameters->sublist("ice");
  s.enabled = ice.get<bool>("enabled");
  s.isothermal = ice.get<bool>("isothermal");
  s.heat_exchange_coefficient = ice.get<double>("heat_exchange_coefficient");
  s.pressure = ice.get<std::string>("pressure");
  s.exchange_coefficient = ice.get<double>("exchange_coefficient");
  s.solid_exchange_coefficient = ice.get<double>("solid_exchange_coefficient");
  s.max_outer_iterations = ice.get<int>("max_outer_iterations");
  s.outer_tolerance = ice.get<double>("outer_tolerance");
  // solver_tolerance 0: each solve's target follows from outer_tolerance; 1e-10 relative is then
  // only a floor (a solve that reaches it has nothing left to do for the outer test either).
  s.solver_tolerance_given = ice.get<double>("solver_tolerance") > 0;
  s.solver_tolerance = s.solver_tolerance_given ? ice.get<double>("solver_tolerance") : 1e-10;
  s.dt_growth = ice.get<double>("dt_growth");
  s.odd_even_filter = ice.get<double>("odd_even_filter");
  if (ice.isSublist("linear_solver")) s.linear_solver = ice.sublist("linear_solver");
  s.linear_solver.set("tolerance", s.solver_tolerance);
  // The pressure matrix changes little from step to step: between full MueLu set-ups (every 50
  // solves, or sooner when a reused hierarchy needs 1.5 times the iterations per decade of a fresh
  // one) only the finest level's smoother is recomputed ("RAP"). On the dam break at 280k cells
  // this costs a third of a set-up every 10 solves with RP reuse, at the same CG iteration count
  // (bench/bench_ice, doc/ice-pressure.md).
  if (!s.linear_solver.isParameter("reuse interval")) s.linear_solver.set("reuse interval", 50);
  if (!s.linear_solver.isParameter("reuse mode")) s.linear_solver.set("reuse mode", std::string("RAP"));
  if (!s.linear_solver.isParameter("reuse slowdown limit")) s.linear_solver.set("reuse slowdown limit", 1.5);
  // The correction solves of a step (outer iteration 2 on) apply the hierarchy as its first solve
  // refreshed it: their matrix differs from the first one by the upwind sides of a few faces (with
  // solids) or the slope of a volume law that fell, and the refresh of the finest level's smoother
  // cost more than it saved (the 10 mm seed scene, 1.94 outer iterations per step: 3 % of the step,
  // CG iterations 6.33 -> 6.29 per step; doc/mpmice.md, "Cost").
  if (!s.linear_solver.isParameter("refresh corrections")) s.linear_solver.set("refresh corrections", false);
  return s;
}

template <int Dim>
IceSolver<Dim>::IceSolver(const Scene& scene, std::shared_ptr<const Layout<Dim>> layout,
                          const std::vector<SolidProperties>& solids)
    : scene_(scene),
      settings_(IceSettings::fromScene(scene)),
      layout_(layout),
      materials_(int(scene.materials.size())),
      compressibility_(layout, Location::Cell, materials_, "compressibility"),
      mixture_compressibility_(layout, Location::Cell, 1, "mixture_compressibility"),
      equilibrium_pressure_(layout, Location::Cell, 1, "equilibrium_pressure"),
      delta_p_(layout, Location::Cell, 1, "delta_p"),
      sum_delta_p_(layout, Location::Cell, 1, "sum_delta_p"),
      rhs_(layout, Location::Cell, 1, "pressure_rhs"),
      outer_weight_(layout, Location::Cell, 1, "outer_weight"),
      face_velocity_(layout, materials_, "face_velocity"),
      corrected_face_velocity_(layout, materials_, "corrected_face_velocity"),
      face_specific_volume_(layout, materials_, "face_specific_volume"),
      face_beta_(layout, 1, "face_beta"),
      solid_face_share_(layout, solids.empty() ? 1 : 2 * materials_, "solid_face_share"),
      solid_face_cover_(layout, solids.empty() ? 1 : 2 * materials_, "solid_face_cover"),
      solid_volume_change_(layout, Location::Cell, materials_, "solid_volume_change"),
      solid_kinematic_velocity_(layout, solids.empty() ? 1 : materials_, "solid_kinematic_velocity"),
      fluid_face_fraction_(layout, solids.empty() ? 1 : 2 * materials_, "fluid_face_fraction"),
      new_velocity_(layout, Location::Cell, materials_ * Dim, "new_velocity"),
      filter_laplacian_(layout, Location::Cell, settings_.odd_even_filter > 0 ? materials_ * Dim : 1,
                        "odd-even filter second difference"),
      filter_increment_(layout, Location::Cell, settings_.odd_even_filter > 0 ? materials_ * Dim : 1,
                        "odd-even filter increment"),
      old_specific_volume_(layout, Location::Cell, materials_, "old_specific_volume"),
      solid_reference_pressure_(layout, Location::Cell, 1, "solid_reference_pressure"),
      solid_particle_volume_(layout, Location::Cell, solids.empty() ? 1 : materials_, "solid_particle_volume")
{
  closed_ = CellMask("closed cells", layout->overlapCells());  // zero: every cell open
  without_row_ = CellMask("cells without a pressure row", layout->overlapCells());
  solid_reference_pressure_.fill(scene.initial.pressure);
  if (!solids.empty()) {
    fluid_outflow_share_ = typename Advector<Dim>::CapView("fluid outflow share", layout->overlapCells(), 2 * Dim);
    Kokkos::deep_copy(fluid_outflow_share_, 1.0);
    fraction_faces_ = CellMask("faces with fluid fractions", layout->overlapCells());
  }
  if (materials_ > ice::kMaxMaterials)
    throw InputError("cfdmpm.materials: " + std::to_string(materials_) + " materials; at most " +
                     std::to_string(ice::kMaxMaterials) + " are allowed");
  for (int m = 0; m < materials_; ++m) {
    const MaterialSpec& material = scene.materials[m];
    names_.push_back(material.name);
    if (material.kind != "fluid") {
      const SolidProperties* solid = nullptr;
      for (const SolidProperties& s : solids)
        if (s.material == m) solid = &s;
      if (!solid)
        throw InputError("cfdmpm.materials." + material.name + ".kind: got 'solid'; the fluid step alone "
                         "runs fluid materials only (solids need the coupled step)");
      if (!settings_.isothermal)
        throw InputError("cfdmpm.ice.isothermal: got 'false' in a scene with the solid material '" + material.name +
                         "'; allowed: true. The coupled step does not carry the solids' temperature yet, so "
                         "their heat exchange with the fluids would be missing");
      roles_.lagrangian[m] = 1;
      roles_.rigid[m] = solid->rigid ? 1 : 0;
      roles_.reference_inside[m] = solid->reference_pressure_inside && !solid->rigid ? 1 : 0;
      any_rigid_ = any_rigid_ || solid->rigid;
      roles_.any_solid = true;
      bulk_modulus_[m] = solid->bulk_modulus;
      // The reference density and pressure are replaced per cell in the equilibration.
      eos_[m] = ice::SolidEos(solid->bulk_modulus, solid->density, scene.initial.pressure);
      viscosity_[m] = 0.0;
      specific_heat_[m] = 1.0;  // isothermal: not used
      conductivity_[m] = 0.0;
      continue;
    }
    eos_[m] = fluidEos(material);
    viscosity_[m] = material.parameters.get<double>("viscosity");
    specific_heat_[m] = material.parameters.get<double>("specific_heat");
    conductivity_[m] = material.parameters.get<double>("thermal_conductivity");
  }
  for (int m = 0; m < materials_; ++m) {
    if (roles_.lagrangian[m]) continue;
    const double rho = eos_[m].density(scene.initial.pressure, scene.initial.temperature);
    const double kappa = 1.0 / (rho * eos_[m].dp_drho(rho, scene.initial.temperature));
    if (std::isfinite(kappa) && kappa > 0 && (stiffest_compressibility_ == 0 || kappa < stiffest_compressibility_)) {
      stiffest_compressibility_ = kappa;
      stiffest_density_ = rho;
    }
  }
  for (int d = 0; d < 3; ++d) gravity_[d] = d < Dim ? scene.domain.gravity[d] : 0.0;
  for (int f = 0; f < 2 * Dim; ++f) wall_no_slip_[f] = 1, wall_temperature_[f] = -1;
  for (const BoundarySpec& b : scene.boundaries)
    for (int f = 0; f < 2 * Dim; ++f)
      if (b.face == faceName(f)) {
        wall_no_slip_[f] = b.velocity == "no_slip";
        if (b.temperature == "fixed") wall_temperature_[f] = b.temperature_value;
      }
  if (settings_.odd_even_filter > 0 && layout->ghostWidth() < 2)
    throw InputError("cfdmpm.domain.ghost_width: got " + std::to_string(layout->ghostWidth()) +
                     " with cfdmpm.ice.odd_even_filter " + std::to_string(settings_.odd_even_filter) +
                     "; the filter reads two cells across each face: allowed: 2 or more, or odd_even_filter: 0");
  pressure_solver_ = std::make_unique<PressureSolver<Dim>>(layout, settings_.linear_solver);
  for (const char* phase : kPhases) timers_[phase] = Teuchos::TimeMonitor::getNewCounter(std::string("ice: ") + phase);
  typename Advector<Dim>::Options advection;
  for (int m = 0; m < materials_; ++m)
    if (roles_.lagrangian[m]) advection.held_materials |= 1u << m;  // solids move with their particles
  advection.closed_cells = closed_;  // nothing flows into or out of them
  advector_ = std::make_unique<Advector<Dim>>(layout, materials_, advection);
}

template <int Dim>
IceSolver<Dim>::~IceSolver() = default;

template <int Dim>
void IceSolver<Dim>::setSolidReferencePressure(const Field<Dim>& pressure)
{
  Kokkos::deep_copy(solid_reference_pressure_.view(), pressure.view());
  solid_reference_pressure_.exchangeHalo();  // the momentum sources read it in the neighbours
}

// A cell that rigid bodies fill is a wall (closedCells). From the particles' volume fractions, which
// the coupled step sets in owned and ghost cells before the equilibration phase. A deformable solid
// in the cell (its boxes overlapping the body's: both shares are then scaled below 1 anyway) keeps it
// open, so that the exchange and the pressure reach it.
template <int Dim>
void IceSolver<Dim>::markClosedCells(const CellState<Dim>& state)
{
  if (!any_rigid_) return;
  const int n = materials_;
  const auto roles = roles_;
  const auto theta = state.volume_fraction.view();
  const auto rho = state.density.view();
  auto closed = closed_;
  const LocalOrdinal owned = layout_->ownedCells();
  long long local = 0;
  Kokkos::parallel_reduce(
      "ice::markClosedCells", Kokkos::RangePolicy<ExecutionSpace>(0, layout_->overlapCells()),
      KOKKOS_LAMBDA(const LocalOrdinal c, long long& count) {
        double rigid = 0;
        bool other_solid = false;
        for (int m = 0; m < n; ++m) {
          if (roles.rigid[m]) rigid += theta(c, m);
          else if (roles.lagrangian[m] && rho(c, m) > 0) other_solid = true;
        }
        const bool shut = rigid >= 1.0 - kClosedGap && !other_solid;
        closed(c) = shut ? 1 : 0;
        if (shut && c < owned) ++count;
      },
      local);
  Teuchos::reduceAll(*layout_->comm(), Teuchos::REDUCE_SUM, local, Teuchos::outArg(closed_count_));
}

// A closed cell's row of the pressure matrix has no neighbour (its faces are shut) and a zero
// right-hand side: it changes nothing, but CG's vector operations and products and MueLu's smoother
// and coarse levels pass over it (28 % of the rows of the seed scene at 5 mm). Such cells are left
// out of the matrix (PressureSolver::excludeCells), which builds its graph and preconditioner again
// each time the set changes; so the set is changed only when it must be or when that pays:
// * a cell without a row that has opened must get one (at once);
// * closed cells whose face neighbours are all closed (or walls) lose their rows when they are
//   kPressureRowsGain of the grid's cells (the initial bed at the first step; a moving body's wake).
// A closed cell next to an open one keeps its row: the cells at a rigid body's surface open and
// close as deformable solids' particle boxes touch them (the sand sliding on the seed scene's bed,
// a block resting on a rigid floor), and each change would rebuild the matrix; two cells deep
// nothing reaches.
template <int Dim>
void IceSolver<Dim>::updatePressureRows()
{
  const auto closed = closed_;
  const auto neighbours = layout_->cellNeighbours();
  auto without = without_row_;
  long long counts[2] = {0, 0}, global[2] = {0, 0};  // rows missing from open cells; deep closed cells with rows
  Kokkos::parallel_reduce(
      "ice::pressureRowsChanged", Kokkos::RangePolicy<ExecutionSpace>(0, layout_->ownedCells()),
      KOKKOS_LAMBDA(const LocalOrdinal c, long long& opened, long long& gain) {
        if (without(c) && !closed(c)) ++opened;
        if (!without(c) && closedTwoDeep<Dim>(closed, neighbours, c)) ++gain;
      },
      counts[0], counts[1]);
  Teuchos::reduceAll(*layout_->comm(), Teuchos::REDUCE_SUM, 2, counts, global);
  if (global[0] == 0 && double(global[1]) < kPressureRowsGain * double(layout_->grid().cellCount())) return;
  Kokkos::parallel_for(
      "ice::cellsWithoutPressureRow", Kokkos::RangePolicy<ExecutionSpace>(0, layout_->ownedCells()),
      KOKKOS_LAMBDA(const LocalOrdinal c) { without(c) = closedTwoDeep<Dim>(closed, neighbours, c) ? 1 : 0; });
  pressure_solver_->excludeCells(without_row_);
}

template <int Dim>
std::vector<long long> IceSolver<Dim>::closedCellsPerPatch() const
{
  const Grid<Dim>& grid = layout_->grid();
  const int patches = grid.patchCount();
  std::vector<long long> local(std::size_t(patches), 0), total(std::size_t(patches), 0);
  const auto closed = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), closed_);
  const auto ijk = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), layout_->cellIndex());
  for (LocalOrdinal c = 0; c < layout_->ownedCells(); ++c) {
    if (!closed(c)) continue;
    std::array<long long, 3> cell{0, 0, 0};
    for (int d = 0; d < Dim; ++d) cell[d] = ijk(c, d);
    ++local[std::size_t(grid.patchOfCell(cell))];
  }
  Teuchos::reduceAll(*layout_->comm(), Teuchos::REDUCE_SUM, patches, local.data(), total.data());
  return total;
}

// [3] Equilibration pressure: per cell, the pressure at which the materials' volumes fill it.
// A solid's equation of state is taken about its share of the cell on entry (θ_s from the particles'
// volumes) at the cell's reference pressure p_ref (solidReferencePressure: the fluids' hydrostatic
// pressure of the initial state), with the stiffness of its bulk modulus:
// ρ_micro(p) = (ρ_s/θ_s) / (1 − (p − p_ref)/K). A cell that a solid fills alone then has the pore
// pressure of still fluid at its place, and a solid that the particles pack into more (or less)
// than its cell pushes with K times the excess. (The pressure of the previous step in place of p_ref
// would integrate a persistent excess from step to step without bound.)
template <int Dim>
int IceSolver<Dim>::equilibrate(CellState<Dim>& state)
{
  const int n = materials_;
  const auto eos = eos_;
  const auto roles = roles_;
  const auto bulk = bulk_modulus_;
  auto rho = state.density.view();
  auto T = state.temperature.view();
  auto theta = state.volume_fraction.view();
  auto v = state.specific_volume.view();
  auto p = state.pressure.view();
  auto kappa = compressibility_.view();
  auto sum_kappa = mixture_compressibility_.view();
  const auto p_ref = solid_reference_pressure_.view();
  const double shift = reference_shift_;  // the fluids' uniform change since the initial state
  auto particle_volume = solid_particle_volume_.view();
  const auto closed = closed_;
  const auto ijk = layout_->cellIndex();
  const long long nx = layout_->grid().cells()[0], ny = layout_->grid().cells()[1];
  Kokkos::View<long long, MemorySpace> first("first failed cell");
  Kokkos::deep_copy(first, std::numeric_limits<long long>::max());
  int failures = 0;
  ice::MaterialArray<int> fluid{};
  int fluids = 0;
  for (int m = 0; m < n; ++m)
    if (!roles_.lagrangian[m]) fluid[fluids++] = m;
  const bool fluids_alone = fluids > 0 && solid_cells_.extent(0) > 0;
  const auto solid_cells = solid_cells_;
  const auto kernel = [&](auto count, auto with_solids) {
    constexpr int N = decltype(count)::value;
    constexpr bool kSolids = decltype(with_solids)::value;
    Kokkos::parallel_reduce(
        "ice::equilibrate", Kokkos::RangePolicy<ExecutionSpace>(0, layout_->ownedCells()),
        KOKKOS_LAMBDA(const LocalOrdinal c, int& failed) {
          if (closed(c)) return;  // a wall: its pressure and traces of fluid stay as they are
          const int nm = N > 0 ? N : n;
          ice::MaterialArray<double> mass_density{}, temperature{};
          for (int m = 0; m < nm; ++m) {
            mass_density[m] = rho(c, m) > 0 ? rho(c, m) : 0.0;
            temperature[m] = T(c, m);
          }
          ice::EquilibrationResult r;
          if constexpr (kSolids) {
            // A trace of a material (less than kNegligibleMassShare of the cell's mass: e.g. air
            // advected to a denormal density into a cell that sand and water fill) cannot fill the
            // room that the others leave; it takes no part in the root (it would drive p to 0).
            double cell_mass = 0;
            for (int m = 0; m < nm; ++m) cell_mass += mass_density[m];
            for (int m = 0; m < nm; ++m)
              if (!(mass_density[m] > kNegligibleMassShare * cell_mass)) mass_density[m] = 0.0;
            if (fluids_alone && !solid_cells(c)) {
              // No solid here (markSolidCells): the fluids' root alone, which is the general one to
              // the bit (materials without mass take no part in it, ice/equilibration.hpp), and the
              // solids' columns as the general path sets those of an absent solid.
              ice::MaterialArray<ice::Eos> fluid_eos;
              ice::MaterialArray<double> fluid_mass{}, fluid_temperature{};
              for (int a = 0; a < fluids; ++a) {
                const int m = fluid[a];
                fluid_eos[a] = eos[m];
                fluid_mass[a] = mass_density[m];
                fluid_temperature[a] = temperature[m];
              }
              const ice::EquilibrationResult f =
                  fluids == 2 ? ice::equilibrationPressure<2>(2, fluid_eos, fluid_mass, fluid_temperature, p(c, 0))
                              : ice::equilibrationPressure(fluids, fluid_eos, fluid_mass, fluid_temperature, p(c, 0));
              r.status = f.status;
              r.pressure = f.pressure;
              for (int m = 0; m < nm; ++m) r.volume_fraction[m] = 0.0;
              for (int a = 0; a < fluids; ++a) {
                const int m = fluid[a];
                r.volume_fraction[m] = f.volume_fraction[a];
                r.density[m] = f.density[a];
                r.compressibility[m] = f.compressibility[a];
              }
              for (int m = 0; m < nm; ++m) {
                if (!roles.lagrangian[m]) continue;
                const double rho_s = eos[m].density(f.pressure, temperature[m]);
                r.density[m] = rho_s;
                r.compressibility[m] = 1.0 / (rho_s * eos[m].sound_speed_squared(rho_s, temperature[m]));
                particle_volume(c, m) = 1.0 / eos[m].solid.reference_density;
              }
            } else {
              ice::MaterialArray<ice::Eos> local = eos;
              for (int m = 0; m < nm; ++m) {
                if (!roles.lagrangian[m]) continue;
                const bool present = mass_density[m] > 0 && theta(c, m) > 0;
                if (present) local[m] = ice::SolidEos(bulk[m], mass_density[m] / theta(c, m), p_ref(c, 0) + shift);
                // The particles' own specific volume, before the equilibration compresses the solid's
                // share (faceVelocities); where the solid is absent or a trace, its material's.
                particle_volume(c, m) = present ? theta(c, m) / mass_density[m] : 1.0 / eos[m].solid.reference_density;
              }
              r = ice::equilibrationPressure<N>(nm, local, mass_density, temperature, p(c, 0));
            }
          } else {
            r = ice::equilibrationPressure<N>(nm, eos, mass_density, temperature, p(c, 0));
          }
          if (!r.converged()) {
            ++failed;
            const long long gid = ijk(c, 0) + nx * (ijk(c, 1) + (Dim == 3 ? ny * ijk(c, 2) : 0));
            Kokkos::atomic_fetch_min(&first(), gid);
          }
          p(c, 0) = r.pressure;
          double sk = 0;
          for (int m = 0; m < nm; ++m) {
            theta(c, m) = r.volume_fraction[m];
            // A material without mass keeps its specific volume where the cell's pressure lies
            // outside what its equation of state can represent (a solid squeezed beyond p_ref + K).
            // A solid without mass takes its material's (particle_volume above): its equation of
            // state, ρ0 exp((p - p_ref)/K), has no bound below, and a soft solid absent from a pocket
            // of water stretched to -72 MPa (K = 1e5 Pa: the softer sand at 10 mm) got
            // 1e-306..5e-312 kg/m^3, a specific volume of 1e305 or infinity, which the cell's
            // momentum exchange turned into NaN at every Δt.
            // A boiling liquid without mass takes at most its vapour's specific volume at the
            // cavitation pressure: a trace of water in a sand the fluids see stretched below 0 Pa
            // (no root for it; its law's density is p ρ_c / p_c) kept a specific volume from near
            // 0 Pa, ~1e12 m³/kg, closed to θ = 1.28 after the advection, and the Lagrangian volume
            // change at p < 0 turned it to −4e69 (a Drucker-Prager column under water, 0.2 s).
            const double vapour = !(mass_density[m] > 0) && eos[m].kind == ice::EosKind::LinearWater
                                      ? eos[m].linear_water.cavitationDensity(temperature[m])
                                      : 0.0;  // ρ_c of a boiling liquid without mass
            if (kSolids && roles.lagrangian[m] && !(mass_density[m] > 0))
              v(c, m) = particle_volume(c, m);
            else if (vapour > 0 && !(r.density[m] > vapour))
              v(c, m) = 1.0 / vapour;
            else if (mass_density[m] > 0 || (r.density[m] > 0 && r.density[m] < DBL_MAX))
              v(c, m) = 1.0 / r.density[m];
            kappa(c, m) = r.compressibility[m] > 0 && r.compressibility[m] < DBL_MAX ? r.compressibility[m] : 0.0;
            sk += r.volume_fraction[m] * kappa(c, m);
          }
          sum_kappa(c, 0) = sk;
        },
        failures);
  };
  forMaterialCount(n, [&](auto count) {
    if (roles_.any_solid) kernel(count, std::true_type());
    else kernel(count, std::false_type());
  });
  for (Field<Dim>* f : {&state.volume_fraction, &state.specific_volume, &state.pressure, &compressibility_,
                        &mixture_compressibility_})
    f->exchangeHalo();
  if (roles_.any_solid) solid_particle_volume_.exchangeHalo();
  int total = 0;
  Teuchos::reduceAll(*layout_->comm(), Teuchos::REDUCE_SUM, failures, Teuchos::outArg(total));
  first_failed_equilibration_ = -1;
  if (total > 0) {
    long long local_first = 0;
    Kokkos::deep_copy(local_first, first);
    Teuchos::reduceAll(*layout_->comm(), Teuchos::REDUCE_MIN, local_first, Teuchos::outArg(first_failed_equilibration_));
  }
  return total;
}

// [4] Face velocities: the density-weighted average of the two cells, accelerated by the pressure
// difference (harmonic-mean specific volume) and gravity (Kashiwa; Uintah computeVel_FC), then the
// implicit face momentum exchange and the face specific volume the pressure equation uses (Uintah
// vel_FC_exchange). One pass per direction; stored on the lower face of each owned cell. Domain
// faces stay zero (walls).
template <int Dim>
void IceSolver<Dim>::faceVelocities(const CellState<Dim>& state, double dt)
{
  const int n = materials_;
  const auto neighbours = layout_->cellNeighbours();
  const auto rho = state.density.view();
  const auto u = state.velocity.view();
  const auto theta = state.volume_fraction.view();
  const auto v = state.specific_volume.view();
  const auto p = state.pressure.view();
  const auto roles = faceRoles();
  const auto K = pairCoefficients(settings_, n, roles, true);
  const bool with_solids = roles_.any_solid;
  const auto particle_volume = solid_particle_volume_.view();
  const auto closed = closed_;
  // On a face between two cells that no solid reaches (markSolidCells) the fluids take a short
  // path: their exchange among themselves alone (the solids have no weight in it there), and the
  // solids' columns, which the pressure phase does not read on such a face, set as the general path
  // sets those of a material absent on both sides. Bit for bit the general path's values: the
  // elimination visits the materials with mass in the same order either way (ice/exchange.hpp). Not
  // where the fluids' exchange among themselves is off but not with the solids (the general path
  // would then still solve), nor with fewer than two fluids.
  ice::MaterialArray<int> fluid{};
  int fluids = 0;
  bool fluids_coupled = false, any_coupled = false;
  for (int m = 0; m < n; ++m) {
    if (!roles.solid(m)) fluid[fluids++] = m;
    for (int o = 0; o < n; ++o) any_coupled = any_coupled || (o != m && K(m, o) != 0.0);
  }
  ice::ExchangeCoefficients K_fluids = ice::ExchangeCoefficients::uniform(0.0);
  for (int a = 0; a < fluids; ++a)
    for (int b = 0; b < fluids; ++b) {
      K_fluids.value[a][b] = K(fluid[a], fluid[b]);
      fluids_coupled = fluids_coupled || (a != b && K(fluid[a], fluid[b]) != 0.0);
    }
  const bool short_path = with_solids && fluids >= 2 && fluids_coupled == any_coupled && solid_cells_.extent(0) > 0;
  const auto solid_cells = solid_cells_;
  forMaterialCount(n, [&](auto count) {
    constexpr int N = decltype(count)::value;
    for (int d = 0; d < Dim; ++d) {
      auto uf = face_velocity_.direction(d).view();
      auto vf = face_specific_volume_.direction(d).view();
      auto beta = face_beta_.direction(d).view();
      const auto share = solid_face_share_.direction(d).view();
      auto kinematic = solid_kinematic_velocity_.direction(d).view();
      const double dt_per_h = dt / layout_->grid().spacing()[d];
      const double g = gravity_[d];
      Kokkos::parallel_for(
          "ice::faceVelocities", Kokkos::RangePolicy<ExecutionSpace>(0, layout_->ownedCells()),
          KOKKOS_LAMBDA(const LocalOrdinal c) {
            const int nm = N > 0 ? N : n;
            const LocalOrdinal l = neighbours(c, 2 * d);
            if (l < 0) {
              for (int m = 0; m < nm; ++m) uf(c, m) = 0.0, vf(c, m) = 0.0;
              beta(c, 0) = 0.0;
              return;
            }
            if (shutFace(closed, c, l)) {
              // A face of a cell that rigid bodies fill is closed to everything else (as below
              // with open = 0, which it is to within kClosedGap): the bodies keep their own face
              // velocity, nothing else crosses or takes a pressure correction.
              for (int m = 0; m < nm; ++m) {
                double velocity = 0;
                if (roles.rigid[m]) {
                  const double rl = rho(l, m), rr = rho(c, m);
                  velocity = (rl * u(l, m * Dim + d) + rr * u(c, m * Dim + d)) / (rl + rr + kTiny);
                }
                uf(c, m) = velocity, vf(c, m) = 0.0;
                if (with_solids && roles.lagrangian[m]) kinematic(c, m) = velocity;
              }
              beta(c, 0) = 0.0;
              return;
            }
            const double pressure_difference = p(c, 0) - p(l, 0);
            if (short_path && !solid_cells(c) && !solid_cells(l)) {
              ice::MaterialArray<double> tl{}, tr{}, vl{}, vr{}, vel{}, sv{};
              for (int a = 0; a < fluids; ++a) {
                const int m = fluid[a];
                tl[a] = theta(l, m), tr[a] = theta(c, m), vl[a] = v(l, m), vr[a] = v(c, m);
                const double rl = math::max(0.0, rho(l, m)), rr = math::max(0.0, rho(c, m));  // (below)
                const double mean = (rl * u(l, m * Dim + d) + rr * u(c, m * Dim + d)) / (rl + rr + kTiny);
                vel[a] = mean - dt_per_h * ice::harmonicMean(vl[a], vr[a]) * pressure_difference + dt * g;
              }
              if (fluids == 2) ice::exchangeMomentumFC<2>(2, dt, K_fluids, tl, tr, vl, vr, vel, sv);
              else ice::exchangeMomentumFC(fluids, dt, K_fluids, tl, tr, vl, vr, vel, sv);
              const FaceMixture mix = faceMixture(fluids, tl, tr, tl, tr, vel, sv, [](int) { return false; });
              const double mixture = mix.velocity, mixture_sv = mix.specific_volume;
              for (int a = 0; a < fluids; ++a) {
                const int m = fluid[a];
                const bool present = tl[a] + tr[a] > 2 * kNegligibleVolumeShare;
                uf(c, m) = present ? vel[a] : mixture;
                vf(c, m) = present ? sv[a] : mixture_sv;
              }
              for (int m = 0; m < nm; ++m) {
                if (roles.rigid[m]) {
                  uf(c, m) = vf(c, m) = kinematic(c, m) = 0.0;
                } else if (roles.lagrangian[m]) {
                  uf(c, m) = kinematic(c, m) = mixture;
                  vf(c, m) = mixture_sv;
                }
              }
              beta(c, 0) = mix.beta;
              return;
            }
            ice::MaterialArray<double> tl{}, tr{}, vl{}, vr{}, vel{}, sv{}, own{};
            for (int m = 0; m < nm; ++m) {
              tl[m] = theta(l, m), tr[m] = theta(c, m), vl[m] = v(l, m), vr[m] = v(c, m);
              // A solid's share of the face is its particles' volume there (solidFaceShares), so
              // its mass on the face is that share over the particles' specific volume. The
              // equilibration's may be far smaller: where the fluids overfill a cell the pressure
              // rises until they fit and a solid's share shrinks as exp(-(p - p_ref)/K) (SolidEos);
              // a trace of soft sand beside the bed, 2.4 MPa above p_ref with K = 1e5 Pa, then had
              // a specific volume of 1e-14 m^3/kg and outweighed the water on the face by 1e9, which
              // pinned the water to the sand's velocity and took its response to the pressure.
              if (with_solids && roles.lagrangian[m]) vl[m] = particle_volume(l, m), vr[m] = particle_volume(c, m);
              // A mass below zero (a trace's round-off) weighs nothing: with the other cell's equal
              // and positive, the mean divided by kTiny alone (2.5e85 m/s on a face of a slide in
              // air, which the exchange passed on to every material of the face).
              const double rl = math::max(0.0, rho(l, m)), rr = math::max(0.0, rho(c, m));
              const double ul = u(l, m * Dim + d), ur = u(c, m * Dim + d);
              const double mean = (rl * ul + rr * ur) / (rl + rr + kTiny);
              const double vbar = ice::harmonicMean(vl[m], vr[m]);
              // A solid's cell velocity already holds gravity and its stress (the MPM grid's v*).
              // A rigid body does not accelerate at all.
              vel[m] = roles.rigid[m]        ? mean
                       : roles.lagrangian[m] ? mean - dt_per_h * vbar * pressure_difference
                                             : mean - dt_per_h * vbar * pressure_difference + dt * g;
              own[m] = mean;  // a solid's face velocity from its particles' own motion
            }
            // On the face a material has the shares fl (just below it) and fr (just above): a
            // fluid its cells' volume fractions, a solid its share of the face (solidFaceShares). At
            // the front of a body inside a cell, the fluid between the front and the face is not in
            // the solid: it is not coupled to it there and leaves ahead of it.
            ice::MaterialArray<double> fl = tl, fr = tr;
            if (with_solids)
              for (int m = 0; m < nm; ++m)
                if (roles.lagrangian[m]) {
                  const double filled = roles.rigid[m] ? 0.0 : filledFaceWeight(tl[m], tr[m]);
                  fl[m] = math::max(filled, math::min(1.0, share(c, 2 * m)));
                  fr[m] = math::max(filled, math::min(1.0, share(c, 2 * m + 1)));
                }
            ice::exchangeMomentumFC<N>(nm, dt, K, fl, fr, vl, vr, vel, sv);
            // A material absent on both sides has no weight in the exchange and would keep its own
            // acceleration (for air inside water, v_air ∇p ~ 800 g); it moves with the mixture
            // instead: the mass-weighted mean of the present materials' face velocities, and the
            // same mean of their specific volumes for the pressure correction, so that it keeps
            // moving with them after every correction. (With the matrix's β = Σ θ_f v_f instead,
            // which is smaller where a rigid body or a solid takes part of the face, a trace of
            // air next to the bed's cut cells left at up to ~100 m/s when the equilibration
            // pressure jumped by MPa: the correction that cancels such a jump then differed
            // between the water and the trace, and the trace's outflux refused the step.)
            const FaceMixture mix = faceMixture(nm, tl, tr, fl, fr, vel, sv, [&](int m) { return roles.rigid[m] != 0; });
            // A rigid body closes its larger share of the face; the other materials flow through
            // the rest (a face inside it, or on its surface, is a wall). A moving body's share is
            // the time its box covers the face in the step (MpmSolver::particlesToCells), so the
            // fluids cross what it opens (behind it) or what it has not closed yet (ahead of it) at
            // its speed. It keeps its own face velocity and takes no pressure correction.
            const double open = with_solids ? 1.0 - rigidClosedShare(nm, roles, share, c) : 1.0;
            const double mixture = mix.velocity, mixture_sv = mix.specific_volume;
            for (int m = 0; m < nm; ++m) {
              if (roles.rigid[m]) {
                // Its own motion is all of it (solidVolumeChange holds it): the pressure equation's
                // flux of a solid is what the face velocity carries beyond the kinematic one, zero
                // here. (Left at zero, a moving body's whole motion across its faces was counted on
                // top of solidVolumeChange, twice the room behind it and twice the intrusion ahead.)
                uf(c, m) = vel[m], vf(c, m) = 0.0;
                if (with_solids) kinematic(c, m) = vel[m];
                continue;
              }
              const bool present = tl[m] + tr[m] > 2 * kNegligibleVolumeShare;
              if (with_solids && roles.lagrangian[m]) kinematic(c, m) = open * (present ? own[m] : mixture);
              uf(c, m) = open * (present ? vel[m] : mixture);
              vf(c, m) = open * (present ? sv[m] : mixture_sv);  // and follows the mixture's pressure correction
            }
            beta(c, 0) = open * mix.beta;
          });
    }
  });
  face_velocity_.exchangeHalo();
  face_specific_volume_.exchangeHalo();
  face_beta_.exchangeHalo();
  if (with_solids) solid_kinematic_velocity_.exchangeHalo();
}

// [3] The cells (owned and ghost) where a solid is or reaches: a solid's mass, volume fraction, or
// share or cover of one of the cell's lower faces (the faces stored at the cell) is not zero. On a
// face between two cells outside the mask no solid lies on either side, and the face velocities and
// the pressure phase's face kernels take the fluids' short path there, with the values their
// general path gives when every solid term is zero: the solids cover a few per cent of the seed
// scene's open cells, and the general path reads all of their columns on every face, which the
// kernels' memory traffic follows. A solid's face velocity there is the fluids' mixture's (as for
// any material absent on both sides), and no correction moves it (no share of the face carries it).
// The owned cells that are not marked and have no marked neighbour (quietCell) are marked too, for
// the kernels that visit a cell and its faces together. Marked once per step, at the equilibration
// (or by the coupled step as it sets the solids' columns, solidCellsToMark): no phase from there to
// the exchange moves a solid. (The fluids' fractions on a face between unmarked cells are the
// upwind cell's, as without solids, and blend into the slab profile's as a solid appears on the
// face or in a donor: switched on the marks, they changed with a solid's trace in a neighbouring
// cell, which round-off makes on one decomposition and not on another; fluidFaceFractions.)
template <int Dim>
void IceSolver<Dim>::markSolidCells(const CellState<Dim>& state)
{
  if (solid_cells_.extent(0) != std::size_t(layout_->overlapCells()))
    solid_cells_ = CellMask("solid cells", layout_->overlapCells());
  const int n = materials_;
  const auto roles = roles_;
  const auto theta = state.volume_fraction.view();
  const auto rho = state.density.view();
  typename Field<Dim>::ConstView share[3], cover[3];
  for (int d = 0; d < Dim; ++d) {
    share[d] = solid_face_share_.direction(d).view();
    cover[d] = solid_face_cover_.direction(d).view();
  }
  auto marked = solid_cells_;
  Kokkos::parallel_for(
      "ice::markSolidCells", Kokkos::RangePolicy<ExecutionSpace>(0, layout_->overlapCells()),
      KOKKOS_LAMBDA(const LocalOrdinal c) {
        bool solid = false;  // a NaN is not zero: it takes the general path, which reports it
        for (int m = 0; m < n && !solid; ++m) {
          if (!roles.solid(m)) continue;
          solid = theta(c, m) != 0.0 || rho(c, m) != 0.0;
          for (int d = 0; d < Dim && !solid; ++d)
            for (int side = 0; side < 2; ++side)
              solid = solid || share[d](c, 2 * m + side) != 0.0 || cover[d](c, 2 * m + side) != 0.0;
        }
        marked(c) = solid ? 1 : 0;
      });
  markQuietCells();
}

template <int Dim>
void IceSolver<Dim>::markQuietCells()
{
  const auto marked = solid_cells_;
  // Owned and ghost cells: a ghost's neighbours beyond the halo count as unmarked, but no face
  // between a ghost and such a cell is read (fluidFaceFractions' slabs).
  if (quiet_cells_.extent(0) != std::size_t(layout_->overlapCells()))
    quiet_cells_ = CellMask("quiet cells", layout_->overlapCells());
  auto quiet = quiet_cells_;
  const auto neighbours = layout_->cellNeighbours();
  Kokkos::parallel_for(
      "ice::markQuietCells", Kokkos::RangePolicy<ExecutionSpace>(0, layout_->overlapCells()),
      KOKKOS_LAMBDA(const LocalOrdinal c) {
        bool none = !marked(c);
        for (int f = 0; f < 2 * Dim; ++f) {
          const LocalOrdinal o = neighbours(c, f);
          none = none && !(o >= 0 && marked(o));
        }
        quiet(c) = none ? 1 : 0;
      });
}

// [5] With solids in the cells, the volume fraction of each fluid that crosses each face: the
// advection's own mass profile in the donor's slab (Advector::slabDensities, for the face velocities
// before the correction) times the donor's specific volume. The upwind cell's volume fraction would
// differ from what the advection moves wherever the fraction varies steeply (the water between a
// sand front and a face, the water of a cut cell), and next to a solid or the bed the mismatch has
// nowhere soft to go: 1e-5 of a cell in water and sand is a pressure error of ~100 kPa, where in
// water and air it is a few Pa. Fluids alone keep the upwind cell's fraction, and so do the faces
// where no solid is (it spares the slabs and the room of the faces that no solid reaches: the
// fractions and their two slab passes were ~3.5 s of the 10 mm seed scene's 22 s per 211 steps;
// doc/mpmice.md, "Cost").
template <int Dim>
void IceSolver<Dim>::fluidFaceFractions(const CellState<Dim>& state, double dt)
{
  // The slabs of the cells that neither hold nor border a solid are not read (below).
  const auto& slab = advector_->slabDensities(face_velocity_, dt, state.density, quiet_cells_);
  const auto v = state.specific_volume.view();
  const auto theta = state.volume_fraction.view();
  const auto rho = state.density.view();
  const auto u = state.velocity.view();
  const auto neighbours = layout_->cellNeighbours();
  const int n = materials_;
  const auto roles = roles_;
  const auto closed = closed_;
  auto leaves = fluid_outflow_share_;
  auto written = fraction_faces_;
  const auto solid_cells = solid_cells_;
  for (int d = 0; d < Dim; ++d) {
    auto out = fluid_face_fraction_.direction(d).view();
    const auto share = solid_face_share_.direction(d).view();
    const auto cover = solid_face_cover_.direction(d).view();
    const auto kinematic = solid_kinematic_velocity_.direction(d).view();
    const double dt_per_h = dt / layout_->grid().spacing()[d];
    Kokkos::parallel_for(
        "ice::fluidFaceFractions", Kokkos::RangePolicy<ExecutionSpace>(0, layout_->overlapCells()),
        KOKKOS_LAMBDA(const LocalOrdinal c) {
          const LocalOrdinal l = neighbours(c, 2 * d);
          const unsigned char bit = static_cast<unsigned char>(1u << d);
          if (shutFace(closed, c, l) || !solidOnFace(solid_cells, c, l)) {
            // Nothing crosses (faceVelocities), or no solid is on either side (markSolidCells):
            // the fluids cross with the upwind cell's fraction, which the readers take from the
            // volume fractions (solidOnFace), and all of each slab leaves in the advection. The
            // face is not written unless its share was set here before: most faces of a slide
            // have no solid, and writing their fractions twice per step was ~4 % of its step.
            if (written(c) & bit) {
              if (l >= 0) leaves(l, 2 * d + 1) = 1.0;
              leaves(c, 2 * d) = 1.0;
              written(c) &= static_cast<unsigned char>(~bit);
            }
            return;
          }
          written(c) |= bit;
          // A solid's columns of `out` stay as constructed, zero: nothing reads them (a solid's
          // flux takes its share of the face), and leaving them unwritten spares the kernel, which
          // memory bounds, a quarter of its streams.
          double fluid[2] = {0, 0}, rigid[2] = {0, 0}, deformable[2] = {0, 0}, swept[2] = {0, 0};
          double donor_solid[2] = {0, 0};  // the solids' volume fraction of each donor
          for (int m = 0; m < n; ++m) {
            if (!roles.solid(m)) continue;
            for (int side = 0; side < 2; ++side) {
              (roles.rigid[m] ? rigid : deformable)[side] += math::min(1.0, share(c, 2 * m + side));
              swept[side] += math::min(1.0, cover(c, 2 * m + side));
            }
            if (l >= 0) donor_solid[0] += theta(l, m);
            donor_solid[1] += theta(c, m);
          }
          // The advection's slab profile where a solid is on the face or in a donor; the upwind
          // cell's fraction where none is, blended in below kSolidPresent of the solids' largest
          // share, cover or volume fraction here, so that a solid's trace at round-off (which the
          // particles' sums leave on one decomposition and not on another) changes the fractions
          // by as little (doc/mpmice.md, "Cost").
          double presence = 0;
          for (int side = 0; side < 2; ++side)
            presence = math::max(presence, math::max(math::max(rigid[side], deformable[side]),
                                                     math::max(swept[side], donor_solid[side])));
          const double slab_weight = math::min(1.0, presence / kSolidPresent);
          double profile[2][ice::kMaxMaterials];  // each fluid's profile on the face, per donor side
          for (int m = 0; m < n; ++m) {
            if (roles.solid(m)) continue;
            // Donor below the face (its upper face 2 d + 1) and donor above (this cell's lower face).
            const double upwind[2] = {l >= 0 ? theta(l, m) : theta(c, m), theta(c, m)};
            const double slabs[2] = {l >= 0 ? slab(l, 2 * d + 1, m) * v(l, m) : theta(c, m), slab(c, 2 * d, m) * v(c, m)};
            for (int side = 0; side < 2; ++side) {
              profile[side][m] = slab_weight >= 1.0 ? slabs[side] : upwind[side] + slab_weight * (slabs[side] - upwind[side]);
              fluid[side] += profile[side][m];
            }
          }
          // The fluids cross a face in the room the solids leave there. A cell's linear profile
          // cannot hold the sharp edge of a solid inside the cell: above a sand surface it would
          // carry water down through a face that the sand covers (and trap it in the sand's cells,
          // where a share of 1e-3 is ~30 kPa of the sand's bulk modulus), so the fluids never take
          // more than the room. Where the donor holds a solid they take all of it, in proportion to
          // their profiles: ahead of a sand front inside a cell, all the water between the front
          // and the face leaves through the face (the profile put only 0.3-0.75 of it there, so that
          // the water left faster than the front by that factor, and the front cell's pressure
          // peak drove the water ahead). A donor whose fluids' profiles hold less than
          // kFillMinimum of the face keeps its profile (a nearly dry cell does not fill a face).
          // The room is what the face itself leaves open (doc/mpmice.md, "the fluids' room on a
          // face"). A deformable solid covers the face only where it lies on both sides of it, in
          // both layers (MpmSolver::particlesToCells), ramped in by the lesser layer's share up to
          // kFaceCoverRamp; a surface inside one layer has not reached the face, which is still all
          // fluid there.
          // Where it crosses the face its cover lies between two limits: a surface across the face
          // covers it by the mean of the two layers' shares, one along it just beyond it fills one
          // layer and covers the face whole; the fuller layer's share f weighs the second as f^8
          // (half at f = 0.92). Taken from the donor's layer alone, the room let the air above a
          // block falling through air cross the face below its top into the cells the block
          // filled, where it stayed (a donor the block fills on its side gave nothing), and made
          // the air beneath it leave through ever less of the face below: at the first crossing
          // the air reached 47-315 m/s, with no step refused. A rigid body's part of the face is
          // not in the room: faceVelocities closes it (below).
          // The layers see where a surface is, not where it goes within the step: behind the top of
          // a block falling through air the face it leaves stayed covered ~0.9 for the whole step
          // (its upper layer held 1e-2 of the block, the block moved three times as far), and the
          // air that had to follow the block into the room it left reached 23 m/s. So the face is
          // open wherever the solids' cover over the step as they would cross it from the donor's
          // side (solidFaceCovers) leaves it open; where that cover is the larger, the layers'
          // (continuous as a surface rests on a face) holds.
          double covered = 0;
          const double lesser = math::min(deformable[0], deformable[1]);
          if (lesser > 0) {
            const double across = 0.5 * (deformable[0] + deformable[1]);
            const double fuller = math::min(1.0, math::max(deformable[0], deformable[1]));
            const double along = fuller * fuller, along4 = along * along;
            const double reached = math::min(1.0, lesser / kFaceCoverRamp);
            covered = reached * (across + (fuller - across) * along4 * along4);
          }
          // The cover over the step is for a surface that crosses the face; one that slides along
          // it (the side of a body moving past the face) is where the layers say it is. Weighed by
          // the share of the deformable solids' velocity at the face that is normal to it, |v_d| /
          // |v| (the solids' momentum of both cells over their mass; 1 at rest). Taken whole on
          // every face, the cover opened the faces a rising 100 kg/m^3 disk slides along, and its
          // velocity swung at 16-18 ms (growth 5.6 against 2.7 weighed; doc/stability.md, (b)); on
          // the faces it crosses only, it mends the falling block's crossings as before.
          double across_motion = 1.0;
          if (swept[0] < rigid[0] + covered || swept[1] < rigid[1] + covered) {  // else the layers hold anyway
            double mass = 0, momentum[3] = {0, 0, 0};
            for (int m = 0; m < n; ++m) {
              if (!roles.deformable(m)) continue;
              for (int k = 0; k < 2; ++k) {
                const LocalOrdinal cell = k == 0 ? c : l;
                if (cell < 0) continue;
                const double r = rho(cell, m);
                mass += r;
                for (int e = 0; e < Dim; ++e) momentum[e] += r * u(cell, m * Dim + e);
              }
            }
            double speed2 = 0;
            for (int e = 0; e < Dim; ++e) speed2 += momentum[e] * momentum[e];
            if (mass > 0 && speed2 > 0) across_motion = math::abs(momentum[d]) / math::sqrt(speed2);
          }
          // The rigid bodies' part of the face is closed to every fluid in faceVelocities already:
          // its face velocities are the open part's times 1 − R (R: rigidClosedShare, the larger of
          // the two sides' shares), so the fractions here are of the open part. What else closes
          // the face on a donor's side (the deformable solids' cover, the cover over the step) is
          // taken out of that open part. Counted as a share of the whole face instead (the room
          // 1 − the donor's rigid share), the water of a cut cell left through a face of the bed's
          // staircase as (1 − R)² of the flow, the water above it entered as 1 − R: the fractions of
          // the two sides differed (0.5 and 1.0), the flux jumped where a slow flow along the
          // staircase turned in the pressure correction and left a residual for a second outer
          // iteration (doc/mpmice.md, "Cost"). Without a rigid body the room is 1 − closed, as it was.
          const double rigid_closed = rigidClosedShare(n, roles, share, c);
          const double open = 1.0 - rigid_closed;
          double keep[2];
          for (int side = 0; side < 2; ++side) {
            const double layers = rigid[side] + covered;
            const double closed = layers + across_motion * (math::min(layers, swept[side]) - layers);
            const double others = closed - rigid[side];  // closed by the deformable solids on this side
            const double room = !(open > 0.0) ? 0.0 : others < open ? math::min(1.0, 1.0 - others / open) : 0.0;
            const LocalOrdinal donor = side == 0 ? l : c;
            const bool fill = donor_solid[side] > kSolidPresent && fluid[side] > kFillMinimum;
            keep[side] = fluid[side] > 0 && (fill || fluid[side] > room) ? room / fluid[side] : 1.0;
            // Filling the room, a donor's fluids, which the face exchange ties to the solid there,
            // may not carry out more than the donor holds at the solid's speed across the face:
            // under the bottom of a falling block the air of the cell the block nearly fills (1e-3
            // of it) would have left through the whole open face below at the block's speed, three
            // times what the cell held, and the pressure equation slowed the block's face velocity
            // to fit (−7.5 kPa).
            if (fill) {
              double speed = 0, held = 0;  // the solids' fastest face velocity out of the donor
              for (int m = 0; m < n; ++m) {
                if (roles.lagrangian[m]) speed = math::max(speed, side == 0 ? kinematic(c, m) : -kinematic(c, m));
                else if (!roles.rigid[m]) held += theta(donor, m);
              }
              const double carried = speed * dt_per_h * fluid[side] * keep[side];
              if (carried > held) keep[side] *= held / carried;
            }
          }
          for (int m = 0; m < n; ++m)
            if (!roles.solid(m))
              for (int side = 0; side < 2; ++side) out(c, 2 * m + side) = profile[side][m] * keep[side];
          if (l >= 0) leaves(l, 2 * d + 1) = keep[0];
          leaves(c, 2 * d) = keep[1];
        });
  }
}

// [5] With solids in the cells, the pressure matrix's face coefficient β = Σ_m v_f,m θ_m with the
// volume fraction θ_m that each material's flux carries (pressureRightHandSide): a fluid's from
// fluidFaceFractions, a deformable solid's share of the face, none for a rigid body. The flux of
// material m through a face is w θ_m(side w comes from), with the fractions fixed for the step, so
// its derivative with respect to w is the share on the upwind side of w: β takes that side of the
// current face velocity (predicted before the first solve, corrected before the others), which
// makes each outer iteration a Newton step of the piecewise linear fluxes. Where the side is not
// known (w = 0), the larger of the two shares. On a face whose flow turns in a correction the
// step takes the new side's share, which is exact once the flow stays on that side; should the
// flows keep turning, from outer iteration kNewtonOuterIterations + 1 on every face takes the
// larger of its two shares, which never assumes less response than the flux has, so that the
// outer iterations contract (the rule used throughout before: by a factor ~0.44 per iteration on
// the seed scene, whose bed's staircase of cut cells has fluid shares 0.25 and 0.75 in alternate
// cells, where the matrix then took three times the response the flux had; doc/mpmice.md, "Cost").
template <int Dim>
void IceSolver<Dim>::carriedFaceBeta(const CellState<Dim>& state, int outer_iteration)
{
  const auto theta = state.volume_fraction.view();
  const int n = materials_;
  const auto neighbours = layout_->cellNeighbours();
  const auto roles = faceRoles();
  const bool upwind = outer_iteration <= kNewtonOuterIterations;
  // With the solids' volume from their particles the matrix leaves their faces out: the particles
  // make ~10 % of the face crossing the face form predicts (doc/mpmice.md), and a matrix without it
  // needs 4-6 outer iterations per step on the seed scene instead of 6-10.
  const bool solid_faces = !solid_volume_predictor_;
  const auto closed = closed_;
  const auto solid_cells = solid_cells_;
  for (int d = 0; d < Dim; ++d) {
    const auto vf = face_specific_volume_.direction(d).view();
    const auto fluid = fluid_face_fraction_.direction(d).view();
    const auto share = solid_face_share_.direction(d).view();
    const auto uf = face_velocity_.direction(d).view();
    auto beta = face_beta_.direction(d).view();
    Kokkos::parallel_for(
        "ice::carriedFaceBeta", Kokkos::RangePolicy<ExecutionSpace>(0, layout_->overlapCells()),
        KOKKOS_LAMBDA(const LocalOrdinal c) {
          const LocalOrdinal l = neighbours(c, 2 * d);
          if (l < 0) return;  // a wall, or a ghost's outer face: as faceVelocities left it
          if (shutFace(closed, c, l)) {  // (faceVelocities): no material takes a correction
            beta(c, 0) = 0.0;
            return;
          }
          double b = 0;
          const bool solid_share = solid_faces && solid_cells(c);  // else no solid's share (markSolidCells)
          const bool fractions = solidOnFace(solid_cells, c, l);  // else the upwind cells' (fluidFaceFractions)
          for (int m = 0; m < n; ++m) {
            if (roles.rigid[m]) continue;
            const bool solid = roles.lagrangian[m];
            if (solid && !solid_share) continue;
            const double below = solid ? math::min(1.0, share(c, 2 * m)) : fractions ? fluid(c, 2 * m) : theta(l, m);
            const double above = solid ? math::min(1.0, share(c, 2 * m + 1)) : fractions ? fluid(c, 2 * m + 1) : theta(c, m);
            const double w = uf(c, m);
            // The side rule of pressureRightHandSide's flux: below when w > 0, else above.
            const double carried = upwind && w != 0 ? (w > 0 ? below : above) : math::max(below, above);
            b += vf(c, m) * carried;
          }
          beta(c, 0) = b > 0 ? b : 0.0;
        });
  }
}

// [5] Right-hand side of the pressure equation, −Δt Σ_faces A Σ_m θ_upwind,m u_f,m · n_out
// − V Σ_m θ_m s(κ_m Σδp) (≈ V Σθκ Σδp; the outer-iteration residual form of Uintah's setupRHS),
// plus the solids' own change of volume V Σ_s Δθ_s (solidVolumeChange); returns the outer test's
// measure, max |rhs| / V over the cells, each weighed by how much softer than water it is (below).
// after_solve: first apply the solve's δp, in the same pass: Σδp += δp, p = p_eq + Σδp, and every
// face velocity u_f −= Δt v_f (δp_R − δp_L) / h (owned cells; the ghosts of p and Σδp are not read
// before the momentum phase refreshes p). Each cell corrects its lower faces into a second array and
// recomputes its upper faces from the old values (they belong to the upper neighbour, whose
// iteration may run at the same time); the arrays then swap and the ghosts are refreshed.
template <int Dim>
double IceSolver<Dim>::pressureRightHandSide(CellState<Dim>& state, double dt, bool after_solve)
{
  const int n = materials_;
  const auto neighbours = layout_->cellNeighbours();
  const auto theta = state.volume_fraction.view();
  const auto kappa = compressibility_.view();
  auto sum_dp = sum_delta_p_.view();
  const auto dp = delta_p_.view();
  auto p = state.pressure.view();
  const auto p_eq = equilibrium_pressure_.view();
  const auto T = state.temperature.view();
  const auto eos = eos_;
  auto rhs = rhs_.view();
  auto outer_weight = outer_weight_.view();
  const double volume = layout_->grid().cellVolume();
  // No fluid with a finite compressibility: every cell's volume residual as it is.
  const double stiffest = stiffest_compressibility_ > 0 ? stiffest_compressibility_ : INFINITY;
  const double stiffest_density = stiffest_density_;  // 0 without such a fluid: no density factor
  const auto mass_density = state.density.view();
  double area[3], dt_per_h[3];
  for (int d = 0; d < Dim; ++d) {
    const double h = layout_->grid().spacing()[d];
    area[d] = volume / h, dt_per_h[d] = dt / h;
  }
  typename Field<Dim>::ConstView uf[3], vf[3], share[3], fluid[3], kinematic[3];
  const auto solid_change_view = solid_volume_change_.view();
  typename Field<Dim>::View corrected[3];
  const auto roles = faceRoles();
  // The solids' volume change from their particles (setSolidVolumePredictor): no face terms.
  const bool solid_faces = !solid_volume_predictor_;
  const auto closed = closed_;
  const auto quiet_cells = quiet_cells_;
  const auto solid_cells = solid_cells_;
  for (int d = 0; d < Dim; ++d) {
    share[d] = solid_face_share_.direction(d).view();
    fluid[d] = fluid_face_fraction_.direction(d).view();
    kinematic[d] = solid_kinematic_velocity_.direction(d).view();
    uf[d] = face_velocity_.direction(d).view();
    vf[d] = face_specific_volume_.direction(d).view();
    corrected[d] = corrected_face_velocity_.direction(d).view();
  }
  double local_max = 0;
  const auto kernel = [&](auto count, auto correct) {
    constexpr int N = decltype(count)::value;
    constexpr bool kCorrect = decltype(correct)::value;
    Kokkos::parallel_reduce(
        "ice::pressureRhs", Kokkos::RangePolicy<ExecutionSpace>(0, layout_->ownedCells()),
        KOKKOS_LAMBDA(const LocalOrdinal c, double& worst) {
          const int nm = N > 0 ? N : n;
          if (closed(c)) {
            // A wall: no volume crosses its faces, its pressure stays. Its row of the matrix has
            // no neighbour (β = 0 on its faces) and a zero right-hand side; whatever δp the solve
            // leaves there moves no face (v_f = 0) and is not applied, and its weight leaves it
            // out of the stopping tests.
            if (kCorrect)
              for (int d = 0; d < Dim; ++d)
                for (int m = 0; m < nm; ++m) corrected[d](c, m) = uf[d](c, m);
            rhs(c, 0) = 0.0;
            outer_weight(c, 0) = 0.0;
            return;
          }
          if (kCorrect) {
            sum_dp(c, 0) += dp(c, 0);
            p(c, 0) = p_eq(c, 0) + sum_dp(c, 0);
          }
          const bool fluids_only = quietCell(quiet_cells, c);  // no solid on any face
          // Velocity of material m on the lower face of cell `upper` in direction d (below it:
          // cell `lower`), corrected with this iteration's δp when kCorrect.
          const auto faceVelocity = [&](int d, int m, LocalOrdinal upper, LocalOrdinal lower) {
            const double w = uf[d](upper, m);
            return kCorrect ? w - dt_per_h[d] * vf[d](upper, m) * (dp(upper, 0) - dp(lower, 0)) : w;
          };
          // Volume flux of material m through the lower face of cell `upper` (cell `lower` below
          // it) at face velocity w, per face area: a fluid's upwind volume fraction (with solids:
          // the advection's, fluidFaceFractions) times w; for a solid, the difference between what
          // w and the particles' own face velocity carry across with its upwind share of the face
          // (their own motion is in solidVolumeChange).
          const auto flux = [&](int d, int m, LocalOrdinal upper, LocalOrdinal lower, double w) {
            if (roles.lagrangian[m]) {
              if (!solid_faces) return 0.0;
              const auto crossing = [&](double velocity) {
                return velocity * math::min(1.0, share[d](upper, velocity > 0 ? 2 * m : 2 * m + 1));
              };
              return crossing(w) - crossing(kinematic[d](upper, m));
            }
            // With solids, fluidFaceFractions' fraction on a face that a solid is on (none where
            // the face is shut), else the upwind cell's, as without solids (solidOnFace).
            if (roles.any_solid && !fluids_only) {
              if (shutFace(closed, upper, lower)) return w * 0.0;
              if (solidOnFace(solid_cells, upper, lower)) return w * fluid[d](upper, w > 0 ? 2 * m : 2 * m + 1);
            }
            return w * (w > 0 ? theta(lower, m) : theta(upper, m));
          };
          double outflow = 0;  // Σ_faces A Σ_m θ_upwind u · n_out  (m^3/s)
          for (int d = 0; d < Dim; ++d) {
            const LocalOrdinal l = neighbours(c, 2 * d), r = neighbours(c, 2 * d + 1);
            for (int m = 0; m < nm; ++m) {
              if (fluids_only && (roles.rigid[m] || roles.lagrangian[m])) {
                if (kCorrect) corrected[d](c, m) = 0.0;  // (markSolidCells)
                continue;
              }
              if (roles.rigid[m]) {
                // Its face velocity is its own motion and takes no correction (v_f = 0,
                // faceVelocities): it carries nothing beyond solidVolumeChange.
                if (kCorrect) corrected[d](c, m) = uf[d](c, m);
                continue;
              }
              if (l >= 0) {  // lower face, outward normal −e_d
                const double w = faceVelocity(d, m, c, l);
                if (kCorrect) corrected[d](c, m) = w;
                outflow -= area[d] * flux(d, m, c, l, w);
              } else if (kCorrect) {
                corrected[d](c, m) = uf[d](c, m);  // a wall: stays zero
              }
              if (r >= 0) {  // upper face, stored on the upper neighbour
                const double w = faceVelocity(d, m, r, c);
                outflow += area[d] * flux(d, m, r, c, w);
              }
            }
          }
          double solid_change = 0;  // Σ_solids Δθ of the particles' own motion
          if (roles.any_solid && !fluids_only)
            for (int m = 0; m < nm; ++m)
              if (roles.lagrangian[m]) solid_change += solid_change_view(c, m);
          double compression = 0;  // Σ_m θ_m s(κ_m Σδp): the share of the cell the pressure change takes
          double softness = 0;     // its slope, Σ_m θ_m s'(κ_m Σδp), a boiling liquid's as the liquid's
          for (int m = 0; m < nm; ++m) {
            if (fluids_only && (roles.rigid[m] || roles.lagrangian[m])) continue;  // θ_m = 0
            compression += theta(c, m) * materialVolumeLoss(eos[m], p_eq(c, 0), T(c, m), kappa(c, m), sum_dp(c, 0));
            softness += cavitating(eos[m], p_eq(c, 0))
                            ? theta(c, m) * stiffest
                            : materialVolumeLossSlope(eos[m], p_eq(c, 0), T(c, m), theta(c, m), kappa(c, m), sum_dp(c, 0));
          }
          rhs(c, 0) = volume * solid_change - dt * outflow - volume * compression;
          // The outer test's measure: the volume residual weighed by how much softer than the
          // stiffest fluid the cell is, min(1, κ_stiffest / softness), and by how much lighter,
          // max(1, ρ_stiffest / ρ_c) with ρ_c = Σ_m ρ_m θ_m. A residual r leaves a pressure error
          // δp = r / softness for the next equilibration to take up, and δp moves the cell's
          // contents by Δt δp / (ρ_c h): the test bounds the pressure error by
          // outer_tolerance / κ_stiffest in the stiffest fluid (215 Pa at 1e-7 in water) and in
          // every cell as heavy or heavier (a cell of sand: κ ~1e-5 1/Pa at E = 1.5e5 Pa, where
          // the volume alone asked for 0.1-1000 Pa: the seed scene at 5 mm spent its third and
          // fourth outer iterations on them), and by that times ρ_c / ρ_stiffest in a lighter
          // cell, so that no cell's velocity error exceeds the stiffest fluid's (without the
          // density factor a gas of 0.1 kg/m^3 kept a 20 Pa error and moved at 4e-4 m/s over a
          // still surface). A boiling liquid counts as the liquid (its vapour's slope is not what
          // a surplus meets), and a cell stiffer than the stiffest fluid keeps its volume residual.
          double cell_density = 0;
          for (int m = 0; m < nm; ++m)
            if (!fluids_only || !(roles.rigid[m] || roles.lagrangian[m])) cell_density += mass_density(c, m);
          const double weight = (softness > stiffest ? stiffest / softness : 1.0) *
                                (cell_density > 0 && cell_density < stiffest_density ? stiffest_density / cell_density : 1.0);
          outer_weight(c, 0) = weight;
          // A value that is not finite counts as infinite (a NaN would lose every comparison and
          // vanish from the maximum), so that the outer iteration sees it and stops.
          const double a = Kokkos::Experimental::isfinite(rhs(c, 0)) ? weight * math::abs(rhs(c, 0)) : INFINITY;
          if (a > worst) worst = a;
        },
        Kokkos::Max<double>(local_max));
  };
  forMaterialCount(n, [&](auto count) {
    if (after_solve) kernel(count, std::true_type());
    else kernel(count, std::false_type());
  });
  if (after_solve) {
    face_velocity_.swapValues(corrected_face_velocity_);
    face_velocity_.exchangeHalo();
  }
  double global_max = 0;
  Teuchos::reduceAll(*layout_->comm(), Teuchos::REDUCE_MAX, local_max, Teuchos::outArg(global_max));
  return global_max / volume;  // max_c w_c |rhs_c| / V (the same as the largest quotient: V > 0)
}

// [5] The correction part of pressureRightHandSide(after_solve = true) alone, for a caller that
// computes the residual only later (the solids' volumes predicted from the corrected pressure):
// Σδp += δp, p = p_eq + Σδp, u_f −= Δt v_f (δp_R − δp_L) / h on every face of an owned cell but a
// rigid body's, a wall or a closed cell's. The same values as pressureRightHandSide's, bit for bit.
template <int Dim>
void IceSolver<Dim>::applyPressureCorrection(CellState<Dim>& state, double dt)
{
  const int n = materials_;
  const auto neighbours = layout_->cellNeighbours();
  auto sum_dp = sum_delta_p_.view();
  const auto dp = delta_p_.view();
  auto p = state.pressure.view();
  const auto p_eq = equilibrium_pressure_.view();
  double dt_per_h[3];
  for (int d = 0; d < Dim; ++d) dt_per_h[d] = dt / layout_->grid().spacing()[d];
  typename Field<Dim>::ConstView uf[3], vf[3];
  typename Field<Dim>::View corrected[3];
  for (int d = 0; d < Dim; ++d) {
    uf[d] = face_velocity_.direction(d).view();
    vf[d] = face_specific_volume_.direction(d).view();
    corrected[d] = corrected_face_velocity_.direction(d).view();
  }
  const auto roles = faceRoles();
  const auto closed = closed_;
  const auto quiet_cells = quiet_cells_;
  forMaterialCount(n, [&](auto count) {
    constexpr int N = decltype(count)::value;
    Kokkos::parallel_for(
        "ice::pressureCorrection", Kokkos::RangePolicy<ExecutionSpace>(0, layout_->ownedCells()),
        KOKKOS_LAMBDA(const LocalOrdinal c) {
          const int nm = N > 0 ? N : n;
          const bool wall_cell = closed(c);
          if (!wall_cell) {
            sum_dp(c, 0) += dp(c, 0);
            p(c, 0) = p_eq(c, 0) + sum_dp(c, 0);
          }
          if (quietCell(quiet_cells, c)) {  // as pressureRightHandSide: no solid's face velocity
            for (int d = 0; d < Dim; ++d) {
              const LocalOrdinal l = neighbours(c, 2 * d);
              const bool still = wall_cell || l < 0;
              const double jump = still ? 0.0 : dp(c, 0) - dp(l, 0);
              for (int m = 0; m < nm; ++m)
                corrected[d](c, m) = roles.rigid[m] || roles.lagrangian[m] ? 0.0
                                     : still ? uf[d](c, m)
                                             : uf[d](c, m) - dt_per_h[d] * vf[d](c, m) * jump;
            }
            return;
          }
          for (int d = 0; d < Dim; ++d) {
            const LocalOrdinal l = neighbours(c, 2 * d);
            for (int m = 0; m < nm; ++m) {
              const double w = uf[d](c, m);
              corrected[d](c, m) = wall_cell || roles.rigid[m] || l < 0 ? w : w - dt_per_h[d] * vf[d](c, m) * (dp(c, 0) - dp(l, 0));
            }
          }
        });
  });
  face_velocity_.swapValues(corrected_face_velocity_);
  face_velocity_.exchangeHalo();
}

// [6] Momentum sources and Lagrangian velocities. Face pressure p_f weighted by the summed fluid
// densities of the two cells (Uintah computePressFC); force on material m: −θ_m V ∇p_f, and on fluids
// Newtonian viscous stress (θ μ ∇²u per material) and gravity. Solids get the pressure force only:
// their stress and gravity act on the MPM grid, whose velocity their cell velocity already is. The
// Lagrangian specific volume follows the pressure change: v_L = v (1 − κ_m Σδp) (Uintah
// computeLagrangianSpecificVolume, isothermal). New velocities go to lagrangianVelocity().
template <int Dim>
void IceSolver<Dim>::momentumSourcePhase(CellState<Dim>& state, double dt)
{
  Teuchos::TimeMonitor phase(*timers_.at("momentum"));
  state.pressure.exchangeHalo();
  if (!settings_.isothermal) {
    Kokkos::deep_copy(old_specific_volume_.view(), state.specific_volume.view());
    state.temperature.exchangeHalo();
  }
  const int n = materials_;
  const auto neighbours = layout_->cellNeighbours();
  const auto theta = state.volume_fraction.view();
  const auto rho = state.density.view();
  const auto p = state.pressure.view();
  const auto kappa = compressibility_.view();
  const auto sum_dp = sum_delta_p_.view();
  const auto u = state.velocity.view();
  auto v = state.specific_volume.view();
  const auto p_ref_static = solid_reference_pressure_.view();
  const double shift = reference_shift_;
  const auto p_eq = equilibrium_pressure_.view();
  const auto T = state.temperature.view();
  const auto eos = eos_;
  const auto mu = viscosity_;
  const auto roles = momentumRoles();
  const bool with_solids = roles_.any_solid;
  typename Field<Dim>::ConstView share[3];
  for (int d = 0; d < Dim; ++d) share[d] = solid_face_share_.direction(d).view();
  double h[3], inverse_h2[3], g[3];
  int no_slip[6];
  for (int d = 0; d < Dim; ++d) {
    h[d] = layout_->grid().spacing()[d], g[d] = gravity_[d];
    inverse_h2[d] = 1.0 / (h[d] * h[d]);
  }
  for (int f = 0; f < 2 * Dim; ++f) no_slip[f] = wall_no_slip_[f];
  // New velocities go to a second field so that the viscous stencil reads old values only.
  auto un = new_velocity_.view();
  const auto is_closed = closed_;
  const auto quiet_cells = quiet_cells_;
  forMaterialCount(n, [&](auto count) {
    constexpr int N = decltype(count)::value;
    Kokkos::parallel_for(
        "ice::momentumSources", Kokkos::RangePolicy<ExecutionSpace>(0, layout_->ownedCells()),
        KOKKOS_LAMBDA(const LocalOrdinal c) {
          const int nm = N > 0 ? N : n;
          if (is_closed(c)) {  // a wall: no force acts on what it holds
            for (int k = 0; k < nm * Dim; ++k) un(c, k) = u(c, k);
            return;
          }
          LocalOrdinal neighbour[2 * Dim];
          for (int f = 0; f < 2 * Dim; ++f) neighbour[f] = neighbours(c, f);
          ice::MaterialArray<double> r{}, t{};
          for (int m = 0; m < nm; ++m) r[m] = rho(c, m), t[m] = theta(c, m);
          double grad_p[3] = {0, 0, 0};
          if (!with_solids) {
            double sum_rho_c = 0;
            for (int m = 0; m < nm; ++m) sum_rho_c += r[m];
            for (int d = 0; d < Dim; ++d) {
              double face_p[2];
              for (int side = 0; side < 2; ++side) {
                const LocalOrdinal o = neighbour[2 * d + side];
                if (o < 0) {
                  // Wall: the pressure's normal gradient is the hydrostatic one (dp/dn = ρ g·n), so
                  // a fluid at rest next to a wall feels no net force.
                  face_p[side] = p(c, 0) + (side == 0 ? -0.5 : 0.5) * h[d] * sum_rho_c * g[d];
                  continue;
                }
                double sum_rho_o = 0;
                for (int m = 0; m < nm; ++m) sum_rho_o += rho(o, m);
                face_p[side] = (p(o, 0) * sum_rho_c + p(c, 0) * sum_rho_o) / (sum_rho_c + sum_rho_o + kTiny);
              }
              grad_p[d] = (face_p[1] - face_p[0]) / h[d];
            }
          } else {
            // With solids the pressure is the pore fluid's: its profile follows the density of the
            // fluids per volume of fluid (a solid's weight rests on its own stress). Between two
            // cells that hold fluid the face pressure is weighted by these densities as above; where
            // a cell holds no fluid (a solid alone) the pressure is interpolated linearly (a
            // central difference), and extrapolated linearly to a wall.
            const auto fluidDensity = [&](LocalOrdinal cell) {
              double mass = 0, volume = 0;
              for (int m = 0; m < nm; ++m)
                if (!roles.lagrangian[m]) mass += rho(cell, m), volume += theta(cell, m);
              return mass > 0 && volume > 0 ? mass / volume : 0.0;
            };
            const double rho_c = fluidDensity(c);
            // The pressure that acts: the cell's own where its fluids set it, the reference where a
            // solid with `interior_pressure: reference` fills it (kPoreShareLow). The fluids' share
            // is the volume their mass takes at the reference pressure: a void that a dilating sand
            // opens holds a trace of fluid stretched to near vacuum, which is not pore fluid (counted
            // by its volume, its ~-1e5 Pa stopped a sand column collapsing in air after 17 mm
            // against the dry column's 90; test VoidInADilatingSandDoesNotPullOnIt, doc/mpmice.md).
            // Where no solid is in the cell or beside it (quietCell) the solids' columns are left
            // unread: their volume fractions and shares of the faces are zero there.
            const bool quiet = quietCell(quiet_cells, c);
            const auto p_ref = [&](LocalOrdinal cell, int) { return p_ref_static(cell, 0) + shift; };
            const auto acting = [&](LocalOrdinal cell) {
              double solid = 0;
              for (int m = 0; m < nm && !quiet; ++m)
                if (roles.reference_inside[m]) solid += theta(cell, m);
              // No such solid: the share below is 1, the cell's own pressure (in the same form).
              if (!(solid > 0)) return p_ref(cell, 0) + (p(cell, 0) - p_ref(cell, 0));
              double fluid = 0;
              for (int m = 0; m < nm; ++m)
                if (!roles.lagrangian[m] && rho(cell, m) > 0)
                  fluid += rho(cell, m) / eos[m].density(p_ref(cell, 0), T(cell, m));
              const double share = fluid / (fluid + solid);
              const double weight =
                  math::min(1.0, math::max(0.0, (share - kPoreShareLow) / (kPoreShareHigh - kPoreShareLow)));
              return p_ref(cell, 0) + weight * (p(cell, 0) - p_ref(cell, 0));
            };
            const double p_c = acting(c);
            for (int d = 0; d < Dim; ++d) {
              double face_p[2];
              bool extrapolate[2] = {false, false};
              for (int side = 0; side < 2; ++side) {
                const LocalOrdinal o = neighbour[2 * d + side];
                const double wall = p_c + (side == 0 ? -0.5 : 0.5) * h[d] * rho_c * g[d];
                // The share of the face a rigid body closes is a wall (faceVelocities lets no
                // fluid through it): the pressure of a cell the body fills, set by its trace of
                // fluid and the body's stiffness, does not reach the fluid beside it.
                const double closed = o < 0 || is_closed(o) ? 1.0
                                      : quiet             ? 0.0
                                                          : rigidClosedShare(nm, roles, share[d], side == 0 ? c : o);
                if (closed >= 1.0) {
                  face_p[side] = wall;
                  extrapolate[side] = !(rho_c > 0);
                  continue;
                }
                const double rho_o = fluidDensity(o), p_o = acting(o);
                const double across = rho_c > 0 && rho_o > 0 ? (p_o * rho_c + p_c * rho_o) / (rho_c + rho_o) : 0.5 * (p_o + p_c);
                face_p[side] = closed > 0 && rho_c > 0 ? closed * wall + (1.0 - closed) * across : across;
              }
              if (extrapolate[0] && !extrapolate[1]) face_p[0] = 2.0 * p_c - face_p[1];
              if (extrapolate[1] && !extrapolate[0]) face_p[1] = 2.0 * p_c - face_p[0];
              grad_p[d] = (face_p[1] - face_p[0]) / h[d];
            }
          }
          for (int m = 0; m < nm; ++m) {
            for (int k = 0; k < Dim; ++k) {
              const double uc = u(c, m * Dim + k);
              if (!(r[m] > 0) || roles.rigid[m]) {  // no mass of m here, or a rigid body: no force to apply
                un(c, m * Dim + k) = uc;
                continue;
              }
              if (roles.lagrangian[m]) {
                un(c, m * Dim + k) = uc + dt * (-t[m] * grad_p[k]) / r[m];
                continue;
              }
              // Viscous force per volume: θ_m μ_m ∇²u_k, so that the acceleration is ν_m ∇²u_k
              // whatever the material's share of the cell (a face-averaged θ would blow up where
              // θ_c -> 0). A no-slip wall holds u = 0 on the face, h/2 away.
              double laplacian = 0;
              for (int d = 0; d < Dim; ++d) {
                double difference = 0;
                for (int side = 0; side < 2; ++side) {
                  const int f = 2 * d + side;
                  const LocalOrdinal o = neighbour[f];
                  if (o >= 0) difference += u(o, m * Dim + k) - uc;
                  else if (no_slip[f] && k != d) difference -= 2.0 * uc;
                }
                laplacian += difference * inverse_h2[d];
              }
              const double force = -t[m] * grad_p[k] + mu[m] * t[m] * laplacian + r[m] * g[k];  // per volume
              un(c, m * Dim + k) = uc + dt * force / r[m];  // (not dt / ρ first: ρ can be subnormal)
            }
            v(c, m) = v(c, m) * (1.0 - materialVolumeLoss(eos[m], p_eq(c, 0), T(c, m), kappa(c, m), sum_dp(c, 0)));
          }
        });
  });
}

// [7] The fluids' cell velocities lose their odd-even part where they zigzag (`ice.odd_even_filter`,
// off by default; the slide's scene uses 0.25). On a collocated grid a velocity that alternates from cell to cell is invisible
// to the pressure: the face velocities average it away and the cell-centred pressure force (a central
// difference of face pressures) cannot act on it. Where a cell's pressure stands above its
// neighbours' (the cell at a sand front that the water must leave) the central difference pushes the
// next cell but not the one after, and the water ahead of the slide's front took up an odd-even
// pattern from the first steps (40 mm: u_x = 0.024, 0.007, 0.018, 0.006 m/s in successive columns
// at 0.01 s, 0.43, 0.01, 0.27, 0.00 at 0.1 s) that grew until the run failed, whatever the time
// step. The filter, u −= κ Σ_d δ_d⁴ u per step with δ_d the second difference in direction d,
// removes the share 16 κ (`odd_even_filter`) of the odd-even mode of each direction and
// (2 sin(π/N))⁴ κ of a wave of N cells: with 0.25, 1.5e-4 of a 20-cell wave per step, so that its
// effect on resolved flow vanishes as h⁴/Δt under refinement. A sixth-order filter (δ⁶, sharper)
// that removed a quarter or a third of the odd-even mode per step let the slide fail at 0.13 s as
// without a filter (the pattern at the front spans three to four cells, which δ⁶ spares), and so
// did δ⁴ removing 1/16. Written as fluxes of momentum between neighbours,
// m_i Δu_i = Σ_o F_io with F_io = −F_oi, it conserves each fluid's momentum; a face's weight is the
// smaller of the two cells' densities of the fluid (none across a free surface into cells the fluid
// does not fill, or at a wall).
template <int Dim>
void IceSolver<Dim>::filterOddEven(const CellState<Dim>& state)
{
  // The odd-even mode of one direction is an eigenvector of δ² with eigenvalue −4, of δ⁴ with 16.
  const double kappa = settings_.odd_even_filter / 16.0;
  if (!(kappa > 0)) return;
  // The fluids' velocity columns, in order: a solid's are not filtered (its level and increment
  // stay zero, and are neither written nor read).
  Kokkos::Array<int, ice::kMaxMaterials * 3> fluid_column{};
  int columns = 0;
  for (int m = 0; m < materials_; ++m)
    if (!roles_.solid(m))
      for (int k = 0; k < Dim; ++k) fluid_column[columns++] = m * Dim + k;
  const auto neighbours = layout_->cellNeighbours();
  const auto rho = state.density.view();
  const auto closed = closed_;
  auto un = new_velocity_.view();
  auto increment = filter_increment_.view();
  auto laplacian = filter_laplacian_.view();
  Kokkos::deep_copy(increment, 0.0);
  new_velocity_.exchangeHalo();
  for (int d = 0; d < Dim; ++d) {
    // Whether the velocity zigzags across the face between c and its neighbour on `side`: the three
    // differences of the four cells around it (c's other neighbour, c, o, o's other neighbour)
    // alternate in sign. A smooth flow turns at most once in four cells, so it passes untouched.
    const auto zigzag = KOKKOS_LAMBDA(const LocalOrdinal c, const int side, const int col)->bool
    {
      const LocalOrdinal o = neighbours(c, 2 * d + side);
      if (o < 0) return false;
      const LocalOrdinal before = neighbours(c, 2 * d + 1 - side), after = neighbours(o, 2 * d + side);
      if (before < 0 || after < 0) return false;
      const double d1 = un(c, col) - un(before, col), d2 = un(o, col) - un(c, col), d3 = un(after, col) - un(o, col);
      return d1 * d2 < 0 && d2 * d3 < 0;
    };
    // (B v)_c = Σ_o m_co (v_o − v_c) over the zigzag faces of c, with m_co = min(ρ_c, ρ_o) the
    // face's weight (the fluid's densities in the two cells): B is the weighted graph Laplacian of
    // those faces (symmetric, positive semi-definite, rows summing to zero).
    const auto weightedDifference = KOKKOS_LAMBDA(const LocalOrdinal c, const int col, const double rc,
                                                  const typename Field<Dim>::View& v)->double
    {
      double sum = 0;
      for (int side = 0; side < 2; ++side) {
        if (!zigzag(c, side, col)) continue;
        const LocalOrdinal o = neighbours(c, 2 * d + side);
        // A trace left by the advection can be below zero by round-off (a donor that gave all of
        // its mass); it weighs nothing (a negative weight larger than ρ_c blew the level of a
        // trace up to 1e28 m/s beside the softer sand at 10 mm).
        const double ro = math::max(0.0, rho(o, col / Dim));
        sum += math::min(rc, ro) * (v(o, col) - v(c, col));
      }
      return sum;
    };
    // The level δ² u per unit density, L = ρ⁻¹ B u.
    Kokkos::parallel_for(
        "ice::filterLaplacian", Kokkos::RangePolicy<ExecutionSpace>(0, layout_->ownedCells()),
        KOKKOS_LAMBDA(const LocalOrdinal c) {
          for (int i = 0; i < columns; ++i) {
            const int col = fluid_column[i], m = col / Dim;
            const double rc = rho(c, m);
            const bool filtered = rc > 0 && !closed(c);
            laplacian(c, col) = filtered ? weightedDifference(c, col, rc, un) / rc : 0.0;
          }
        });
    filter_laplacian_.exchangeHalo();
    // −κ δ_d⁴ u as momentum fluxes of the level between neighbours across the same faces:
    // ρ Δu = −κ B L = −κ B ρ⁻¹ B u, so the filter conserves momentum and never adds kinetic
    // energy: Σ ρ u·Δu = −κ |ρ^(−1/2) B u|² ≤ 0, whatever the densities and the faces chosen. (A
    // level over every face weighted by the densities' ratio, as first written, made the operator
    // unsymmetric where the fluid's density jumps, at a sand front, with no such bound.)
    Kokkos::parallel_for(
        "ice::filterFlux", Kokkos::RangePolicy<ExecutionSpace>(0, layout_->ownedCells()),
        KOKKOS_LAMBDA(const LocalOrdinal c) {
          for (int i = 0; i < columns; ++i) {
            const int col = fluid_column[i], m = col / Dim;
            const double rc = rho(c, m);
            if (!(rc > 0) || closed(c)) continue;
            increment(c, col) -= kappa * weightedDifference(c, col, rc, laplacian) / rc;
          }
        });
  }
  Kokkos::parallel_for(
      "ice::filterApply", Kokkos::RangePolicy<ExecutionSpace>(0, layout_->ownedCells()),
      KOKKOS_LAMBDA(const LocalOrdinal c) {
        for (int i = 0; i < columns; ++i) un(c, fluid_column[i]) += increment(c, fluid_column[i]);
      });
}

// [8] The implicit cell-centred momentum exchange (Uintah addExch_Vel_Temp_CC, momentum part) on the
// Lagrangian velocities, pointwise; a material with a negligible share of the mass then takes the
// mixture's velocity. A rigid material enters with an inertia that keeps its velocity (kRigidInertia).
// The exchanged velocities become the state's; then the energy, unless isothermal. Cells whose
// exchange is not finite are counted in the report (the caller stops the run).
template <int Dim>
void IceSolver<Dim>::exchangePhase(CellState<Dim>& state, double dt, IceStepReport& report)
{
  Teuchos::TimeMonitor phase(*timers_.at("exchange"));
  filterOddEven(state);
  const int n = materials_;
  const auto theta = state.volume_fraction.view();
  const auto rho = state.density.view();
  const auto v = state.specific_volume.view();
  const auto K = pairCoefficients(settings_, n, roles_);
  const auto roles = roles_;
  const auto ijk = layout_->cellIndex();
  const long long nx = layout_->grid().cells()[0], ny = layout_->grid().cells()[1];
  auto un = new_velocity_.view();
  const auto closed = closed_;
  // Failures are rare: counted with atomics (Kokkos 3.4 has no reduction over two reducers).
  Kokkos::View<int, MemorySpace> bad("exchange failures");
  Kokkos::View<long long, MemorySpace> first("first failed cell");
  Kokkos::deep_copy(first, std::numeric_limits<long long>::max());
  forMaterialCount(n, [&](auto count) {
    constexpr int N = decltype(count)::value;
    Kokkos::parallel_for(
        "ice::exchangeCC", Kokkos::RangePolicy<ExecutionSpace>(0, layout_->ownedCells()),
        KOKKOS_LAMBDA(const LocalOrdinal c) {
          if (closed(c)) return;  // a wall: its velocities stay
          const int nm = N > 0 ? N : n;
          ice::MaterialArray<double> r{}, t{}, s{}, weight{};  // weight: r, a rigid body's scaled up
          ice::MaterialArray<Kokkos::Array<double, Dim>> vel{};
          for (int m = 0; m < nm; ++m) {
            r[m] = rho(c, m), t[m] = theta(c, m), s[m] = v(c, m), weight[m] = r[m];
            if (roles.rigid[m]) weight[m] *= kRigidInertia, s[m] /= kRigidInertia;
            for (int d = 0; d < Dim; ++d) vel[m][d] = un(c, m * Dim + d);
          }
          const ice::ExchangeStatus status = ice::exchangeMomentumCC<Dim, N>(nm, dt, K, weight, t, s, vel);
          if (status != ice::ExchangeStatus::Ok) {
            Kokkos::atomic_add(&bad(), 1);
            const long long gid = ijk(c, 0) + nx * (ijk(c, 1) + (Dim == 3 ? ny * ijk(c, 2) : 0));
            Kokkos::atomic_fetch_min(&first(), gid);
          }
          followMixtureVelocity<Dim>(
              nm, [&](int m) { return r[m]; }, [&](int m, int d) -> double& { return vel[m][d]; });
          for (int m = 0; m < nm; ++m)
            for (int d = 0; d < Dim; ++d) un(c, m * Dim + d) = vel[m][d];
        });
  });
  int failures = 0, total = 0;
  long long local_first = 0, global_first = 0;
  Kokkos::deep_copy(failures, bad);
  Kokkos::deep_copy(local_first, first);
  Teuchos::reduceAll(*layout_->comm(), Teuchos::REDUCE_SUM, failures, Teuchos::outArg(total));
  if (total > 0) {
    Teuchos::reduceAll(*layout_->comm(), Teuchos::REDUCE_MIN, local_first, Teuchos::outArg(global_first));
    report.exchange_failures += total;
    if (report.first_failed_cell < 0 || global_first < report.first_failed_cell) report.first_failed_cell = global_first;
  }
  // The new velocities become the state's; their ghosts are refreshed by the next reader. The old
  // ones are work space from now on.
  state.velocity.swapValues(new_velocity_);
  if (!settings_.isothermal) energy(state, old_specific_volume_, dt);
}

// Energy (when not isothermal), per material with e = c_v T: the work of the pressure on the volume
// change, −p (v_L − v), Fourier conduction θ_m k_m ∇²T_m (fixed-temperature walls at h/2; other walls
// insulate), then the implicit heat exchange between the materials of a cell (Uintah
// addExch_Vel_Temp_CC, heat part). Conduction is explicit: its limit joins the time step.
template <int Dim>
void IceSolver<Dim>::energy(CellState<Dim>& state, const Field<Dim>& old_specific_volume, double dt)
{
  const int n = materials_;
  const auto neighbours = layout_->cellNeighbours();
  const auto theta = state.volume_fraction.view();
  const auto rho = state.density.view();
  const auto p = state.pressure.view();
  const auto v = state.specific_volume.view();
  const auto v_old = old_specific_volume.view();
  auto T = state.temperature.view();
  auto T_new = new_velocity_.view();  // work space: n <= n Dim columns
  const auto cv = specific_heat_;
  const auto k = conductivity_;
  const auto H = ice::ExchangeCoefficients::uniform(settings_.heat_exchange_coefficient);
  double h[3], wall_T[6];
  for (int d = 0; d < Dim; ++d) h[d] = layout_->grid().spacing()[d];
  for (int f = 0; f < 2 * Dim; ++f) wall_T[f] = wall_temperature_[f];
  Kokkos::parallel_for(
      "ice::energy", Kokkos::RangePolicy<ExecutionSpace>(0, layout_->ownedCells()),
      KOKKOS_LAMBDA(const LocalOrdinal c) {
        ice::MaterialArray<double> r{}, t{}, s{}, c_v{}, temperature{};
        for (int m = 0; m < n; ++m) {
          double conduction = 0;  // W/m^3
          for (int d = 0; d < Dim; ++d)
            for (int side = 0; side < 2; ++side) {
              const int f = 2 * d + side;
              const LocalOrdinal o = neighbours(c, f);
              if (o >= 0)
                conduction += k[m] * theta(c, m) * (T(o, m) - T(c, m)) / (h[d] * h[d]);
              else if (wall_T[f] >= 0)
                conduction += k[m] * theta(c, m) * 2.0 * (wall_T[f] - T(c, m)) / (h[d] * h[d]);
            }
          double Tm = T(c, m) - p(c, 0) * (v(c, m) - v_old(c, m)) / cv[m];
          if (rho(c, m) > 0) Tm += dt * conduction / (rho(c, m) * cv[m]);
          r[m] = rho(c, m), t[m] = theta(c, m), s[m] = v(c, m), c_v[m] = cv[m], temperature[m] = Tm;
        }
        ice::exchangeHeatCC(n, dt, H, r, t, s, c_v, temperature);
        for (int m = 0; m < n; ++m) T_new(c, m) = temperature[m];
      });
  Kokkos::parallel_for(
      "ice::copyTemperature", Kokkos::RangePolicy<ExecutionSpace>(0, layout_->ownedCells()),
      KOKKOS_LAMBDA(const LocalOrdinal c) {
        for (int m = 0; m < n; ++m) T(c, m) = T_new(c, m);
      });
}

template <int Dim>
IceStepReport IceSolver<Dim>::step(CellState<Dim>& state, double dt)
{
  IceStepReport report;
  Teuchos::TimeMonitor whole(*timers_.at("step"));
  equilibrationPhase(state, report);   // [3]
  faceVelocityPhase(state, dt);        // [4]
  pressurePhase(state, dt, report);    // [5]
  momentumSourcePhase(state, dt);      // [6]
  exchangePhase(state, dt, report);    // [8]
  advectionPhase(state, dt, report);   // [10]
  return report;
}

// [3] Equilibration pressure, volume fractions, specific volumes, compressibilities; the pressure
// correction starts from this pressure.
template <int Dim>
void IceSolver<Dim>::equilibrationPhase(CellState<Dim>& state, IceStepReport& report)
{
  Teuchos::TimeMonitor phase(*timers_.at("equilibration"));
  markClosedCells(state);
  if (roles_.any_solid) {
    // For this step's phases (none of them moves a solid).
    if (solid_cells_given_) markQuietCells();
    else markSolidCells(state);
    solid_cells_given_ = false;
    updateReferenceShift(state);
  }
  report.reference_shift = reference_shift_;
  Kokkos::deep_copy(delta_p_.view(), state.pressure.view());  // the previous step's pressure (δp is reset before use)
  report.equilibration_failures = equilibrate(state);
  report.first_failed_equilibration = first_failed_equilibration_;
  Kokkos::deep_copy(equilibrium_pressure_.view(), state.pressure.view());
  const auto before = delta_p_.view();
  const auto after = state.pressure.view();
  double jump = 0;
  Kokkos::parallel_reduce(
      "ice::equilibrationJump", Kokkos::RangePolicy<ExecutionSpace>(0, layout_->ownedCells()),
      KOKKOS_LAMBDA(const LocalOrdinal c, double& largest) {
        const double change = math::abs(after(c, 0) - before(c, 0));
        if (change > largest) largest = change;
      },
      Kokkos::Max<double>(jump));
  Teuchos::reduceAll(*layout_->comm(), Teuchos::REDUCE_MAX, jump, Teuchos::outArg(report.equilibration_jump));
}

// The solids' reference pressure follows the fluids' pressure where it changes everywhere alike: a
// closed box whose air a dilating sand compresses, or any scene whose fluids' pressure rises or falls
// as a whole. The shift is the volume mean of p − p_ref over the cells that hold fluids alone (no
// solid, not closed) at the start of the step; local departures (a flow's dynamic pressure, a wave)
// average out over the fluid. Without it a still fluid 520 Pa above its initial pressure (the air of
// a closed 0.4 x 0.15 m box after a sand column in it dilated by 2 %) acted on the sand's surface
// and not inside it, where the reference stayed: a confining pressure of 520 Pa on a column whose
// own weight makes ~2 kPa, which jammed its toe and stopped it at a third of the dry run-out
// (doc/mpmice.md, "The pressure that acts where a solid fills the cell").
template <int Dim>
void IceSolver<Dim>::updateReferenceShift(const CellState<Dim>& state)
{
  const int n = materials_;
  const auto roles = roles_;
  const auto theta = state.volume_fraction.view();
  const auto p = state.pressure.view();
  const auto p_ref = solid_reference_pressure_.view();
  const auto closed = closed_;
  double local[2] = {0, 0};  // Σ (p − p_ref), cells
  Kokkos::parallel_reduce(
      "ice::referenceShift", Kokkos::RangePolicy<ExecutionSpace>(0, layout_->ownedCells()),
      KOKKOS_LAMBDA(const LocalOrdinal c, double& sum, double& cells) {
        if (closed(c)) return;
        for (int m = 0; m < n; ++m)
          if (roles.lagrangian[m] && theta(c, m) > 0) return;
        sum += p(c, 0) - p_ref(c, 0);
        cells += 1.0;
      },
      local[0], local[1]);
  double global[2] = {0, 0};
  Teuchos::reduceAll(*layout_->comm(), Teuchos::REDUCE_SUM, 2, local, global);
  reference_shift_ = global[1] > 0 ? global[0] / global[1] : 0.0;
}

// [4] Face velocities and face exchange.
template <int Dim>
void IceSolver<Dim>::faceVelocityPhase(CellState<Dim>& state, double dt)
{
  Teuchos::TimeMonitor phase(*timers_.at("face velocities"));
  state.velocity.exchangeHalo();
  state.density.exchangeHalo();
  if (roles_.any_solid && solid_cells_.extent(0) == 0) markSolidCells(state);  // (equilibrationPhase marks them)
  faceVelocities(state, dt);
}

// [5] Pressure correction with outer iterations (implicit), or one explicit update.
template <int Dim>
void IceSolver<Dim>::pressurePhase(CellState<Dim>& state, double dt, IceStepReport& report)
{
  Teuchos::TimeMonitor phase(*timers_.at("pressure"));
  sum_delta_p_.fill(0.0);
  const bool implicit = settings_.pressure == "implicit";
  if (roles_.any_solid) {
    if (solid_cells_.extent(0) == 0) markSolidCells(state);  // (equilibrationPhase marks them)
    fluidFaceFractions(state, dt);
    carriedFaceBeta(state, 1);
  }
  if (implicit) {
    secantSlopeWhereBoiling(state);
    if (any_rigid_) updatePressureRows();
    pressure_solver_->assemble(mixture_compressibility_, face_beta_, dt);
  }
  const bool predicted = bool(solid_volume_predictor_) && roles_.any_solid && implicit;
  const bool refresh_fractions = roles_.any_solid && implicit;
  if (predicted) solid_volume_predictor_(state, dt);
  double residual = pressureRightHandSide(state, dt, false);
  // A right-hand side that is not finite stops the iteration at once; the caller names its cause.
  while (std::isfinite(residual) && residual > settings_.outer_tolerance &&
         report.outer_iterations < settings_.max_outer_iterations) {
    ++report.outer_iterations;
    if (implicit) {
      // From the second outer iteration on the matrix follows, with solids, the upwind sides of
      // the corrected face velocities, and the slope of the volume law where it has fallen.
      if (report.outer_iterations > 1) {
        const bool slope_fell = followCompressibility(state);
        if (roles_.any_solid) carriedFaceBeta(state, report.outer_iterations);
        if (roles_.any_solid || slope_fell) pressure_solver_->assemble(mixture_compressibility_, face_beta_, dt);
      }
      delta_p_.fill(0.0);
      // After this solve the right-hand side is the linear residual r plus the change of the
      // upwinded fluxes (the matrix uses mean face volume fractions). The outer test bounds
      // max_c w_c |rhs_c| / V (w_c: the cell's weight, pressureRightHandSide), so a linear
      // residual with max_c w_c |r_c| below half of outer_tolerance V (the solver tests the
      // weighted residual's largest entry) uses at most half of the outer test's allowance in every
      // cell and leaves the other half to the flux change; solving further only polishes digits
      // that the next right-hand side replaces, in a cell of sand or air most of all (its weight is
      // 1e-4 .. 1e-5; doc/ice-pressure.md). An explicit solver_tolerance is honoured as given, in
      // the 2-norm without weights (e.g. tight solves to compare decompositions).
      const double residual_target = settings_.solver_tolerance_given
                                         ? 0.0
                                         : 0.5 * settings_.outer_tolerance * layout_->grid().cellVolume();
      // The outer iteration's index is the solve's kind (PressureSolver::solve): a first solve and
      // a correction solve are not alike enough to judge a reused hierarchy by each other.
      const PressureSolveReport solve =
          pressure_solver_->solve(rhs_, delta_p_, residual_target, report.outer_iterations - 1, &outer_weight_);
      report.linear_iterations += solve.iterations;
      if (!solve.converged) {
        std::ostringstream message;
        message << std::scientific << std::setprecision(3)
                << "ice: the pressure correction's linear solve did not converge: relative residual "
                << solve.relative_residual << " after " << solve.iterations << " CG iterations, tolerance "
                << solve.tolerance;
        if (!solve.failure.empty()) message << " (" << solve.failure << ")";
        message << "; the largest volume imbalance it had to correct is at " << largestResidualCell(state);
        if (settings_.solver_tolerance_given && settings_.solver_tolerance < 1e-13)
          message << "; cfdmpm.ice.solver_tolerance below ~1e-13 can stall at round-off";
        throw StepFailure(message.str());
      }
    } else {
      // Explicit: δp = rhs / (V κ) (faces not coupled through the pressure Laplacian) and
      // p = p_eq + δp in one pass; no face correction, no further iteration.
      const auto rhs = rhs_.view();
      const auto sk = mixture_compressibility_.view();
      auto dp = delta_p_.view();
      auto sum = sum_delta_p_.view();
      auto p = state.pressure.view();
      const auto p_eq = equilibrium_pressure_.view();
      const double volume = layout_->grid().cellVolume();
      Kokkos::parallel_for(
          "ice::explicitPressure", Kokkos::RangePolicy<ExecutionSpace>(0, layout_->ownedCells()),
          KOKKOS_LAMBDA(const LocalOrdinal c) {
            dp(c, 0) = rhs(c, 0) / (volume * sk(c, 0));
            sum(c, 0) += dp(c, 0);
            p(c, 0) = p_eq(c, 0) + sum(c, 0);
          });
      residual = 0;
      break;
    }
    // p = p_eq + Σδp and the faces corrected with this iteration's δp, then the new residual
    // (with the solids' volumes predicted, only after the prediction below; after the first
    // correction of a scene with solids, only after the fractions' refresh below, which changes
    // the fluxes the residual counts: the correction alone, without its residual, before it).
    const bool refresh_now = refresh_fractions && report.outer_iterations == 1;
    if (predicted || refresh_now) applyPressureCorrection(state, dt);
    else residual = pressureRightHandSide(state, dt, true);
    if (refresh_now) {
      // The fluids' face fractions as the advection will take them: its slabs for the corrected
      // face velocities. Kept from the predicted velocities (before), the residual counted each
      // fluid's flux with a slab profile that the advection then did not use; where the water's
      // fraction is steep (beside a sand front, in the bed's cut cells) the difference is the
      // volume a cell misses, which the stiff water took as a pressure jump the next step: at 10 mm
      // and Courant number 0.4 median jumps of 7-18 MPa from 0.1 s and a failure at 0.444 s,
      // against 0.1-0.6 MPa with the fractions refreshed (doc/mpmice.md). Once, after the first
      // correction, which makes nearly all of the change: refreshed after the later ones too, the
      // jumps were the same, and since the fractions are not a smooth function of the velocities
      // (the room beside a solid, the limiter), the residual could then cycle between two states
      // (12 steps of 3000 stopped at 1e-3 after 20 iterations at 20 mm).
      fluidFaceFractions(state, dt);
      if (!predicted) residual = pressureRightHandSide(state, dt, false);
    }
    if (predicted) {
      // The solids' volumes as their particles make them with the corrected pressure.
      solid_volume_predictor_(state, dt);
      residual = pressureRightHandSide(state, dt, false);
    }
  }
  report.outer_residual = residual;
  report.converged = residual <= settings_.outer_tolerance || !implicit;
  if (!std::isfinite(residual)) {
    const auto rhs = rhs_.view();
    const auto ijk = layout_->cellIndex();
    const long long nx = layout_->grid().cells()[0], ny = layout_->grid().cells()[1];
    long long local = LLONG_MAX, global = LLONG_MAX;
    Kokkos::parallel_reduce(
        "ice::firstNonFiniteRhs", Kokkos::RangePolicy<ExecutionSpace>(0, layout_->ownedCells()),
        KOKKOS_LAMBDA(const LocalOrdinal c, long long& lowest) {
          if (Kokkos::Experimental::isfinite(rhs(c, 0))) return;
          const long long gid = ijk(c, 0) + nx * (ijk(c, 1) + (Dim == 3 ? ny * ijk(c, 2) : 0));
          if (gid < lowest) lowest = gid;
        },
        Kokkos::Min<long long>(local));
    Teuchos::reduceAll(*layout_->comm(), Teuchos::REDUCE_MIN, local, Teuchos::outArg(global));
    report.first_nonfinite_pressure_cell = global == LLONG_MAX ? -1 : global;
  }


}

// Water that boils at the equilibration pressure has the vapour's slope, 1/p (~1e-3 /Pa against
// the liquid's 4.7e-10), but only as long as its vapour lasts: the vapour is a share 1 − ρ/ρ_c of
// the cell (1e-4 .. 1e-2 in the slide), and once it is gone the liquid is stiff again. The first
// solve with the tangent takes such a cell for nearly as soft as a gas, raises its pressure by a
// few hundred Pa where the step needs ~1e5, and leaves up to half of the cell unmatched (the slide
// at 10 mm from 0.3 s on: 0.4-0.6 of a cell after every first solve), which a further outer
// iteration must take up. Where a fluid boils and the cell's pressure was higher at the end of the
// last step, the first matrix takes the secant of the volume law from the equilibration pressure
// to that pressure, the rise the step most likely makes; the later iterations follow the tangent
// at the pressure reached (followCompressibility). Other materials in the cell keep θ κ.
template <int Dim>
void IceSolver<Dim>::secantSlopeWhereBoiling(const CellState<Dim>& state)
{
  bool boils = false;
  for (int m = 0; m < materials_; ++m)
    boils = boils || (eos_[m].kind == ice::EosKind::LinearWater && eos_[m].linear_water.cavitation_pressure > 0);
  if (!boils) return;
  const int n = materials_;
  const auto theta = state.volume_fraction.view();
  const auto kappa = compressibility_.view();
  const auto p_eq = equilibrium_pressure_.view();
  const auto previous = delta_p_.view();  // the last step's pressure (equilibrationPhase)
  const auto T = state.temperature.view();
  const auto eos = eos_;
  auto sum_kappa = mixture_compressibility_.view();
  Kokkos::parallel_for(
      "ice::secantSlopeWhereBoiling", Kokkos::RangePolicy<ExecutionSpace>(0, layout_->ownedCells()),
      KOKKOS_LAMBDA(const LocalOrdinal c) {
        const double rise = previous(c, 0) - p_eq(c, 0);
        if (!(rise > 0)) return;
        bool boiling = false;
        for (int m = 0; m < n; ++m) boiling = boiling || (theta(c, m) > 0 && cavitating(eos[m], p_eq(c, 0)));
        if (!boiling) return;
        double sk = 0;
        for (int m = 0; m < n; ++m)
          sk += cavitating(eos[m], p_eq(c, 0))
                    ? theta(c, m) * materialVolumeLoss(eos[m], p_eq(c, 0), T(c, m), kappa(c, m), rise) / rise
                    : theta(c, m) * kappa(c, m);
        sum_kappa(c, 0) = sk;
      });
}

template <int Dim>
bool IceSolver<Dim>::followCompressibility(const CellState<Dim>& state)
{
  const int n = materials_;
  const auto theta = state.volume_fraction.view();
  const auto kappa = compressibility_.view();
  const auto sum_dp = sum_delta_p_.view();
  auto sum_kappa = mixture_compressibility_.view();
  const auto p_eq = equilibrium_pressure_.view();
  const auto T = state.temperature.view();
  const auto eos = eos_;
  const auto closed = closed_;
  const auto slope = KOKKOS_LAMBDA(const LocalOrdinal c) {
    double sk = 0;
    for (int m = 0; m < n; ++m)
      sk += materialVolumeLossSlope(eos[m], p_eq(c, 0), T(c, m), theta(c, m), kappa(c, m), sum_dp(c, 0));
    return sk;
  };
  int local = 0;
  Kokkos::parallel_reduce(
      "ice::compressibilityFallen", Kokkos::RangePolicy<ExecutionSpace>(0, layout_->ownedCells()),
      KOKKOS_LAMBDA(const LocalOrdinal c, int& fallen) {
        if (closed(c)) return;  // its pressure does not change
        if (slope(c) < (1.0 - kCompressibilityChange) * sum_kappa(c, 0)) fallen = 1;
      },
      Kokkos::Max<int>(local));
  int global = 0;
  Teuchos::reduceAll(*layout_->comm(), Teuchos::REDUCE_MAX, local, Teuchos::outArg(global));
  if (global == 0) return false;
  Kokkos::parallel_for(
      "ice::followCompressibility", Kokkos::RangePolicy<ExecutionSpace>(0, layout_->ownedCells()),
      KOKKOS_LAMBDA(const LocalOrdinal c) {
        if (!closed(c)) sum_kappa(c, 0) = slope(c);
      });
  return true;
}

namespace {
// Of a value per rank at one of its owned cells (`local`, at local index `loc`): the largest over
// the ranks (`global_value`) and the lowest global cell id among the ranks that hold it
// (`global_id`; LLONG_MAX if no rank has a cell); `id` is this rank's cell's global id if it holds
// the largest, else LLONG_MAX.
template <int Dim>
void largestOverRanks(const Layout<Dim>& layout, double local, LocalOrdinal loc, double& global_value, long long& id,
                      long long& global_id)
{
  Teuchos::reduceAll(*layout.comm(), Teuchos::REDUCE_MAX, local, Teuchos::outArg(global_value));
  id = LLONG_MAX;
  if (layout.ownedCells() > 0 && local == global_value) id = layout.ownedCellMap()->getGlobalElement(loc);
  global_id = LLONG_MAX;
  Teuchos::reduceAll(*layout.comm(), Teuchos::REDUCE_MIN, id, Teuchos::outArg(global_id));
}
}  // namespace

template <int Dim>
std::string IceSolver<Dim>::largestResidualCell(const CellState<Dim>& state) const
{
  const auto rhs = rhs_.view();
  const auto weight = outer_weight_.view();
  // A value that is not finite counts as the largest (as in the outer test).
  using Location = Kokkos::MaxLoc<double, LocalOrdinal>;
  typename Location::value_type local;
  Kokkos::parallel_reduce(
      "ice::largestResidualCell", Kokkos::RangePolicy<ExecutionSpace>(0, layout_->ownedCells()),
      KOKKOS_LAMBDA(const LocalOrdinal c, typename Location::value_type& best) {
        const double a = Kokkos::Experimental::isfinite(rhs(c, 0)) ? weight(c, 0) * math::abs(rhs(c, 0)) : INFINITY;
        if (a > best.val) best.val = a, best.loc = c;
      },
      Location(local));
  double global_value = 0;
  long long id = 0, global_id = 0;
  largestOverRanks(*layout_, local.val, local.loc, global_value, id, global_id);
  // The volume fractions travel from the rank that holds the cell (the others send zeros).
  const int n = materials_;
  std::vector<double> fractions(n, 0.0), global_fractions(n, 0.0);
  if (id == global_id && id != LLONG_MAX) {
    const auto theta = Kokkos::create_mirror_view_and_copy(
        Kokkos::HostSpace(), Kokkos::subview(state.volume_fraction.view(), local.loc, Kokkos::ALL));
    for (int m = 0; m < n; ++m) fractions[m] = theta(m);
  }
  Teuchos::reduceAll(*layout_->comm(), Teuchos::REDUCE_SUM, n, fractions.data(), global_fractions.data());
  if (global_id == LLONG_MAX) return "no cell (the grid has none)";
  std::ostringstream text;
  text << layout_->grid().cellName(global_id) << ", " << std::scientific << std::setprecision(3) << global_value / layout_->grid().cellVolume()
       << " of its volume (volume fractions:";
  for (int m = 0; m < n; ++m) text << " " << names_[m] << " " << global_fractions[m];
  text << ")";
  return text.str();
}

// [10] Advection of mass, velocity and specific volume of the fluids by the corrected face
// velocities. Solids are Lagrangian: their face velocities are zero here, so their cell columns do
// not move (the next step takes them from the particles again).
template <int Dim>
void IceSolver<Dim>::advectionPhase(CellState<Dim>& state, double dt, IceStepReport& report)
{
  Teuchos::TimeMonitor phase(*timers_.at("advection"));
  // The solids stay where their particles put them: the advector holds them (its held_materials,
  // set in the constructor) and reads none of their face velocities.
  std::vector<Field<Dim>*> carried{&state.velocity, &state.specific_volume};
  if (!settings_.isothermal) carried.push_back(&state.temperature);  // c_v T is the energy per mass
  // With solids, a trace of a fluid may leave its cell whole in a step (Advector::advect): e.g. air
  // in the gaps of a sand's particles at the sand's surface, which the pressure difference that the
  // sand's stress keeps across the face drives out at 17-570 m/s: a slide in air at 20 mm, with
  // filledFaceWeight, still had 172 steps undone, 166 of them for such a trace (1e-8 .. 1e-3 of its
  // cell) or for a cell without the fluid, whose face velocity moves nothing (doc/mpmice.md, "A
  // slide that starts in air").
  const typename Advector<Dim>::FractionView fractions =
      roles_.any_solid ? state.volume_fraction.view() : typename Advector<Dim>::FractionView();
  const AdvectionStatus advected =
      advector_->advect(face_velocity_, dt, state.density, carried, fluid_outflow_share_, fractions);
  report.max_outflux_fraction = advected.max_outflux_fraction;
  if (!advected.ok) {
    // The same on every rank: the status is reduced over all of them.
    std::ostringstream message;
    message << "ice: advection: the outflux of " << names_[advected.material] << " from "
            << layout_->grid().cellName(advected.cell) << " is " << advected.max_outflux_fraction << " of its volume in one step (at most 1)";
    throw StepFailure(message.str());
  }

  // Closure: θ = ρ v (the next equilibration restores Σθ = 1); a material without mass in a cell
  // takes the mixture's velocity and temperature there (advection leaves its own values undefined).
  {
    auto theta = state.volume_fraction.view();
    auto u = state.velocity.view();
    auto T = state.temperature.view();
    const auto rho = state.density.view();
    const auto v = state.specific_volume.view();
    const auto cv = specific_heat_;
    const auto closed = closed_;
    const int n = materials_;
    forMaterialCount(n, [&](auto count) {
      constexpr int N = decltype(count)::value;
      Kokkos::parallel_for(
          "ice::closeCells", Kokkos::RangePolicy<ExecutionSpace>(0, state.density.overlapCount()),
          KOKKOS_LAMBDA(const LocalOrdinal c) {
            if (closed(c)) return;  // nothing entered or left it
            const int nm = N > 0 ? N : n;
            for (int m = 0; m < nm; ++m) theta(c, m) = rho(c, m) * v(c, m);
            const double mass = followMixtureVelocity<Dim>(
                nm, [&](int m) { return rho(c, m); }, [&](int m, int d) -> double& { return u(c, m * Dim + d); });
            double heat = 0, capacity = 0;
            for (int m = 0; m < nm; ++m) heat += rho(c, m) * cv[m] * T(c, m), capacity += rho(c, m) * cv[m];
            if (capacity > 0)
              for (int m = 0; m < nm; ++m)
                if (!(rho(c, m) > kNegligibleMassShare * mass)) T(c, m) = heat / capacity;
          });
    });
  }
}

// Σ_k K_mk θ_k(c) over the materials k other than m (K: the cells' pairCoefficients).
template <class Fractions>
KOKKOS_INLINE_FUNCTION double exchangeTie(const Fractions& theta, const ice::ExchangeCoefficients& K, LocalOrdinal c,
                                          int m, int n)
{
  double tie = 0;
  for (int k = 0; k < n; ++k)
    if (k != m) tie += K(m, k) * theta(c, k);
  return tie;
}
// What material m in cell c limits stableTimeStep by (0 where it does not limit; it limits only where
// present, θ > 1e-6): its convective rate max_d |u_d| / h_d ...
template <int Dim, class Velocities, class Fractions>
KOKKOS_INLINE_FUNCTION double convectiveRate(const Velocities& u, const Fractions& theta, const double* inv_h,
                                             LocalOrdinal c, int m)
{
  if (theta(c, m) < 1e-6) return 0.0;
  double rate = 0;
  for (int d = 0; d < Dim; ++d) rate = math::max(rate, math::abs(u(c, m * Dim + d)) * inv_h[d]);
  return rate;
}
// ... and its specific volume v, whose μ v and k v / c_v set the viscous and conduction limits, except
// where the exchange holds it to the others of its cell within the step, Δt v Σ_n K_mn θ_n > 1
// (stableTimeStep).
template <class Fractions, class Volumes>
KOKKOS_INLINE_FUNCTION double diffusiveVolume(const Fractions& theta, const Volumes& v, double previous_dt,
                                              const ice::ExchangeCoefficients& K, LocalOrdinal c, int m, int n)
{
  if (theta(c, m) < 1e-6) return 0.0;
  if (previous_dt * v(c, m) * exchangeTie(theta, K, c, m, n) > 1.0) return 0.0;
  return v(c, m);
}

template <int Dim>
TimeStepLimit IceSolver<Dim>::stableTimeStep(const CellState<Dim>& state, double previous_dt) const
{
  // [11] Convective CFL: Δt ≤ CFL h / |u| per direction; viscous: Δt ≤ CFL h² / (2 Dim ν); conduction
  // likewise with the thermal diffusivity; per material, over cells where it is present (θ > 1e-6).
  const int n = materials_;
  const auto u = state.velocity.view();
  const auto theta = state.volume_fraction.view();
  const auto v = state.specific_volume.view();
  double h_min = DBL_MAX, inv_h[3];
  for (int d = 0; d < Dim; ++d) {
    h_min = std::min(h_min, layout_->grid().spacing()[d]);
    inv_h[d] = 1.0 / layout_->grid().spacing()[d];
  }
  const double cfl = scene_.time.cfl;
  std::vector<double> local(3 * n, DBL_MAX), global(3 * n);
  const auto K = pairCoefficients(settings_, n, roles_);
  for (int m = 0; m < n; ++m) {
    double rate = 0, max_nu = 0;
    Kokkos::parallel_reduce(
        "ice::stableTimeStep", Kokkos::RangePolicy<ExecutionSpace>(0, state.velocity.ownedCount()),
        KOKKOS_LAMBDA(const LocalOrdinal c, double& worst) {
          const double s = convectiveRate<Dim>(u, theta, inv_h, c, m);
          if (s > worst) worst = s;
        },
        Kokkos::Max<double>(rate));
    // A material that the exchange holds to the others of its cell within the step (β = Δt v_m
    // Σ_n K_mn θ_n above 1) does not limit the viscous step: its explicit viscous change is the force
    // θ μ ∇²u on it whatever its density, and the exchange gives it the mixture's velocity. (Air
    // expanded into a gap of the sand's cells, at tens of Pa, had ν = μ v ~ 0.1 m²/s and a viscous
    // step of 1e-6 s.) Σ_n θ_n over the other materials, not 1 − θ_m: a trace of boiling water
    // advected into a cell of sand at ~0 Pa (its specific volume ~1e12 m³/kg) closed to θ = 1.28
    // there until the next equilibration, 1 − θ_m was negative, and its viscous step of 9e-15 s
    // held the run at time.dt_min (a Drucker-Prager column collapsing under water, 0.191 s).
    Kokkos::parallel_reduce(
        "ice::viscousLimit", Kokkos::RangePolicy<ExecutionSpace>(0, state.velocity.ownedCount()),
        KOKKOS_LAMBDA(const LocalOrdinal c, double& worst) {
          const double volume = diffusiveVolume(theta, v, previous_dt, K, c, m, n);
          if (volume > worst) worst = volume;
        },
        Kokkos::Max<double>(max_nu));
    local[3 * m] = rate > 0 ? cfl / rate : DBL_MAX;
    const double nu = viscosity_[m] * max_nu;  // largest kinematic viscosity μ v
    local[3 * m + 1] = nu > 0 ? cfl * h_min * h_min / (2.0 * Dim * nu) : DBL_MAX;
    // Explicit conduction: thermal diffusivity k v / c_v, when the energy equation runs.
    const double alpha = settings_.isothermal ? 0.0 : conductivity_[m] * max_nu / specific_heat_[m];
    local[3 * m + 2] = alpha > 0 ? cfl * h_min * h_min / (2.0 * Dim * alpha) : DBL_MAX;
  }
  Teuchos::reduceAll(*layout_->comm(), Teuchos::REDUCE_MIN, 3 * n, local.data(), global.data());
  TimeStepLimit limit{scene_.time.dt_max, "dt_max"};
  static const char* const kinds[3] = {"convection(", "viscosity(", "conduction("};
  int limiting = -1;  // the material's 3 m + kind that sets the limit, if one does
  for (int m = 0; m < n; ++m)
    for (int kind = 0; kind < 3; ++kind)
      if (global[3 * m + kind] < limit.dt) {
        limit = {global[3 * m + kind], kinds[kind] + names_[m] + ")"};
        limiting = 3 * m + kind;
      }
  if (previous_dt > 0 && settings_.dt_growth * previous_dt < limit.dt) {
    limit = {settings_.dt_growth * previous_dt, "growth"};
    limiting = -1;
  }
  // Below time.dt_min the run cannot go on (the driver stops it): say which cell sets the limit.
  if (limit.dt < scene_.time.dt_min && limiting >= 0)
    limit.where = limitingCell(state, limiting / 3, limiting % 3, previous_dt);
  return limit;
}

// The owned cell (over all ranks, the lowest global id on a tie) where material m sets the limit of
// kind 0 (convection: largest |u_d| / h_d), 1 or 2 (viscosity, conduction: largest specific volume
// among the cells that limit), as stableTimeStep counts them; its name, the material's volume
// fraction, density and velocity there.
template <int Dim>
std::string IceSolver<Dim>::limitingCell(const CellState<Dim>& state, int m, int kind, double previous_dt) const
{
  const auto u = state.velocity.view();
  const auto theta = state.volume_fraction.view();
  const auto v = state.specific_volume.view();
  double inv_h[3];
  for (int d = 0; d < Dim; ++d) inv_h[d] = 1.0 / layout_->grid().spacing()[d];
  const int n = materials_;
  const auto K = pairCoefficients(settings_, n, roles_);
  using Location = Kokkos::MaxLoc<double, LocalOrdinal>;
  typename Location::value_type local;
  Kokkos::parallel_reduce(
      "ice::limitingCell", Kokkos::RangePolicy<ExecutionSpace>(0, layout_->ownedCells()),
      KOKKOS_LAMBDA(const LocalOrdinal c, typename Location::value_type& best) {
        const double a = kind == 0 ? convectiveRate<Dim>(u, theta, inv_h, c, m)
                                   : diffusiveVolume(theta, v, previous_dt, K, c, m, n);
        if (a > best.val) best.val = a, best.loc = c;
      },
      Location(local));
  double global_value = 0;
  long long id = 0, global_id = 0;
  largestOverRanks(*layout_, local.val, local.loc, global_value, id, global_id);
  if (global_id == LLONG_MAX) return "";
  // The values travel from the rank that holds the cell (the others send zeros).
  std::vector<double> values(2 + Dim, 0.0), global_values(2 + Dim, 0.0);
  if (id == global_id) {
    auto column = [&](const auto& view, int k) {
      return Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), Kokkos::subview(view, local.loc, k))();
    };
    values[0] = column(theta, m);
    values[1] = 1.0 / column(v, m);
    for (int d = 0; d < Dim; ++d) values[2 + d] = column(u, m * Dim + d);
  }
  Teuchos::reduceAll(*layout_->comm(), Teuchos::REDUCE_SUM, 2 + Dim, values.data(), global_values.data());
  std::ostringstream text;
  text << layout_->grid().cellName(global_id) << ", where " << names_[m] << " fills " << std::setprecision(3)
       << global_values[0] << " of the cell at " << global_values[1] << " kg/m^3 and moves at (";
  for (int d = 0; d < Dim; ++d) text << (d ? ", " : "") << global_values[2 + d];
  text << ") m/s";
  return text.str();
}

template <int Dim>
void IceSolver<Dim>::restartPreconditionerSchedule()
{
  if (pressure_solver_) pressure_solver_->requestPreconditionerRebuild();
}

template class IceSolver<2>;
template class IceSolver<3>;

}  // namespace cfdmpm
