#include "input/scene_checks.hpp"

#include "common/mpi_comm.hpp"
#include "grid/decomposition.hpp"
#include "grid/geometry.hpp"
#include "grid/grid.hpp"
#include "ice/eos.hpp"
#include "ice/ice_solver.hpp"
#include "ice/material_eos.hpp"
#include "ice/pressure_solver.hpp"
#include "input/parameter_rule.hpp"
#include "io/output_directory.hpp"
#include "mpm/solid_material.hpp"

#include <Teuchos_CommHelpers.hpp>

#include <unistd.h>

#include <algorithm>
#include <cfloat>
#include <climits>
#include <cmath>
#include <functional>

namespace cfdmpm {

namespace {

// The ICE step keeps materials down to this share of a cell's volume (ice_solver.cpp,
// kNegligibleVolumeShare); their compressibility times that share times the cell volume enters the
// pressure matrix's diagonal and must not underflow.
constexpr double kSmallestVolumeShare = 1e-12;
// Solid materials the MPM step handles at most (mpm_solver.cpp, kMaxMaterials).
constexpr int kMaxSolidMaterials = 8;
// Lattice columns counted per region at most: beyond this (a half-plane in a 3-D grid of ~10^9
// cells) the count would take seconds on every rank, so only emptiness is decided exactly.
constexpr double kMaxCountedColumns = 2e7;

std::string showPoint(const double* x, int dimension)
{
  std::string text = "[";
  for (int d = 0; d < dimension; ++d) text += (d ? ", " : "") + showNumber(x[d]);
  return text + "]";
}

std::string showList(const std::array<long long, 3>& values, int dimension)
{
  std::string text = "[";
  for (int d = 0; d < dimension; ++d) text += (d ? ", " : "") + std::to_string(values[d]);
  return text + "]";
}

/// The vertices as written; a long outline shortened to its first points and its count.
std::string showVertices(const std::vector<std::array<double, 2>>& vertices)
{
  const std::size_t shown = vertices.size() > 12 ? 4 : vertices.size();
  std::string text = "[";
  for (std::size_t k = 0; k < shown; ++k) text += (k ? ", " : "") + showPoint(vertices[k].data(), 2);
  if (shown < vertices.size()) text += ", ... (" + std::to_string(vertices.size()) + " points)";
  return text + "]";
}

/// Three significant digits, for estimates: 1.17e+15.
std::string roughly(double value)
{
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.3g", value);
  return buffer;
}

std::string bytesText(double bytes)
{
  const char* units[] = {"bytes", "kB", "MB", "GB", "TB", "PB", "EB"};
  int u = 0;
  while (bytes >= 1000 && u < 6) bytes /= 1000, ++u;
  return roughly(bytes) + " " + units[u];
}

/// Metres as text with a unit a person reads at once: 0.000625 m -> "0.625 mm".
std::string lengthText(double metres)
{
  if (metres < 0.1 && metres >= 1e-6) return roughly(metres * 1e3) + " mm";
  return roughly(metres) + " m";
}

// --- The sampling lattice ----------------------------------------------------------------------

/// The lattice points of one direction: `per_cell` per cell, at lower + c h + (a + 0.5) / n h,
/// the expression Grid::nodePosition and the samplers (MaterialRegions::sampleCell, seedParticles)
/// use, so that a point counted here is a point the run places.
struct Axis {
  double lower = 0, h = 1;
  long long cells = 1;
  int n = 1;

