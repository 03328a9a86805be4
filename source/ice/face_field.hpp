#pragma once
// Face-centred quantities of the staggered ICE variables (face velocities, face specific volumes).
// For direction d, entry (c, column) of direction(d) lives on the LOWER face of cell c in direction
// d, between the neighbour layout.cellNeighbours()(c, 2 d) and c. The upper faces of the cells on
// the domain's upper boundary have no entry: every domain face is a wall (zero normal velocity), and
// so is the lower face of a cell on the domain's lower boundary (its entry is kept at zero).
#include "fields/field.hpp"

#include <vector>

namespace cfdmpm {

template <int Dim>
class FaceField {
 public:
  FaceField(std::shared_ptr<const Layout<Dim>> layout, int columns, const std::string& name)
  {
    for (int d = 0; d < Dim; ++d)
      directions_.emplace_back(layout, Location::Cell, columns, name + "_" + "xyz"[d]);
  }

  Field<Dim>& direction(int d) { return directions_[d]; }
  const Field<Dim>& direction(int d) const { return directions_[d]; }

  void exchangeHalo()
  {
    for (auto& f : directions_) f.exchangeHalo();
  }
  void fill(Scalar value)
  {
    for (auto& f : directions_) f.fill(value);
  }
  /// Exchanges the values of every direction with `other` (Field::swapValues), without copying.
  void swapValues(FaceField& other)
  {
    for (int d = 0; d < Dim; ++d) directions_[d].swapValues(other.directions_[d]);
  }

 private:
  std::vector<Field<Dim>> directions_;
};

}  // namespace cfdmpm
