#pragma once
// Reads back what Hdf5Writer wrote, collectively (MPI-IO): root attributes, cell or node tables
// into a rank's owned entries, and rows of particle tables. Used to restart from a checkpoint.
//
// Every failure throws InputError naming the file and what is missing or wrong ("not an HDF5
// file", "no dataset /cells/state/density", "dataset ... has shape (40, 100), expected ..."), so
// that a bad checkpoint is refused like a bad scene. HDF5's own error printing is switched off
// while a reader exists. Every member function is collective.
#include "io/output_layout.hpp"

#include <mpi.h>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace cfdmpm {

class Hdf5Reader {
 public:
  /// Opens `path` read-only on every rank.
  Hdf5Reader(MPI_Comm comm, std::string path);
  ~Hdf5Reader();
  Hdf5Reader(const Hdf5Reader&) = delete;
  Hdf5Reader& operator=(const Hdf5Reader&) = delete;

  const std::string& path() const { return path_; }

  bool hasAttribute(const std::string& name) const;
  double attributeDouble(const std::string& name) const;
  long long attributeInteger(const std::string& name) const;
  std::vector<long long> attributeIntegers(const std::string& name) const;
  std::string attributeText(const std::string& name) const;

  /// True if the dataset `path` ("/cells/state/density") exists.
  bool hasDataset(const std::string& dataset) const;
  /// The dataset's dimensions, slowest first.
  std::vector<long long> datasetDims(const std::string& dataset) const;

  /// Reads this rank's owned entries of a table written by Hdf5Writer::writeTable (or a scalar or
  /// vector field) with `columns` values per entry, in ascending global index, into `values`
  /// (ownedCount(layout) * columns doubles). The dataset's shape must be datasetDims(layout, columns).
  void readTable(const OutputLayout& layout, const std::string& dataset, int columns, double* values) const;

  /// Reads rows [first, first + rows) of an (N, columns) or (N) dataset into `values`
  /// (rows * columns doubles). A rank may read no rows.
  void readRows(const std::string& dataset, long long first, long long rows, int columns, double* values) const;

 private:
  [[noreturn]] void fail(const std::string& what) const;
  std::int64_t openAttribute(const std::string& name) const;  // an HDF5 id; the caller closes it

  MPI_Comm comm_;
  std::string path_;
  std::int64_t file_ = -1;  // HDF5 id
  void* saved_error_data_ = nullptr;
  void* saved_error_function_ = nullptr;
};

}  // namespace cfdmpm
