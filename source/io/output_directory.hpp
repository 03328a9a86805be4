#pragma once
// The output directory (scene key output.directory): created before anything is written and never
// silently overwritten.
#include <mpi.h>

#include <string>
#include <vector>

namespace cfdmpm {

/// Prepares `directory` for a run; collective, rank 0 touches the file system and every rank gets
/// the same outcome.
///  - missing: created, with its parents;
///  - exists and empty: used as it is;
///  - exists, not empty, overwrite false: throws InputError
///    "cfdmpm.output.directory: '<path>' exists and is not empty; choose another directory or set
///    output.overwrite: true", and nothing is changed;
///  - exists, not empty, overwrite true: the files cfdmpm writes there (see isOutputFile) are
///    removed, everything else is left alone.
/// A path that exists but is not a directory, or cannot be created, throws InputError too.
void prepareOutputDirectory(MPI_Comm comm, const std::string& directory, bool overwrite);

/// What prepareOutputDirectory would refuse, found without creating or removing anything (for
/// `cfdmpm --check`); collective like it. A missing directory passes when its nearest existing
/// parent is a writable directory.
void checkOutputDirectory(MPI_Comm comm, const std::string& directory, bool overwrite);

/// True for the names of files cfdmpm writes into an output directory: *.h5, *.xmf, *.csv, *.tmp.
bool isOutputFile(const std::string& file_name);

/// Where a run's checkpoints go: <directory>/checkpoints (prepareOutputDirectory with overwrite
/// removes cfdmpm's files there too).
std::string checkpointDirectory(const std::string& output_directory);

/// Creates `directory` (with its parents) if it does not exist. Collective; rank 0 works.
void createDirectory(MPI_Comm comm, const std::string& directory);

/// The step of "<run>_<step><extension>" (e.g. "dam_000120.h5"), or -1 for any other name.
long long stepOfFile(const std::string& file_name, const std::string& run_name, const std::string& extension);

/// The checkpoints of run `run_name` in `checkpoint_directory`, oldest (lowest step) first.
std::vector<std::string> listCheckpoints(const std::string& checkpoint_directory, const std::string& run_name);

/// Before a run continues from the checkpoint of step `step`: removes, on rank 0, what the first
/// run wrote after that step (step files <run>_<n>.h5 and .xmf with n > step, checkpoints with
/// n > step) and any *.tmp file left by a run that was killed. Collective.
void prepareRestartDirectory(MPI_Comm comm, const std::string& directory, const std::string& run_name, long long step);

/// Removes all but the newest `kept` checkpoints of the run. Collective; rank 0 works.
void pruneCheckpoints(MPI_Comm comm, const std::string& output_directory, const std::string& run_name, int kept);

}  // namespace cfdmpm