  long long size() const { return cells * n; }
  double at(long long k) const { return lower + double(k / n) * h + (double(k % n) + 0.5) / n * h; }
  /// The first index whose point is >= x (> x when `strictly`); size() if none.
  long long firstAbove(double x, bool strictly) const
  {
    long long low = 0, high = size();
    while (low < high) {
      const long long mid = low + (high - low) / 2;
      const bool above = strictly ? at(mid) > x : at(mid) >= x;
      if (above) high = mid;
      else low = mid + 1;
    }
    return low;
  }
  /// Points in [lo, hi].
  long long countIn(double lo, double hi) const
  {
    if (!(hi >= lo)) return 0;
    return std::max(0LL, firstAbove(hi, true) - firstAbove(lo, false));
  }
};

std::array<Axis, 3> lattice(const DomainSpec& domain, int per_cell)
{
  std::array<Axis, 3> axes;
  for (int d = 0; d < domain.dimension; ++d)
    axes[d] = Axis{domain.lower[d], (domain.upper[d] - domain.lower[d]) / double(domain.cells[d]), domain.cells[d],
                   per_cell};
  return axes;
}

/// Lattice points behind a half-plane: Dim-1 directions column by column, the last by bisection
/// (the test is monotone along it). The test is regionContains's.
double countHalfPlane(const RegionSpec& region, const std::array<Axis, 3>& axes, int dimension)
{
  const int last = dimension - 1;
  double columns = 1;
  for (int d = 0; d < last; ++d) columns *= double(axes[d].size());
  std::array<double, 3> x{0, 0, 0};
  auto inside = [&] { return regionContains(region, dimension, x); };

  if (columns > kMaxCountedColumns) {
    // Too many to count: only whether any point is behind. The plane's distance is linear, so
    // its smallest value over the lattice is at one of the lattice's corners.
    for (int corner = 0; corner < (1 << dimension); ++corner) {
      for (int d = 0; d < dimension; ++d) x[d] = axes[d].at((corner >> d & 1) ? axes[d].size() - 1 : 0);
      if (inside()) return -1;
    }
    return 0;
  }

  double count = 0;
  const long long nx = axes[0].size(), ny = dimension == 3 ? axes[1].size() : 1;
  const Axis& z = axes[last];
  for (long long i = 0; i < nx; ++i)
    for (long long j = 0; j < ny; ++j) {
      x[0] = axes[0].at(i);
      if (dimension == 3) x[1] = axes[1].at(j);
      auto behind = [&](long long k) {
        x[last] = z.at(k);
        return inside();
      };
      const double n = region.normal[last];
      if (n == 0) {
        count += behind(0) ? double(z.size()) : 0.0;
      } else {
        // n > 0: behind for small coordinates (true then false); n < 0: false then true.
        long long low = 0, high = z.size();
        while (low < high) {
          const long long mid = low + (high - low) / 2;
          if (behind(mid) == (n > 0)) low = mid + 1;
          else high = mid;
        }
        count += double(n > 0 ? low : z.size() - low);
      }
    }
  return count;
}

/// Lattice points inside a polygon (extruded over z in 3-D): per x-column of the lattice, the
/// heights where the outline crosses it, paired by the even-odd rule. Points on the outline itself
/// may be counted where the run's horizontal-ray test leaves them out, or the other way round.
double countPolygon(const RegionSpec& region, const std::array<Axis, 3>& axes, int dimension)
{
  const auto& v = region.vertices;
  double x_min = v[0][0], x_max = v[0][0];
  for (const auto& p : v) x_min = std::min(x_min, p[0]), x_max = std::max(x_max, p[0]);
  const long long first = axes[0].firstAbove(x_min, false), end = axes[0].firstAbove(x_max, true);
  if (double(end - first) > kMaxCountedColumns) return -1;
  double count = 0;
  std::vector<double> crossings;
  for (long long i = first; i < end; ++i) {
    const double x = axes[0].at(i);
    crossings.clear();
    for (std::size_t a = 0, b = v.size() - 1; a < v.size(); b = a++) {
      if ((v[a][0] > x) == (v[b][0] > x)) continue;
      crossings.push_back(v[a][1] + (x - v[a][0]) * (v[b][1] - v[a][1]) / (v[b][0] - v[a][0]));
    }
    std::sort(crossings.begin(), crossings.end());
    for (std::size_t c = 0; c + 1 < crossings.size(); c += 2)
      count += double(axes[1].countIn(crossings[c], crossings[c + 1]));
  }
  if (dimension == 3) count *= double(axes[2].size());
  return count;
}

double countRegion(const RegionSpec& region, const DomainSpec& domain, int per_cell)
{
  const std::array<Axis, 3> axes = lattice(domain, per_cell);
  if (region.shape == "box") {
    double count = 1;
    for (int d = 0; d < domain.dimension; ++d) count *= double(axes[d].countIn(region.lower[d], region.upper[d]));
    return count;
  }
  if (region.shape == "half_plane") return countHalfPlane(region, axes, domain.dimension);
  return countPolygon(region, axes, domain.dimension);
}

std::string describeShape(const RegionSpec& region, int dimension)
{
  if (region.shape == "box")
    return "the box from " + showPoint(region.lower.data(), dimension) + " to " + showPoint(region.upper.data(), dimension);
  if (region.shape == "polygon") return "the polygon " + showVertices(region.vertices);
  return "the half-plane behind the plane through " + showPoint(region.point.data(), dimension) + " with normal " +
         showPoint(region.normal.data(), dimension);
}

// --- Polygons ----------------------------------------------------------------------------------

using Point2 = std::array<double, 2>;

double cross(const Point2& o, const Point2& a, const Point2& b)
{
  return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]);
}

