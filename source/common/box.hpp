#pragma once
// An index box [lower, upper) of cells or nodes. Unused dimensions have lower 0 and upper 1,
// so 2-D and 3-D share one layout; index 0 is x (fastest varying), as in the output files.
#include <array>

namespace cfdmpm {

struct Box {
  std::array<long long, 3> lower{0, 0, 0};
  std::array<long long, 3> upper{1, 1, 1};

  long long extent(int d) const { return upper[d] - lower[d]; }
  long long count() const { return extent(0) * extent(1) * extent(2); }
  bool contains(const std::array<long long, 3>& ijk) const
  {
    for (int d = 0; d < 3; ++d)
      if (ijk[d] < lower[d] || ijk[d] >= upper[d]) return false;
    return true;
  }
};

}  // namespace cfdmpm
