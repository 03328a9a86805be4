#include "grid/geometry.hpp"

namespace cfdmpm {

bool regionContains(const RegionSpec& region, int dimension, const std::array<double, 3>& x)
{
  if (region.shape == "box") {
    for (int d = 0; d < dimension; ++d)
      if (x[d] < region.lower[d] || x[d] > region.upper[d]) return false;
    return true;
  }
  if (region.shape == "half_plane") {
    double s = 0;
    for (int d = 0; d < dimension; ++d) s += (x[d] - region.point[d]) * region.normal[d];
    return s <= 0;
  }
  if (region.shape == "polygon") {
    // Even-odd rule: count crossings of a ray in +x.
    bool inside = false;
    const auto& v = region.vertices;
    for (std::size_t i = 0, j = v.size() - 1; i < v.size(); j = i++) {
      const bool straddles = (v[i][1] > x[1]) != (v[j][1] > x[1]);
      if (straddles && x[0] < (v[j][0] - v[i][0]) * (x[1] - v[i][1]) / (v[j][1] - v[i][1]) + v[i][0])
        inside = !inside;
    }
    return inside;
  }
  throw InputError("regions." + region.name + ".shape: got '" + region.shape +
                   "'; allowed: box, polygon, half_plane");
}

MaterialRegions::MaterialRegions(const Scene& scene)
    : dimension_(scene.domain.dimension),
      background_temperature_(scene.initial.temperature),
      materials_(int(scene.materials.size())),
      background_(scene.materialIndex(scene.initial.background_material)),
      regions_(scene.regions)
{
  for (const RegionSpec& r : regions_) region_material_.push_back(scene.materialIndex(r.material));
}

int MaterialRegions::regionAt(const std::array<double, 3>& x) const
{
  for (int r = int(regions_.size()) - 1; r >= 0; --r)
    if (regionContains(regions_[r], dimension_, x)) return r;
  return -1;
}

int MaterialRegions::materialAt(const std::array<double, 3>& x) const
{
  const int r = regionAt(x);
  return r < 0 ? background_ : region_material_[r];
}

template <int Dim>
CellSample MaterialRegions::sampleCell(const Grid<Dim>& grid, const std::array<long long, 3>& ijk, int samples) const
{
  CellSample cell;
  cell.fraction.assign(materials_, 0.0);
  cell.temperature.assign(materials_, 0.0);
  cell.velocity.assign(materials_, {0.0, 0.0, 0.0});
  const int total = Dim == 2 ? samples * samples : samples * samples * samples;
  const double share = 1.0 / total;
  for (int s = 0; s < total; ++s) {
    std::array<double, 3> x{0, 0, 0};
    int rest = s;
    for (int d = 0; d < Dim; ++d) {
      const int k = rest % samples;
      rest /= samples;
      x[d] = grid.nodePosition(d, ijk[d]) + (k + 0.5) / samples * grid.spacing()[d];
    }
    const int r = regionAt(x);
    const int m = r < 0 ? background_ : region_material_[r];
    cell.fraction[m] += share;
    cell.temperature[m] += share * (r < 0 ? background_temperature_ : regions_[r].temperature);
    for (int d = 0; d < Dim; ++d) cell.velocity[m][d] += share * (r < 0 ? 0.0 : regions_[r].velocity[d]);
  }
  for (int m = 0; m < materials_; ++m) {
    if (cell.fraction[m] > 0) {
      cell.temperature[m] /= cell.fraction[m];
      for (int d = 0; d < Dim; ++d) cell.velocity[m][d] /= cell.fraction[m];
    } else {
      cell.temperature[m] = background_temperature_;
    }
  }
  return cell;
}

template CellSample MaterialRegions::sampleCell<2>(const Grid<2>&, const std::array<long long, 3>&, int) const;
template CellSample MaterialRegions::sampleCell<3>(const Grid<3>&, const std::array<long long, 3>&, int) const;

}  // namespace cfdmpm
