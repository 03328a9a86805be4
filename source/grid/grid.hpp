#pragma once
// The global Cartesian grid: geometry, cell and node numbering, and patches (blocks of cells that
// are the unit of decomposition). The same code serves 2-D and 3-D: Dim is a template parameter and
// every index array has three entries, the unused one fixed (cells 1, index 0).
#include "common/box.hpp"
#include "input/scene.hpp"

#include <array>
#include <stdexcept>
#include <string>

namespace cfdmpm {

template <int Dim>
class Grid {
  static_assert(Dim == 2 || Dim == 3, "cfdmpm grids are 2-D or 3-D");

 public:
  static constexpr int dimension = Dim;
  static constexpr int faces_per_cell = 2 * Dim;
  static constexpr int nodes_per_cell = 1 << Dim;

  /// lower/upper corners (m), cells and patch size per direction (entries beyond Dim ignored).
  Grid(const std::array<double, 3>& lower, const std::array<double, 3>& upper,
       const std::array<long long, 3>& cells, const std::array<long long, 3>& patch_cells)
  {
    for (int d = 0; d < 3; ++d) {
      const bool used = d < Dim;
      lower_[d] = used ? lower[d] : 0.0;
      cells_[d] = used ? cells[d] : 1;
      if (cells_[d] < 1) throw std::invalid_argument("Grid: cells must be >= 1 in every direction");
      spacing_[d] = used ? (upper[d] - lower[d]) / double(cells_[d]) : 1.0;
      if (!(spacing_[d] > 0)) throw std::invalid_argument("Grid: upper must exceed lower");
      patch_cells_[d] = used ? std::min(std::max(patch_cells[d], 1LL), cells_[d]) : 1;
      patches_[d] = (cells_[d] + patch_cells_[d] - 1) / patch_cells_[d];
      nodes_[d] = used ? cells_[d] + 1 : 1;
    }
  }

  explicit Grid(const DomainSpec& domain)
      : Grid(domain.lower, domain.upper, domain.cells, domain.patch_cells)
  {
  }

  // --- geometry -----------------------------------------------------------------------------
  const std::array<double, 3>& lower() const { return lower_; }
  const std::array<double, 3>& spacing() const { return spacing_; }
  double cellVolume() const
  {
    double v = 1;
    for (int d = 0; d < Dim; ++d) v *= spacing_[d];
    return v;
  }
  double cellCentre(int d, long long i) const { return lower_[d] + (double(i) + 0.5) * spacing_[d]; }
  double nodePosition(int d, long long i) const { return lower_[d] + double(i) * spacing_[d]; }

  // --- cells and nodes: global ids are lexicographic with x fastest --------------------------
  const std::array<long long, 3>& cells() const { return cells_; }
  const std::array<long long, 3>& nodes() const { return nodes_; }
  long long cellCount() const { return cells_[0] * cells_[1] * cells_[2]; }
  long long nodeCount() const { return nodes_[0] * nodes_[1] * nodes_[2]; }
  Box cellBox() const { return Box{{0, 0, 0}, cells_}; }
  Box nodeBox() const { return Box{{0, 0, 0}, nodes_}; }

  static long long linear(const std::array<long long, 3>& ijk, const std::array<long long, 3>& n)
  {
    return ijk[0] + n[0] * (ijk[1] + n[1] * ijk[2]);
  }
  static std::array<long long, 3> unlinear(long long id, const std::array<long long, 3>& n)
  {
    return {id % n[0], (id / n[0]) % n[1], id / (n[0] * n[1])};
  }
  long long cellId(const std::array<long long, 3>& ijk) const { return linear(ijk, cells_); }
  long long nodeId(const std::array<long long, 3>& ijk) const { return linear(ijk, nodes_); }
  std::array<long long, 3> cellIndex(long long id) const { return unlinear(id, cells_); }
  std::array<long long, 3> nodeIndex(long long id) const { return unlinear(id, nodes_); }
  /// "cell (i, j)" or "cell (i, j, k)" for the cell with global index id, as messages name it.
  std::string cellName(long long id) const
  {
    const auto ijk = cellIndex(id);
    std::string name = "cell (" + std::to_string(ijk[0]) + ", " + std::to_string(ijk[1]);
    if (Dim == 3) name += ", " + std::to_string(ijk[2]);
    return name + ")";
  }

  /// The cell that owns a node: the cell whose lower corner it is, clamped at the upper faces.
  std::array<long long, 3> ownerCellOfNode(const std::array<long long, 3>& node) const
  {
    std::array<long long, 3> c{};
    for (int d = 0; d < 3; ++d) c[d] = std::min(node[d], cells_[d] - 1);
    return c;
  }

  // --- patches --------------------------------------------------------------------------------
  const std::array<long long, 3>& patchCounts() const { return patches_; }
  int patchCount() const { return int(patches_[0] * patches_[1] * patches_[2]); }
  std::array<long long, 3> patchIndex(int p) const { return unlinear(p, patches_); }
  int patchId(const std::array<long long, 3>& pijk) const { return int(linear(pijk, patches_)); }

  /// The patch that holds the cell with global index ijk.
  int patchOfCell(const std::array<long long, 3>& ijk) const
  {
    std::array<long long, 3> pijk{0, 0, 0};
    for (int d = 0; d < 3; ++d) pijk[d] = ijk[d] / patch_cells_[d];
    return patchId(pijk);
  }

  /// The cells of patch p; the last patch in a direction may be smaller.
  Box patchCells(int p) const
  {
    const auto pijk = patchIndex(p);
    Box b;
    for (int d = 0; d < 3; ++d) {
      b.lower[d] = pijk[d] * patch_cells_[d];
      b.upper[d] = std::min(b.lower[d] + patch_cells_[d], cells_[d]);
    }
    return b;
  }

  /// The nodes owned by patch p's owner on its behalf (see ownerCellOfNode).
  Box patchNodes(int p) const
  {
    Box b = patchCells(p);
    for (int d = 0; d < Dim; ++d)
      if (b.upper[d] == cells_[d]) b.upper[d] += 1;
    return b;
  }

  /// True when patch p touches domain face f (f = 2 d + side; side 0 is the lower face).
  bool patchOnBoundary(int p, int f) const
  {
    const Box b = patchCells(p);
    const int d = f / 2;
    return (f % 2 == 0) ? b.lower[d] == 0 : b.upper[d] == cells_[d];
  }

 private:
  std::array<double, 3> lower_{}, spacing_{};
  std::array<long long, 3> cells_{}, nodes_{}, patch_cells_{}, patches_{};
};

/// Names of the domain faces in the order of face indices f = 2 d + side.
inline const char* faceName(int f)
{
  static const char* names[6] = {"x-", "x+", "y-", "y+", "z-", "z+"};
  return names[f];
}

}  // namespace cfdmpm