int sign(double value) { return (value > 0) - (value < 0); }

bool onSegment(const Point2& a, const Point2& b, const Point2& p)
{
  return std::min(a[0], b[0]) <= p[0] && p[0] <= std::max(a[0], b[0]) && std::min(a[1], b[1]) <= p[1] &&
         p[1] <= std::max(a[1], b[1]);
}

/// True when segments ab and cd share a point (crossing or touching).
bool segmentsMeet(const Point2& a, const Point2& b, const Point2& c, const Point2& d)
{
  const int d1 = sign(cross(c, d, a)), d2 = sign(cross(c, d, b)), d3 = sign(cross(a, b, c)), d4 = sign(cross(a, b, d));
  if (d1 * d2 < 0 && d3 * d4 < 0) return true;
  return (d1 == 0 && onSegment(c, d, a)) || (d2 == 0 && onSegment(c, d, b)) || (d3 == 0 && onSegment(a, b, c)) ||
         (d4 == 0 && onSegment(a, b, d));
}

/// A polygon must enclose an area and not cross itself: the run fills it by the even-odd rule, so
/// a figure eight fills both lobes and collinear points fill nothing. A point repeated in a row
/// (the first repeated at the end, say) is allowed.
void checkPolygon(const RegionSpec& region, const std::string& path)
{
  std::vector<Point2> v;
  std::vector<int> number;  // 1-based vertex number in the file
  for (std::size_t k = 0; k < region.vertices.size(); ++k) {
    if (!v.empty() && region.vertices[k] == v.back()) continue;
    v.push_back(region.vertices[k]);
    number.push_back(int(k) + 1);
  }
  while (v.size() > 1 && v.back() == v.front()) v.pop_back(), number.pop_back();
  const std::string key = path + ".vertices";
  const std::string value = showVertices(region.vertices);

  const std::string no_area =
      "the vertices enclose no area (they are collinear or repeat each other), so the region would place "
      "nothing; give at least 3 points around the outline";
  // Collinear: every vertex on the line from the first to the one farthest from it (to round-off of
  // that length squared).
  std::size_t far = 0;
  auto distance2 = [&](const Point2& p) { return (p[0] - v[0][0]) * (p[0] - v[0][0]) + (p[1] - v[0][1]) * (p[1] - v[0][1]); };
  for (std::size_t k = 1; k < v.size(); ++k)
    if (distance2(v[k]) > distance2(v[far])) far = k;
  bool collinear = true;
  for (const Point2& p : v) collinear = collinear && std::abs(cross(v[0], v[far], p)) <= 1e-12 * distance2(v[far]);
  if (v.size() < 3 || collinear) throw inputError(key, value, no_area);

  const std::size_t n = v.size();
  for (std::size_t i = 0; i < n; ++i) {
    const Point2 &a = v[i], &b = v[(i + 1) % n];
    // An edge that doubles back along the previous one.
    const Point2& before = v[(i + n - 1) % n];
    if (cross(before, a, b) == 0 && (a[0] - before[0]) * (b[0] - a[0]) + (a[1] - before[1]) * (b[1] - a[1]) < 0) {
      throw inputError(key, value,
                       "at vertex " + std::to_string(number[i]) + " " + showPoint(a.data(), 2) +
                           " the outline turns back along itself; the polygon must not cross or touch itself");
    }
    for (std::size_t j = i + 2; j < n; ++j) {
      if (i == 0 && j == n - 1) continue;  // the closing edge meets the first at vertex 1
      const Point2 &c = v[j], &d = v[(j + 1) % n];
      if (segmentsMeet(a, b, c, d)) {
        throw inputError(key, value,
                         "the edge from vertex " + std::to_string(number[i]) + " to " +
                             std::to_string(number[(i + 1) % n]) + " and the edge from vertex " +
                             std::to_string(number[j]) + " to " + std::to_string(number[(j + 1) % n]) +
                             " cross or touch; the polygon must not cross itself (it is filled by the even-odd "
                             "rule, so each lobe of a figure eight would be filled); list the vertices in order "
                             "around the outline, or use one region per lobe");
      }
    }
  }
  double area = 0, x_min = v[0][0], x_max = v[0][0], y_min = v[0][1], y_max = v[0][1];
  for (std::size_t a = 0, b = v.size() - 1; a < v.size(); b = a++) {
    area += v[b][0] * v[a][1] - v[a][0] * v[b][1];
    x_min = std::min(x_min, v[a][0]), x_max = std::max(x_max, v[a][0]);
    y_min = std::min(y_min, v[a][1]), y_max = std::max(y_max, v[a][1]);
  }
  area = std::abs(area) / 2;
  // Relative to the bounding box: a sliver whose area is round-off of the box's is a line.
  if (!(area > 1e-12 * (x_max - x_min) * (y_max - y_min)) || !(area > 0)) throw inputError(key, value, no_area);
}

