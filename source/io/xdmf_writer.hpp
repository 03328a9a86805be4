#pragma once
// XDMF descriptions of the HDF5 step files, for ParaView and VisIt:
//
//   <directory>/<run>_<step>.xmf   one step: a uniform 3DCoRectMesh grid (ORIGIN_DXDYDZ geometry)
//                                  with the step's time and one Attribute per field (Center Cell
//                                  or Node, AttributeType Scalar or Vector)
//   <directory>/<run>.xmf          the time series: a Temporal Collection of every step so far
//
// A step with particle fields (and a particle field "position") is a Spatial Collection of two
// uniform grids instead: the cell/node grid as above and "particles", a Polyvertex grid with XYZ
// geometry (the /padded 3-component copy of the position in 2-D) and Center="Node" attributes
// (AttributeType Scalar, Vector, Tensor for 9 components, Tensor6 for 6, Matrix otherwise).
//
// Both are written to <name>.tmp and renamed, so a reader never sees half a file. XDMF orders
// dimensions, origin and spacing slowest first (z y x), like the HDF5 datasets.
//
// 2-D grids are described as 3-D grids one node thick (z = 0), not as 2DCoRectMesh: ParaView
// (5.11, both the Xdmf3 and the legacy XDMF reader) lays a 2DCoRectMesh in the plane x = 0 with
// the file's x along its y axis, which puts the grid and its (x, y, 0) vectors in different planes.
// Vector attributes reference the 3-component copies of 2-D vectors under /padded (see
// hdf5_writer.hpp), because ParaView's glyphs and stream tracers want 3-component vectors.
#include "io/hdf5_writer.hpp"
#include "io/output_layout.hpp"

#include <mpi.h>

#include <string>
#include <vector>

namespace cfdmpm {

/// The XML of one uniform grid element (topology, geometry, time, attributes) for a written step;
/// `indent` spaces before each line. HDF5 references are relative to the output directory.
/// Only the cell and node fields; the particles have their own grid (xdmfParticleGrid).
std::string xdmfGrid(const OutputLayout& cells, const WrittenStep& step, int indent);

/// The particles of a step as a uniform grid named "particles": Polyvertex topology with one
/// element per particle, XYZ geometry from the particle field "position" (its /padded copy in
/// 2-D), one Center="Node" attribute per particle field. Empty if the step has no particle field
/// "position" or no particles at all.
std::string xdmfParticleGrid(const WrittenStep& step, int indent);

/// What a step contributes to a file: xdmfGrid alone when there is no particle grid, otherwise a
/// Spatial collection (with the step's Time) holding the cell/node grid and then the particle grid.
std::string xdmfStep(const OutputLayout& cells, const WrittenStep& step, int indent);

class XdmfWriter {
 public:
  /// `cells` and `nodes` describe the same grid: nodes = cells + 1 per used direction, same origin
  /// and spacing (std::invalid_argument otherwise).
  XdmfWriter(MPI_Comm comm, std::string directory, std::string run_name, const OutputLayout& cells,
             const OutputLayout& nodes);

  /// Writes the step's own .xmf and rewrites the time series to list every step added so far
  /// (a step with the same file name as an earlier one replaces it). Collective; rank 0 writes,
  /// every rank throws if writing fails.
  void addStep(const WrittenStep& step);

  /// After a restart: sets the steps written before the checkpoint and rewrites the time series to
  /// list exactly those. Collective, like addStep.
  void restoreSteps(std::vector<WrittenStep> steps);

  std::string seriesPath() const;                       // <directory>/<run>.xmf
  std::string stepPath(const WrittenStep& step) const;  // <directory>/<run>_<step>.xmf
  const std::vector<WrittenStep>& steps() const { return steps_; }

 private:
  void writeSeries() const;  // rank 0

  MPI_Comm comm_;
  std::string directory_;
  std::string run_name_;
  OutputLayout cells_;
  std::vector<WrittenStep> steps_;
};

/// Writes `text` to `path` through `path`.tmp and a rename, so `path` is always whole.
void writeFileAtomically(const std::string& path, const std::string& text);

/// The records of written steps as text, one tab-separated line per step and per field, and back
/// (std::invalid_argument on text that is not such a record). A checkpoint keeps them, so that a
/// restarted run's time series lists the steps written before it exactly as the first run did.
std::string stepRecordsText(const std::vector<WrittenStep>& steps);
std::vector<WrittenStep> stepRecordsFromText(const std::string& text);

}  // namespace cfdmpm
