#pragma once
// What the output module needs to know about a grid: sizes, geometry and which entries this rank
// owns. The io module knows neither Tpetra nor the grid classes; the grid fills one OutputLayout per
// location (cells, nodes) and a field hands over its owned values as a plain buffer.
//
// A field's buffer holds this rank's owned entries in ascending global linear index
// (x fastest: gid = i + nx * (j + ny * k)); a vector field interleaves its components
// (buffer[entry * components + c]). That is the order in which HDF5 transfers a selection made of
// the union of the owned boxes, so the buffer goes to the file without a copy.
#include "common/box.hpp"

#include <array>
#include <string>
#include <vector>

namespace cfdmpm {

struct OutputLayout {                       // one per location (cells or nodes)
  int dimension = 2;                        // 2 or 3
  std::array<long long, 3> global_count{1, 1, 1};  // entries per direction, x first; unused dims 1
  std::array<double, 3> origin{0, 0, 0};    // m: lower corner of the first cell / the first node
  std::array<double, 3> spacing{1, 1, 1};   // m; unused dims 1
  std::vector<Box> owned_boxes;             // this rank's boxes (disjoint; union over ranks = all)
};

/// Where a field lives: on the grid's cells or nodes, or on the particles (a list of points whose
/// count may change from step to step; no OutputLayout, see Hdf5Writer::writeParticleScalar).
enum class OutputLocation { Cells, Nodes, Particles };

/// "cells", "nodes" or "particles": the HDF5 group of a location.
const char* locationName(OutputLocation location);

/// Entries owned by this rank (sum of the boxes' counts).
long long ownedCount(const OutputLayout& layout);

/// Total entries of the grid (product of global_count).
long long globalCount(const OutputLayout& layout);

/// Dataset dimensions, slowest first as HDF5 and XDMF store them: (nz, ny, nx) in 3-D, (ny, nx) in
/// 2-D, followed by the number of components for a vector field (components > 1).
std::vector<long long> datasetDims(const OutputLayout& layout, int components);

}  // namespace cfdmpm