// --- The grid's size -------------------------------------------------------------------------

void checkGridSize(const DomainSpec& domain)
{
  const int dim = domain.dimension;
  double cells = 1, patches = 1;
  for (int d = 0; d < dim; ++d) {
    cells *= double(domain.cells[d]);
    patches *= std::ceil(double(domain.cells[d]) / double(domain.patch_cells[d]));
  }
  // Patch ids are int (Grid::patchCount, METIS's idx_t).
  if (patches > double(INT_MAX)) {
    throw inputError("cfdmpm.domain.cells", showList(domain.cells, dim),
                     roughly(cells) + " cells make " + roughly(patches) + " patches of " +
                         showList(domain.patch_cells, dim) + " cells (domain.patch_cells), more than the " +
                         std::to_string(INT_MAX) + " patches a grid may have; use fewer cells or larger patches");
  }
}

// --- Derived quantities ----------------------------------------------------------------------

bool usable(double value) { return std::isfinite(value) && value > 0; }

/// The key whose value sets a fluid's stiffness, for messages.
std::string stiffnessKey(const MaterialSpec& material)
{
  const std::string type = material.parameters.sublist("equation_of_state").get<std::string>("type");
  return "cfdmpm.materials." + material.name + ".equation_of_state." + (type == "ideal_gas" ? "gamma" : "bulk_modulus");
}

std::string keyValue(const MaterialSpec& material, const std::string& key)
{
  const auto& eos = material.parameters.sublist("equation_of_state");
  const std::string name = key.substr(key.rfind('.') + 1);
  return eos.isParameter(name) ? showValue(eos.getEntry(name)) : "";
}

void checkFluidState(const MaterialSpec& material, const ice::Eos& eos, double p, double T, double cell_volume,
                     bool ice_runs, const std::string& key, const std::string& value, const std::string& where)
{
  const double rho = eos.density(p, T);
  const double c2 = usable(rho) ? eos.sound_speed_squared(rho, T) : NAN;
  const double kappa = 1.0 / (rho * c2);
  std::string problem;
  if (!usable(rho)) {
    problem = "the density of " + material.name + " at " + where + " is " + roughly(rho) + " kg/m^3";
  } else if (!usable(c2)) {
    problem = "the sound speed of " + material.name + " at " + where + " is " + roughly(std::sqrt(c2)) + " m/s";
  } else if (!usable(kappa) || (ice_runs && !(kappa * kSmallestVolumeShare * cell_volume >= DBL_MIN))) {
    problem = "the compressibility 1/(rho c^2) of " + material.name + " at " + where + " is " + roughly(kappa) +
              " 1/Pa (density " + roughly(rho) + " kg/m^3, sound speed " + roughly(std::sqrt(c2)) +
              " m/s), too small for the pressure equation: times the smallest volume share the fluid solver keeps "
              "(1e-12) and the cell volume (" + roughly(cell_volume) + ") it must stay above the smallest normal "
              "double, " + roughly(DBL_MIN);
  }
  if (!problem.empty()) throw inputError(key, value, problem + "; choose a smaller value");
}

