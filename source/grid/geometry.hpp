#pragma once
// Geometry of the scene's regions (boxes, polygons, half-planes): which material occupies a point,
// and the volume fraction of each material in a cell by sampling. Used for the initial state and,
// for solids, for seeding particles.
#include "grid/grid.hpp"
#include "input/scene.hpp"

#include <vector>

namespace cfdmpm {

/// True when point x (Dim coordinates used) lies in the region. Polygons are 2-D and extruded over
/// z in 3-D; a half-plane holds the points behind its normal: (x - point) . normal <= 0.
bool regionContains(const RegionSpec& region, int dimension, const std::array<double, 3>& x);

/// What the samples of one cell found: per material its volume fraction and the sample-averaged
/// temperature and velocity of the regions it came from (the initial-state defaults where absent).
struct CellSample {
  std::vector<double> fraction;
  std::vector<double> temperature;
  std::vector<std::array<double, 3>> velocity;
};

/// The scene's regions with their material indices resolved once.
class MaterialRegions {
 public:
  explicit MaterialRegions(const Scene& scene);

  /// Index of the material at point x: the last region in file order that contains x, or the
  /// background material.
  int materialAt(const std::array<double, 3>& x) const;

  /// The materials in the cell with global index ijk, from samples^Dim points on a regular
  /// sub-grid of the cell (samples = 4 resolves an interface to a quarter cell).
  template <int Dim>
  CellSample sampleCell(const Grid<Dim>& grid, const std::array<long long, 3>& ijk, int samples = 4) const;

 private:
  /// Index of the region at x (last in file order that contains it), or -1 for the background.
  int regionAt(const std::array<double, 3>& x) const;

  int dimension_;
  double background_temperature_;
  int materials_;
  int background_;
  std::vector<RegionSpec> regions_;
  std::vector<int> region_material_;
};

}  // namespace cfdmpm
