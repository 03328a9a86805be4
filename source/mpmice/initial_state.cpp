#include "mpmice/initial_state.hpp"

#include "grid/geometry.hpp"
#include "ice/material_eos.hpp"

#include <algorithm>
#include <cmath>
#include <map>

namespace cfdmpm {

namespace {

// The axis gravity acts along, or -1 without gravity. Hydrostatic initialisation integrates along
// it, so gravity must be axis-aligned for that.
int gravityAxis(const Scene& scene)
{
  int axis = -1;
  for (int d = 0; d < scene.domain.dimension; ++d) {
    if (scene.domain.gravity[d] == 0) continue;
    if (axis >= 0 && scene.initial.hydrostatic)
      throw InputError("initial_state.hydrostatic: got 'true' with gravity not along one axis; "
                       "set hydrostatic: false or align domain.gravity with an axis");
    axis = d;
  }
  return axis;
}

// The scene without its solid regions: the fluids that the solids displace. The initial pressure is
// the hydrostatic pressure of these fluids (a solid's weight rests on its own stress, not on the
// pore pressure), and they fill what the particles leave of a cell.
Scene fluidsUnderSolids(const Scene& scene)
{
  Scene fluids = scene;
  fluids.regions.clear();
  for (const RegionSpec& r : scene.regions)
    if (scene.materials[scene.materialIndex(r.material)].kind == "fluid") fluids.regions.push_back(r);
  return fluids;
}

double mixtureDensity(const CellSample& cell, const std::vector<DensityOfState>& density_of, double p)
{
  double rho = 0;
  for (std::size_t m = 0; m < cell.fraction.size(); ++m)
    if (cell.fraction[m] > 0) rho += cell.fraction[m] * density_of[m](p, cell.temperature[m]);
  return rho;
}

}  // namespace

std::vector<DensityOfState> densityFunctions(const Scene& scene)
{
  std::vector<DensityOfState> result;
  for (const MaterialSpec& material : scene.materials) {
    if (material.kind == "fluid") {
      const ice::Eos eos = fluidEos(material);
      result.emplace_back([eos](double p, double T) { return eos.density(p, T); });
    } else {
      const double rho = material.parameters.get<double>("density");
      result.emplace_back([rho](double, double) { return rho; });
    }
  }
  return result;
}


template <int Dim>
void setInitialState(const Scene& scene, const std::vector<DensityOfState>& density_of, CellState<Dim>& state)
{
  const Layout<Dim>& layout = state.volume_fraction.layout();
  const Grid<Dim>& grid = layout.grid();
  const MaterialRegions regions(scene);
  const MaterialRegions fluid_regions(fluidsUnderSolids(scene));
  const int axis = scene.initial.hydrostatic ? gravityAxis(scene) : -1;

  // Hydrostatic pressure at cell centres of a whole column, integrated from the top face (where it
  // is initial_state.pressure) down with the trapezoidal rule on the mixture density, which itself
  // depends on the pressure through the equations of state (two fixed-point passes per cell).
  std::map<std::array<long long, 3>, std::vector<double>> column_pressure;
  auto pressureAt = [&](const std::array<long long, 3>& ijk) {
    if (axis < 0) return scene.initial.pressure;
    std::array<long long, 3> key = ijk;
    key[axis] = 0;
    auto found = column_pressure.find(key);
    if (found == column_pressure.end()) {
      const long long n = grid.cells()[axis];
      const double g = std::abs(scene.domain.gravity[axis]);
      const double h = grid.spacing()[axis];
      const bool top_is_upper = scene.domain.gravity[axis] < 0;
      std::vector<double> p(n);
      double p_above = scene.initial.pressure, rho_above = 0, half_above = 0;
      for (long long s = 0; s < n; ++s) {
        std::array<long long, 3> c = key;
        c[axis] = top_is_upper ? n - 1 - s : s;
        const CellSample cell = fluid_regions.sampleCell(grid, c);
        double guess = p_above, rho = 0;
        for (int pass = 0; pass < 2; ++pass) {
          rho = mixtureDensity(cell, density_of, guess);
          guess = p_above + g * (half_above * rho_above + 0.5 * h * rho);
        }
        p[c[axis]] = guess;
        p_above = guess, rho_above = rho, half_above = 0.5 * h;
      }
      found = column_pressure.emplace(key, std::move(p)).first;
    }
    return found->second[ijk[axis]];
  };

  auto theta = state.volume_fraction.view();
  auto rho = state.density.view();
  auto v = state.specific_volume.view();
  auto u = state.velocity.view();
  auto T = state.temperature.view();
  auto p = state.pressure.view();
  const auto ijk_table = layout.cellIndex();
  for (LocalOrdinal c = 0; c < layout.ownedCells(); ++c) {
    std::array<long long, 3> ijk{0, 0, 0};
    for (int d = 0; d < Dim; ++d) ijk[d] = ijk_table(c, d);
    const CellSample cell = regions.sampleCell(grid, ijk);
    p(c, 0) = pressureAt(ijk);
    for (int m = 0; m < state.materials; ++m) {
      const double rho_micro = density_of[m](p(c, 0), cell.temperature[m]);
      theta(c, m) = cell.fraction[m];
      v(c, m) = 1.0 / rho_micro;
      rho(c, m) = cell.fraction[m] * rho_micro;
      T(c, m) = cell.temperature[m];
      for (int d = 0; d < Dim; ++d) u(c, CellState<Dim>::velocityColumn(m, d)) = cell.velocity[m][d];
    }
  }
  for (Field<Dim>* f : {&state.volume_fraction, &state.density, &state.specific_volume, &state.velocity,
                        &state.temperature, &state.pressure})
    f->exchangeHalo();
}

template <int Dim>
void fillAroundSolids(const Scene& scene, const std::vector<DensityOfState>& density_of, CellState<Dim>& state)
{
  const Layout<Dim>& layout = state.volume_fraction.layout();
  const Grid<Dim>& grid = layout.grid();
  const MaterialRegions fluid_regions(fluidsUnderSolids(scene));
  std::vector<int> fluid, solid;
  for (int m = 0; m < state.materials; ++m) (scene.materials[m].kind == "fluid" ? fluid : solid).push_back(m);
  auto theta = state.volume_fraction.view();
  auto rho = state.density.view();
  auto v = state.specific_volume.view();
  auto u = state.velocity.view();
  auto T = state.temperature.view();
  const auto p = state.pressure.view();
  const auto ijk_table = layout.cellIndex();
  for (LocalOrdinal c = 0; c < layout.ownedCells(); ++c) {
    double solid_share = 0, fluid_share = 0;
    for (int m : solid) solid_share += theta(c, m);
    for (int m : fluid) fluid_share += theta(c, m);
    const double room = std::max(0.0, 1.0 - solid_share);
    if (fluid_share > 0) {
      for (int m : fluid) theta(c, m) *= room / fluid_share;
    } else if (room > 0) {
      // The regions gave this cell to a solid, but its particles leave room: the fluids the solid
      // displaced fill it.
      std::array<long long, 3> ijk{0, 0, 0};
      for (int d = 0; d < Dim; ++d) ijk[d] = ijk_table(c, d);
      const CellSample under = fluid_regions.sampleCell(grid, ijk);
      double total = 0;
      for (int m : fluid) total += under.fraction[m];
      for (int m : fluid) {
        theta(c, m) = total > 0 ? room * under.fraction[m] / total : 0.0;
        T(c, m) = under.temperature[m];
        for (int d = 0; d < Dim; ++d) u(c, CellState<Dim>::velocityColumn(m, d)) = under.velocity[m][d];
      }
    }
    for (int m : fluid) {
      const double rho_micro = density_of[m](p(c, 0), T(c, m));
      v(c, m) = 1.0 / rho_micro;
      rho(c, m) = theta(c, m) * rho_micro;
    }
  }
  for (Field<Dim>* f : {&state.volume_fraction, &state.density, &state.specific_volume, &state.velocity,
                        &state.temperature})
    f->exchangeHalo();
}

template void fillAroundSolids<2>(const Scene&, const std::vector<DensityOfState>&, CellState<2>&);
template void fillAroundSolids<3>(const Scene&, const std::vector<DensityOfState>&, CellState<3>&);

template void setInitialState<2>(const Scene&, const std::vector<DensityOfState>&, CellState<2>&);
template void setInitialState<3>(const Scene&, const std::vector<DensityOfState>&, CellState<3>&);

}  // namespace cfdmpm