void checkDerivedQuantities(const Scene& scene)
{
  const DomainSpec& domain = scene.domain;
  const int dim = domain.dimension;
  double h_min = INFINITY, cell_volume = 1, height = 0, g = 0;
  for (int d = 0; d < dim; ++d) {
    const double h = (domain.upper[d] - domain.lower[d]) / double(domain.cells[d]);
    h_min = std::min(h_min, h);
    cell_volume *= h;
    if (domain.gravity[d] != 0) height = std::max(height, domain.upper[d] - domain.lower[d]);
  }
  // hypot: the squares of a gravity near the largest double would overflow.
  g = std::hypot(domain.gravity[0], domain.gravity[1], dim == 3 ? domain.gravity[2] : 0.0);
  // The fluid step (and its pressure equation) runs unless ice.enabled is false, with or without
  // solids (mpmice/mpmice_step.cpp).
  const bool ice_runs = scene.parameters->sublist("ice").get<bool>("enabled");
  const std::string gravity_value = showPoint(domain.gravity.data(), dim);

  // Gravity: a body at rest must not fall more than a cell in the first step, dt_initial (the
  // step-0 time step is at most dt_initial), or no CFL-limited step can follow it.
  if (g * scene.time.dt_initial * scene.time.dt_initial > h_min) {
    const double fall_time = std::sqrt(h_min / g);
    if (fall_time < scene.time.dt_min) {
      throw inputError("cfdmpm.domain.gravity", gravity_value,
                       "a body at rest falls a cell (" + lengthText(h_min) + ") in " + roughly(fall_time) +
                           " s, less than time.dt_min (" + showNumber(scene.time.dt_min) +
                           " s), so no time step could follow it; the magnitude must be at most " +
                           roughly(h_min / (scene.time.dt_min * scene.time.dt_min)) + " m/s^2");
    }
    throw inputError("cfdmpm.time.dt_initial", showNumber(scene.time.dt_initial),
                     "gravity (" + roughly(g) + " m/s^2) moves a body at rest by g dt^2 = " +
                         roughly(g * scene.time.dt_initial * scene.time.dt_initial) +
                         " m in the first step, more than a cell (" + lengthText(h_min) + "); must be at most " +
                         roughly(fall_time) + " s");
  }

  // Fluids: density, sound speed and compressibility at their reference state (the equation of
  // state's own keys), at the initial pressure and temperature, and at the bottom of a hydrostatic
  // column (gravity's doing).
  double densest = 0;
  for (const MaterialSpec& material : scene.materials) {
    if (material.kind != "fluid") continue;
    const ice::Eos eos = fluidEos(material);
    const auto& list = material.parameters.sublist("equation_of_state");
    if (list.isParameter("reference_pressure") && list.isParameter("reference_temperature")) {
      const std::string key = stiffnessKey(material);
      checkFluidState(material, eos, list.get<double>("reference_pressure"), list.get<double>("reference_temperature"),
                      cell_volume, ice_runs, key, keyValue(material, key), "its reference pressure and temperature");
    }
    const double p = scene.initial.pressure, T = scene.initial.temperature;
    checkFluidState(material, eos, p, T, cell_volume, ice_runs, "cfdmpm.initial_state.pressure", showNumber(p),
                    "the initial pressure " + showNumber(p) + " Pa and temperature " + showNumber(T) + " K");
    densest = std::max(densest, eos.density(p, T));
  }
  for (const MaterialSpec& material : scene.materials)
    if (material.kind == "solid") densest = std::max(densest, material.parameters.get<double>("density"));
  if (scene.initial.hydrostatic && g > 0) {
    // The column's weight with the densest material throughout: an upper bound of the bottom pressure.
    const double bottom = scene.initial.pressure + densest * g * height;
    for (const MaterialSpec& material : scene.materials) {
      if (material.kind != "fluid") continue;
      checkFluidState(material, fluidEos(material), bottom, scene.initial.temperature, cell_volume, ice_runs,
                      "cfdmpm.domain.gravity", gravity_value,
                      "the bottom of the initial hydrostatic column (pressure up to " + roughly(bottom) + " Pa)");
    }
  }

  // Solids: the elastic wave speed sets the particle solver's time step; it must be finite, and
  // the first step (cfl h / c, at most dt_initial) no shorter than dt_min.
  for (const mpm::SolidMaterial& solid : mpm::solidMaterials(scene)) {
    const double c = solid.model.visit([&](const auto& model) { return model.waveSpeed(solid.density); });
    const std::string type = scene.materials[solid.scene_index].parameters.sublist("model").get<std::string>("type");
    if (type == "rigid") continue;
    const std::string key = "cfdmpm.materials." + solid.name + ".model." +
                            (type == "neo_hookean" ? "bulk_modulus" : "youngs_modulus");
    const auto& model = scene.materials[solid.scene_index].parameters.sublist("model");
    const std::string value = showValue(model.getEntry(key.substr(key.rfind('.') + 1)));
    const double dt = scene.time.cfl * h_min / c;
    if (!usable(c)) {
      throw inputError(key, value,
                       "the elastic wave speed of " + solid.name + " is " + roughly(c) +
                           " m/s (with density " + roughly(solid.density) + " kg/m^3); choose a smaller value");
    }
    if (dt < scene.time.dt_min) {
      throw inputError(key, value,
                       "the elastic wave speed of " + solid.name + ", " + roughly(c) +
                           " m/s, limits the particle solver's time step to cfl h / c = " + roughly(dt) +
                           " s, below time.dt_min (" + showNumber(scene.time.dt_min) + " s)");
    }
  }
}

