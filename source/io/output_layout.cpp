#include "io/output_layout.hpp"

namespace cfdmpm {

const char* locationName(OutputLocation location)
{
  switch (location) {
    case OutputLocation::Cells: return "cells";
    case OutputLocation::Nodes: return "nodes";
    case OutputLocation::Particles: return "particles";
  }
  return "cells";
}

long long ownedCount(const OutputLayout& layout)
{
  long long count = 0;
  for (const Box& box : layout.owned_boxes) count += box.count();
  return count;
}

long long globalCount(const OutputLayout& layout)
{
  return layout.global_count[0] * layout.global_count[1] * layout.global_count[2];
}

std::vector<long long> datasetDims(const OutputLayout& layout, int components)
{
  std::vector<long long> dims;
  for (int d = layout.dimension - 1; d >= 0; --d) dims.push_back(layout.global_count[d]);
  if (components > 1) dims.push_back(components);
  return dims;
}

}  // namespace cfdmpm
