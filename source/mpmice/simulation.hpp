#pragma once
// A run of one scene from its initial state to its end time: set-up (grid, decomposition, state),
// output, and the time loop. ICE alone, MPM alone and the coupled method are this one driver with
// material sets present or absent.
#include "input/scene.hpp"

#include <Teuchos_Comm.hpp>

#include <string>

namespace cfdmpm {

struct RunOptions {
  bool overwrite = false;  // replace the output of an earlier run (also output.overwrite)
  // A restart: the checkpoint to continue from, and the run's name (its files' prefix) as the
  // first run chose it. The scene's output.directory is the one holding the checkpoint.
  std::string restart_checkpoint;
  std::string run_name;
};

struct RunSummary {
  std::string output_directory;
  std::string time_series;   // the XDMF time series for ParaView
  std::string diagnostics;   // the CSV time series
  long long steps = 0;
  double time = 0;           // simulated time reached (s)
  long long retried_steps = 0;    // steps of this run taken only after undone attempts
  long long undone_attempts = 0;  // the attempts undone (a step may be retried several times)
  bool stopped_by_signal = false;
};

/// Runs the scene on the communicator's ranks. Throws InputError for problems of the scene that
/// show only at set-up (too few patches for the ranks, an unwritable output directory, ...), before
/// anything is written.
RunSummary runScene(const Scene& scene, const RunOptions& options,
                    const Teuchos::RCP<const Teuchos::Comm<int>>& comm);

}  // namespace cfdmpm