// --- Settings the solvers check when they are built ---------------------------------------------

void checkSolverSettings(const Scene& scene)
{
  int solids = 0;
  std::string first_solid;
  for (const auto& m : scene.materials)
    if (m.kind == "solid" && solids++ == 0) first_solid = m.name;
  // As the coupled step builds its solvers (mpmice/mpmice_step.cpp, ice/ice_solver.cpp): the fluid
  // step, which runs unless ice.enabled is false, holds every material, solids included.
  const auto& ice = scene.parameters->sublist("ice");
  const bool ice_runs = ice.get<bool>("enabled");
  if (ice_runs && int(scene.materials.size()) > ice::kMaxMaterials) {
    throw inputError("cfdmpm.materials", std::to_string(scene.materials.size()) + " materials",
                     "the fluid solver handles at most " + std::to_string(ice::kMaxMaterials));
  }
  if (ice_runs && solids > 0 && !ice.get<bool>("isothermal")) {
    throw inputError("cfdmpm.ice.isothermal", "false",
                     "allowed: true in a scene with the solid material '" + first_solid +
                         "'; the coupled step does not carry the solids' temperature yet");
  }
  if (scene.mpm.solid_volume == "particles" && scene.mpm.coupling != "monolithic") {
    throw inputError("cfdmpm.mpm.solid_volume", "particles",
                     "allowed with mpm.coupling: monolithic only (the staggered coupling fixes the solids' motion "
                     "before the pressure); set solid_volume: faces or coupling: monolithic");
  }
  if (scene.mpm.substeps > 1 && scene.mpm.solid_volume != "faces") {
    throw inputError("cfdmpm.mpm.substeps", std::to_string(scene.mpm.substeps),
                     "allowed: 1 with mpm.solid_volume: particles (its trial moves are one grid update long); set "
                     "substeps: 1 or solid_volume: faces");
  }
  if (scene.mpm.substeps > 1 && scene.mpm.coupling != "monolithic") {
    throw inputError("cfdmpm.mpm.substeps", std::to_string(scene.mpm.substeps),
                     "allowed: 1 with mpm.coupling: staggered (the staggered coupling moves the particles before "
                     "the pressure, in one step); set substeps: 1 or coupling: monolithic");
  }
  if (scene.mpm.solid_volume == "particles" && ice_runs && ice.get<std::string>("pressure") != "implicit") {
    throw inputError("cfdmpm.mpm.solid_volume", "particles",
                     "allowed with ice.pressure: implicit only (it acts in the implicit pressure's outer iterations)");
  }
  if (solids > kMaxSolidMaterials) {
    throw inputError("cfdmpm.materials", std::to_string(solids) + " solid materials",
                     "the particle solver handles at most " + std::to_string(kMaxSolidMaterials));
  }
  // The pressure solver's settings as the fluid solver hands them over (defaults filled in).
  PressureSolver<2>::checkSettings(IceSettings::fromScene(scene).linear_solver, "cfdmpm.ice.linear_solver.");
  mpm::solidMaterials(scene);

  // Hydrostatic initialisation integrates along gravity, which must then be along one axis.
  int axes = 0;
  for (int d = 0; d < scene.domain.dimension; ++d) axes += scene.domain.gravity[d] != 0;
  if (scene.initial.hydrostatic && axes > 1) {
    throw inputError("cfdmpm.initial_state.hydrostatic", "true",
                     "needs domain.gravity along one axis, got " +
                         showPoint(scene.domain.gravity.data(), scene.domain.dimension) +
                         "; set hydrostatic: false or align domain.gravity with an axis");
  }
}

