#pragma once
// Checkpoints: everything the next step of a run depends on, in one HDF5 file, so that
// `cfdmpm --restart` continues the run as if it had not stopped (bit for bit on as many ranks).
//
//   <output directory>/checkpoints/<run>_<step>.h5    (doc/output.md, "Checkpoints")
//     attributes  format, run_name, scene_path, scene (the scene file's text), ranks,
//                 decomposition (the rank of every patch), step, time, dt_previous, output_mark,
//                 checkpoint_mark, unconverged_warnings, output_steps (the time series' records)
//     /cells/state/<field>          every cell field of every material, all columns, owned cells
//                                   in global order (volume_fraction, density, specific_volume,
//                                   velocity, temperature, pressure)
//     /cells/ice/solid_reference_pressure   when the fluids move
//     /particles/packed             (N, columns): every particle's whole state in the order of
//                                   Particles::pack (names in the attribute particle_columns),
//                                   rank 0's particles first; attribute particle_rank_counts
//
// Written like the step files (a temporary name, renamed once every rank has closed it): a
// checkpoint with its final name is complete. What else a step depends on is rebuilt the same way
// on restart: the grid (from the scene) and its decomposition (the checkpoint's on as many ranks,
// which a rebalance may have made differ from the first; otherwise METIS for the new count), the
// particle bins (from the particles), node fields (every step starts from the particles), and the
// pressure solver's preconditioner: writing a checkpoint makes the next solve build a fresh MueLu
// hierarchy in the running run too (IceSolver::restartPreconditionerSchedule), so both continue
// from the same reuse schedule.
#include "fields/cell_state.hpp"
#include "io/hdf5_writer.hpp"
#include "mpmice/mpmice_step.hpp"
#include "mpmice/run_state.hpp"

#include <mpi.h>

#include <memory>
#include <string>
#include <vector>

namespace cfdmpm {

/// The driver's own state between steps.
struct RunClock {
  long long step = 0;
  double time = 0;             // s
  double dt_previous = 0;      // the last step's Δt limit before clipping to output times (s)
  double output_mark = 0;      // the next output time before it is clipped to the end time (s)
  double checkpoint_mark = 0;  // the next checkpoint time, simulated (s)
  int unconverged_warnings = 0;
};

/// What a restart needs before it builds anything: read by every rank from the checkpoint.
struct CheckpointHeader {
  std::string path;              // the checkpoint file
  std::string output_directory;  // the directory of the run (the checkpoint's folder's parent)
  std::string run_name;
  std::string scene_path;        // the first run's scene file, as named then
  std::string scene_text;        // its text
  long long step = 0;
  double time = 0;
  int ranks = 0;
  std::vector<int> decomposition;  // the rank of every patch when the checkpoint was written
};

/// The checkpoint to restart from: `file_or_directory` itself, or the newest checkpoint in
/// <directory>/checkpoints/. Throws InputError naming the path and what is missing.
std::string findCheckpoint(const std::string& file_or_directory);

/// Opens the checkpoint and reads its header; collective. Throws InputError (file named) if the
/// file is missing, not HDF5 or not a cfdmpm checkpoint.
CheckpointHeader readCheckpointHeader(MPI_Comm comm, const std::string& path);

/// Refuses (InputError) a scene given with --restart that does not fit the checkpoint: another
/// dimension, domain, cells, patches, ghost width or list of materials.
void checkRestartScene(const Scene& scene, const Scene& checkpoint_scene);

template <int Dim>
class CheckpointWriter {
 public:
  /// Checkpoints go to <output_directory>/checkpoints/, created here if missing (collective).
  CheckpointWriter(const Scene& scene, const Layout<Dim>& layout, const std::string& run_name,
                   const std::string& output_directory);

  /// Writes the checkpoint of `clock.step` and keeps only the newest output.checkpoints_kept;
  /// returns its path. Collective.
  std::string write(const RunClock& clock, const CellState<Dim>& state, MpmIceStep<Dim>& stepper,
                    const std::vector<WrittenStep>& output_steps);

 private:
  void writeField(const Field<Dim>& field, const std::string& name);

  const Scene& scene_;
  const Layout<Dim>& layout_;
  std::string run_name_;
  std::string output_directory_;
  std::unique_ptr<Hdf5Writer> hdf5_;
  std::vector<double> buffer_;
};

/// Loads a checkpoint into a run state freshly built by buildRunState (every rank, collective),
/// through adoptState: cell fields with their halos, the fluid solver's solid reference pressure,
/// the particles (on the same number of ranks each rank gets back its own, in their order;
/// otherwise they go to the owners of their cells). Returns the driver's clock; `output_steps` gets
/// the records of the step files written up to the checkpoint.
template <int Dim>
RunClock readCheckpoint(const std::string& path, RunState<Dim>& run, std::vector<WrittenStep>& output_steps);

extern template class CheckpointWriter<2>;
extern template class CheckpointWriter<3>;

}  // namespace cfdmpm
