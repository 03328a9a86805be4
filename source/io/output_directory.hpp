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
///    "output.directory: '<path>' exists and is not empty; choose another directory or set
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

}  // namespace cfdmpm
