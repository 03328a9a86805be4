#pragma once
// The per-material state at cell centres, shared by every material, fluid (ICE) or solid (MPM), so
// that equilibration, pressure and exchange treat all materials alike (design: one step, material
// sets switched on or off). Columns are materials; the velocity has Dim columns per material.
#include "fields/field.hpp"

#include <array>
#include <memory>

namespace cfdmpm {

template <int Dim>
struct CellState {
  CellState(std::shared_ptr<const Layout<Dim>> layout, int material_count)
      : materials(material_count),
        volume_fraction(layout, Location::Cell, material_count, "volume_fraction"),
        density(layout, Location::Cell, material_count, "density"),
        specific_volume(layout, Location::Cell, material_count, "specific_volume"),
        velocity(layout, Location::Cell, material_count * Dim, "velocity"),
        temperature(layout, Location::Cell, material_count, "temperature"),
        pressure(layout, Location::Cell, 1, "pressure")
  {
  }

  /// The fields, with their names, in a fixed order.
  std::array<Field<Dim>*, 6> fields()
  {
    return {&volume_fraction, &density, &specific_volume, &velocity, &temperature, &pressure};
  }
  std::array<const Field<Dim>*, 6> fields() const
  {
    return {&volume_fraction, &density, &specific_volume, &velocity, &temperature, &pressure};
  }

  /// Takes the values of every field, owned and ghost entries, from `other` (same layout and
  /// materials): undoing a step restores the state from a copy.
  void assign(const CellState& other)
  {
    const auto from = other.fields();
    const auto to = fields();
    for (std::size_t f = 0; f < to.size(); ++f) Kokkos::deep_copy(to[f]->view(), from[f]->view());
  }

  /// Column of velocity component d of material m.
  static int velocityColumn(int m, int d) { return m * Dim + d; }

  int materials;
  Field<Dim> volume_fraction;  // θ_m, Σ_m θ_m = 1
  Field<Dim> density;          // bulk density ρ_m = mass_m / V_cell (kg/m^3)
  Field<Dim> specific_volume;  // v_m = 1 / ρ_micro,m (m^3/kg), the material's own density inverted
  Field<Dim> velocity;         // u_m (m/s)
  Field<Dim> temperature;      // T_m (K)
  Field<Dim> pressure;         // p (Pa), shared by all materials
};

}  // namespace cfdmpm