// --- Memory ------------------------------------------------------------------------------------

// Peak resident memory of a run, measured with /usr/bin/time on one rank (Release build, 3 steps):
//  - the dam break (2 fluids, ICE) at 256,000 and 1,024,000 cells: 1,168 bytes per cell more, so
//    ~600 bytes per cell and material in 2-D; 3-D is taken as 1.5 times that (a third face
//    direction and a 7-point pressure matrix; not measured);
//  - the granular column (MPM) with 102,400 and 614,400 particles on the same grid: 414 bytes per
//    particle more in 2-D; 3-D is taken as 1.6 times that (3x3 tensors instead of 2x2 plus one);
//  - ~100 MB per rank for the program, Trilinos and MPI.
// The estimate decides only whether a run can fit at all, so a factor of two either way is harmless.
constexpr double kBytesPerCellAndMaterial2D = 600;
constexpr double kBytesPerParticle2D = 420;
constexpr double kBytesPerRank = 100e6;

double physicalMemory()
{
  const long pages = ::sysconf(_SC_PHYS_PAGES), page = ::sysconf(_SC_PAGE_SIZE);
  return pages > 0 && page > 0 ? double(pages) * double(page) : 0.0;
}

}  // namespace

std::vector<RegionPlacement> regionPlacements(const Scene& scene)
{
  std::vector<RegionPlacement> placements;
  for (const RegionSpec& region : scene.regions) {
    RegionPlacement p;
    p.region = region.name;
    p.material = region.material;
    const MaterialSpec& material = scene.materials[scene.materialIndex(region.material)];
    p.solid = material.kind == "solid";
    p.per_direction = p.solid && material.parameters.isParameter("particles_per_cell")
                          ? material.parameters.get<int>("particles_per_cell")
                          : p.solid ? 2 : 4;
    p.points = countRegion(region, scene.domain, p.per_direction);
    p.cells = p.points < 0 ? -1 : p.points / std::pow(double(p.per_direction), scene.domain.dimension);
    placements.push_back(p);
  }
  return placements;
}

MemoryEstimate estimateMemory(const Scene& scene)
{
  const int dim = scene.domain.dimension;
  MemoryEstimate estimate;
  estimate.cells = 1;
  for (int d = 0; d < dim; ++d) estimate.cells *= double(scene.domain.cells[d]);
  for (const RegionPlacement& p : regionPlacements(scene))
    if (p.solid && p.points > 0) estimate.particles += p.points;
  const double per_cell = kBytesPerCellAndMaterial2D * double(scene.materials.size()) * (dim == 3 ? 1.5 : 1.0);
  const double per_particle = kBytesPerParticle2D * (dim == 3 ? 1.6 : 1.0);
  estimate.bytes = estimate.cells * per_cell + estimate.particles * per_particle;
  estimate.detail = roughly(estimate.cells) + " cells (domain.cells) x " + roughly(per_cell) + " bytes for " +
                    std::to_string(scene.materials.size()) + " materials";
  if (estimate.particles > 0)
    estimate.detail += " + " + roughly(estimate.particles) + " particles (regions of solids, particles_per_cell) x " +
                       roughly(per_particle) + " bytes";
  return estimate;
}

