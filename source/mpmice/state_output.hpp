#pragma once
// Writes the cell state (and later node and particle fields) at an output step: one HDF5 file,
// its XDMF sidecar and the time-series XDMF. Bridges fields (Tpetra) and the io module (buffers).
#include "input/scene.hpp"
#include "io/hdf5_writer.hpp"
#include "io/xdmf_writer.hpp"
#include "mpm/mpm_solver.hpp"
#include "fields/cell_state.hpp"

#include <memory>
#include <string>
#include <vector>

namespace cfdmpm {

/// The io module's description of the grid at `location` with this rank's owned boxes.
template <int Dim>
OutputLayout outputLayout(const Grid<Dim>& grid, Location location, const std::vector<Box>& boxes)
{
  OutputLayout out;
  out.dimension = Dim;
  out.global_count = location == Location::Cell ? grid.cells() : grid.nodes();
  for (int d = 0; d < 3; ++d) {
    out.origin[d] = d < Dim ? grid.lower()[d] : 0.0;
    out.spacing[d] = d < Dim ? grid.spacing()[d] : 1.0;
  }
  out.owned_boxes = boxes;
  return out;
}

template <int Dim>
class StateOutput {
 public:
  /// Throws InputError if output.fields asks for a field this version does not write; call it
  /// before anything is written.
  static void checkFields(const Scene& scene);

  /// The output directory must have been prepared (prepareOutputDirectory).
  StateOutput(const Scene& scene, const Layout<Dim>& layout, const std::string& run_name);

  /// Writes the fields listed in output.fields (cell fields from the state; particle fields, with
  /// the positions, from `particles` when given); returns the HDF5 file's path.
  std::string write(long long step, double time, const CellState<Dim>& state,
                    const mpm::ParticleOutput* particles = nullptr);

  std::string seriesPath() const { return xdmf_->seriesPath(); }

  /// Writes from here on with the owned cells and nodes of `layout`, a new decomposition of the same
  /// grid (a rebalance); the time series goes on. Collective.
  void moveTo(const Layout<Dim>& layout);

  /// The steps written so far (for a checkpoint), and after a restart the steps written before it
  /// (the time series is rewritten to list exactly those).
  const std::vector<WrittenStep>& writtenSteps() const { return xdmf_->steps(); }
  void restoreSteps(std::vector<WrittenStep> steps) { xdmf_->restoreSteps(std::move(steps)); }

 private:
  void writeColumns(const Field<Dim>& field, int first_column, int components, const std::string& name);

  std::vector<std::string> material_names_;
  std::vector<std::string> fields_;
  std::string directory_;
  std::string run_name_;
  std::unique_ptr<Hdf5Writer> hdf5_;
  std::unique_ptr<XdmfWriter> xdmf_;
  std::vector<double> buffer_;
};

}  // namespace cfdmpm
