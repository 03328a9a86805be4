#pragma once
// One HDF5 file per output step, written collectively by all ranks with MPI-IO.
//
//   <directory>/<run>_<step>.h5       (step zero-padded to 6 digits)
//     attributes  time (s), step
//     /cells      attributes count_xyz, origin_xyz, spacing_xyz; one dataset per cell field
//     /nodes      the same for node fields
//
//     /particles  attribute count (int64, over all ranks); one dataset per particle field, dims
//                 (N) for a scalar, (N, components) for a vector or tensor, rank 0's particles
//                 first, then rank 1's, ...; only in steps that write particle fields
//
//     /padded     2-D only: /padded/cells/<name>, /padded/nodes/<name>, each 2-D vector field
//                 again with a zero third component, for ParaView (its vectors have 3 components);
//                 /padded/particles/<name> for 2-component particle fields (position, velocity)
//
// A field name may contain slashes ("water/volume_fraction" becomes /cells/water/volume_fraction;
// the groups on the way are created). Datasets are float64 with dims (nz, ny, nx) in 3-D and
// (ny, nx) in 2-D, plus a trailing component dimension (= the grid dimension) for vector fields.
//
// The file is written as <name>.h5.tmp and renamed by rank 0 once every rank has closed it, so a
// file with the final name is always complete, whenever the run stops.
//
// Every member function is collective: all ranks call it in the same order with the same names,
// including ranks that own no entries.
#include "io/output_layout.hpp"

#include <mpi.h>

#include <cstdint>
#include <memory>
#include <utility>
#include <string>
#include <vector>

namespace cfdmpm {

/// One field of a written step, as the XDMF sidecar needs it.
struct WrittenField {
  OutputLocation location = OutputLocation::Cells;
  std::string name;             // as given, e.g. "water/volume_fraction"
  std::string dataset;          // path in the file, e.g. "/cells/water/volume_fraction"
  int components = 1;           // 1: scalar; dimension: vector; particles: any (9: stress tensor)
  std::vector<long long> dims;  // HDF5 dims, slowest first; particles: {N} or {N, components}
  // What a visualisation reads: the dataset itself, except for 2-D vectors, whose (x, y, 0)
  // copy lives at /padded/<location>/<name> with 3 components (ParaView's vectors have three).
  std::string display_dataset;
  std::vector<long long> display_dims;
};

/// What one output step put on disk; identical on every rank.
struct WrittenStep {
  std::string file;  // file name inside the output directory, e.g. "dam_000120.h5"
  long long step = 0;
  double time = 0;   // s
  std::vector<WrittenField> fields;
};

/// "<run>_<step>.h5" with the step zero-padded to 6 digits (more if needed).
std::string stepFileName(const std::string& run_name, long long step);

class Hdf5Writer {
 public:
  /// Checks the layouts (dimension 2 or 3, boxes inside the grid, owned counts adding up to the
  /// grid over all ranks) and throws std::invalid_argument on every rank if one is wrong.
  Hdf5Writer(MPI_Comm comm, std::string directory, std::string run_name, OutputLayout cells,
             OutputLayout nodes);
  /// An unfinished step is abandoned: its temporary file is closed and removed.
  ~Hdf5Writer();
  Hdf5Writer(const Hdf5Writer&) = delete;
  Hdf5Writer& operator=(const Hdf5Writer&) = delete;

  /// Creates <directory>/<run>_<step>.h5.tmp and writes the attributes time and step.
  void beginStep(long long step, double time);

  /// Writes a scalar field: `count` values, this rank's owned entries in ascending global index.
  void writeScalar(OutputLocation location, const std::string& name, const double* values,
                   std::size_t count);
  /// Writes a vector field with `dimension` components per entry, interleaved
  /// (values[entry * dimension + c]); `count` is the number of doubles.
  void writeVector(OutputLocation location, const std::string& name, const double* values,
                   std::size_t count);

  /// Particle fields (location Particles, group /particles). `local_count` is the number of this
  /// rank's particles (not of doubles); the ranks' particles are stored one after the other in rank
  /// order, each rank at the offset given by MPI_Exscan of the counts. A rank without particles
  /// passes 0 (values may be null) and still takes part. The first particle field of a step creates
  /// /particles with the attribute count (the total); every later one must have the same
  /// local_count on every rank (std::invalid_argument otherwise). The count may differ from step to
  /// step. A field named "position" is what the XDMF sidecar uses as the particles' geometry.
  void writeParticleScalar(const std::string& name, const double* values, std::size_t local_count);
  /// `components` values per particle, interleaved (values[particle * components + c]), e.g. the
  /// position with the grid dimension's components or the stress with 9 (row by row).
  void writeParticleVector(const std::string& name, const double* values, std::size_t local_count,
                           int components);

  /// A cell or node table of `columns` values per entry (any count, e.g. one per material),
  /// interleaved like a vector field, without the /padded copy: for files that are read back (the
  /// checkpoint), not displayed. `count` is the number of doubles.
  void writeTable(OutputLocation location, const std::string& name, const double* values,
                  std::size_t count, int columns);

  /// Attributes of the file's root group; the same value on every rank.
  void writeAttribute(const std::string& name, double value);
  void writeAttribute(const std::string& name, long long value);
  void writeAttribute(const std::string& name, const std::vector<long long>& values);
  void writeAttribute(const std::string& name, const std::string& text);

  /// Closes the file, renames it to its final name (rank 0) and returns what was written.
  WrittenStep endStep();

  bool stepOpen() const;
  const OutputLayout& layout(OutputLocation location) const;
  const std::string& directory() const { return directory_; }
  const std::string& runName() const { return run_name_; }

 private:
  struct OpenStep;
  void writeField(OutputLocation location, const std::string& name, int components,
                  const double* values, std::size_t count, bool display_copy = true);
  void writeDataset(const OutputLayout& grid, const std::string& path, int components,
                    const double* values, std::size_t count);
  std::int64_t fileSelection(const OutputLayout& grid, int components);  // an HDF5 dataspace id
  void writeParticleField(const std::string& name, int components, const double* values,
                          std::size_t local_count);
  void writeParticleDataset(const std::string& path, int components, const double* values,
                            std::size_t local_count);
  void checkNewField(OutputLocation location, const std::string& name);
  void abandonStep() noexcept;

  MPI_Comm comm_;
  std::string directory_;
  std::string run_name_;
  OutputLayout cells_;
  OutputLayout nodes_;
  std::unique_ptr<OpenStep> open_;
  // File dataspaces selecting this rank's boxes, per (layout, components); HDF5 ids.
  std::vector<std::pair<std::pair<const OutputLayout*, int>, std::int64_t>> selections_;
};

}  // namespace cfdmpm