void checkSceneAsAWhole(const Scene& scene)
{
  checkGridSize(scene.domain);
  for (const RegionSpec& region : scene.regions)
    if (region.shape == "polygon") checkPolygon(region, "cfdmpm.regions." + region.name);
  const std::vector<RegionPlacement> placements = regionPlacements(scene);
  for (std::size_t r = 0; r < placements.size(); ++r) {
    const RegionPlacement& p = placements[r];
    if (p.points != 0) continue;
    const RegionSpec& region = scene.regions[r];
    double h_min = INFINITY;
    for (int d = 0; d < scene.domain.dimension; ++d)
      h_min = std::min(h_min, (scene.domain.upper[d] - scene.domain.lower[d]) / double(scene.domain.cells[d]));
    const std::string spacing = lengthText(h_min / p.per_direction) + " apart: " + std::to_string(p.per_direction) +
                                " per cell and direction in " + lengthText(h_min) + " cells";
    std::string why = p.solid ? "places no particle of " + p.material + ": no particle position (" + spacing +
                                    ", particles_per_cell) lies in " + describeShape(region, scene.domain.dimension)
                              : "places no " + p.material + ": none of the points the initial state samples (" +
                                    spacing + ") lies in " + describeShape(region, scene.domain.dimension);
    why += region.shape == "half_plane" ? "; the whole domain is on the side the normal points to"
                                        : "; make the region larger or the cells (domain.cells) finer";
    throw InputError("cfdmpm.regions." + region.name + ": " + why);
  }
  checkSolverSettings(scene);
  checkDerivedQuantities(scene);
}

namespace {

void checkSetUpOnRanks(const Scene& scene, const Teuchos::RCP<const Teuchos::Comm<int>>& comm, bool overwrite)
{
  // Memory: the estimate against the physical memory of every node the ranks run on.
  const MPI_Comm mpi = rawMpiComm(comm);
  MPI_Comm node;
  MPI_Comm_split_type(mpi, MPI_COMM_TYPE_SHARED, comm->getRank(), MPI_INFO_NULL, &node);
  int node_rank = 0;
  MPI_Comm_rank(node, &node_rank);
  MPI_Comm_free(&node);
  double mine[2] = {node_rank == 0 ? physicalMemory() : 0.0, node_rank == 0 ? 1.0 : 0.0}, all[2] = {0, 0};
  MPI_Allreduce(mine, all, 2, MPI_DOUBLE, MPI_SUM, mpi);
  MemoryEstimate estimate = estimateMemory(scene);
  estimate.bytes += kBytesPerRank * comm->getSize();
  if (all[0] > 0 && estimate.bytes > all[0]) {
    throw InputError("cfdmpm.domain.cells: the run needs about " + bytesText(estimate.bytes) + " of memory (" +
                     estimate.detail + ", + " + bytesText(kBytesPerRank) + " per rank), but the " +
                     std::to_string(comm->getSize()) + " rank(s) run on " + roughly(all[1]) + " node(s) with " +
                     bytesText(all[0]) + " in all; use fewer cells or particles, or more nodes");
  }
  // Patches for the ranks, as the run decomposes them.
  if (scene.domain.dimension == 3)
    partitionPatches(Grid<3>(scene.domain), comm->getSize());
  else
    partitionPatches(Grid<2>(scene.domain), comm->getSize());
  checkOutputDirectory(mpi, scene.output.directory, overwrite || scene.output.overwrite);
}

}  // namespace

void checkSetUp(const Scene& scene, const Teuchos::RCP<const Teuchos::Comm<int>>& comm, bool overwrite)
{
  try {
    checkSetUpOnRanks(scene, comm, overwrite);
  } catch (const InputError& error) {
    throw InputError(scene.path + ": " + error.what());
  }
}

}  // namespace cfdmpm
