#pragma once
// The state at t = 0 from the scene's regions: volume fractions by sampling the geometry, the
// pressure (uniform, or hydrostatic from the top of the domain down), and each material's density
// from its equation of state at that pressure and the initial temperature.
#include "input/scene.hpp"
#include "fields/cell_state.hpp"

#include <functional>
#include <vector>

namespace cfdmpm {

/// ρ_micro(p, T) of one material: its equation of state solved for the density.
using DensityOfState = std::function<double(double pressure, double temperature)>;

/// ρ_micro(p, T) for every material of the scene, in material order: a fluid's EOS solved for the
/// density; a solid's rest density (its bulk response is the MPM model's).
std::vector<DensityOfState> densityFunctions(const Scene& scene);

template <int Dim>
void setInitialState(const Scene& scene, const std::vector<DensityOfState>& density_of, CellState<Dim>& state);

/// For the coupled step: once the solids' volume fractions in the state come from their particles,
/// the fluids fill what is left of each cell (the sampled fluids scaled to it, or, where the regions
/// gave the whole cell to a solid, the fluids that the solid displaced), with their densities at
/// the cell's pressure. Cells stay full (Σθ = 1) wherever the particles leave room.
template <int Dim>
void fillAroundSolids(const Scene& scene, const std::vector<DensityOfState>& density_of, CellState<Dim>& state);

}  // namespace cfdmpm
