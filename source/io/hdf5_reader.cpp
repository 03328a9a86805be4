#include "io/hdf5_reader.hpp"

#include "common/error.hpp"
#include "io/collective.hpp"
#include "io/hdf5_common.hpp"

#include <hdf5.h>

#include <filesystem>
#include <sstream>

namespace cfdmpm {

static_assert(std::is_same_v<hid_t, std::int64_t>, "Hdf5Reader keeps HDF5 ids as std::int64_t");

using io_detail::anyRank;
using io_detail::H5Handle;
using io_detail::kTextDatasetGroup;

namespace {

std::string shape(const std::vector<long long>& dims)
{
  std::ostringstream text;
  text << "(";
  for (std::size_t i = 0; i < dims.size(); ++i) text << (i ? ", " : "") << dims[i];
  text << (dims.size() == 1 ? ",)" : ")");
  return text.str();
}

}  // namespace

Hdf5Reader::Hdf5Reader(MPI_Comm comm, std::string path) : comm_(comm), path_(std::move(path))
{
  // Failures are reported by the exceptions below; HDF5's stack dump would only bury them.
  H5E_auto2_t function = nullptr;
  H5Eget_auto2(H5E_DEFAULT, &function, &saved_error_data_);
  saved_error_function_ = reinterpret_cast<void*>(function);
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);

  std::error_code error;
  const bool exists = std::filesystem::is_regular_file(path_, error);
  if (anyRank(comm_, !exists)) fail("no such file");
  H5Handle access(H5Pcreate(H5P_FILE_ACCESS), H5Pclose);
  bool ok = access.get() >= 0 && H5Pset_fapl_mpio(access.get(), comm_, MPI_INFO_NULL) >= 0 &&
            H5Pset_all_coll_metadata_ops(access.get(), true) >= 0;
  if (ok) file_ = H5Fopen(path_.c_str(), H5F_ACC_RDONLY, access.get());
  if (anyRank(comm_, !ok || file_ < 0)) fail("not a readable HDF5 file (truncated or not written by cfdmpm?)");
}

Hdf5Reader::~Hdf5Reader()
{
  if (file_ >= 0 && H5Iis_valid(file_) > 0) H5Fclose(file_);
  H5Eset_auto2(H5E_DEFAULT, reinterpret_cast<H5E_auto2_t>(saved_error_function_), saved_error_data_);
}

void Hdf5Reader::fail(const std::string& what) const
{
  throw InputError("checkpoint '" + path_ + "': " + what);
}

bool Hdf5Reader::hasAttribute(const std::string& name) const
{
  return H5Aexists(file_, name.c_str()) > 0 || hasDataset(kTextDatasetGroup + name);
}

std::int64_t Hdf5Reader::openAttribute(const std::string& name) const
{
  const hid_t attribute = hasAttribute(name) ? H5Aopen(file_, name.c_str(), H5P_DEFAULT) : H5I_INVALID_HID;
  if (attribute < 0) fail("no attribute '" + name + "'");
  return attribute;
}

double Hdf5Reader::attributeDouble(const std::string& name) const
{
  H5Handle attribute(openAttribute(name), H5Aclose);
  double value = 0;
  H5Handle space(H5Aget_space(attribute.get()), H5Sclose);
  if (H5Sget_simple_extent_npoints(space.get()) != 1 || H5Aread(attribute.get(), H5T_NATIVE_DOUBLE, &value) < 0)
    fail("attribute '" + name + "' is not one number");
  return value;
}

long long Hdf5Reader::attributeInteger(const std::string& name) const
{
  H5Handle attribute(openAttribute(name), H5Aclose);
  H5Handle type(H5Aget_type(attribute.get()), H5Tclose);
  H5Handle space(H5Aget_space(attribute.get()), H5Sclose);
  long long value = 0;
  if (H5Tget_class(type.get()) != H5T_INTEGER || H5Sget_simple_extent_npoints(space.get()) != 1 ||
      H5Aread(attribute.get(), H5T_NATIVE_LLONG, &value) < 0)
    fail("attribute '" + name + "' is not one integer");
  return value;
}

std::vector<long long> Hdf5Reader::attributeIntegers(const std::string& name) const
{
  H5Handle attribute(openAttribute(name), H5Aclose);
  H5Handle type(H5Aget_type(attribute.get()), H5Tclose);
  H5Handle space(H5Aget_space(attribute.get()), H5Sclose);
  const hssize_t n = H5Sget_simple_extent_npoints(space.get());
  std::vector<long long> values(n > 0 ? std::size_t(n) : 0);
  if (H5Tget_class(type.get()) != H5T_INTEGER || n < 1 ||
      H5Aread(attribute.get(), H5T_NATIVE_LLONG, values.data()) < 0)
    fail("attribute '" + name + "' is not a list of integers");
  return values;
}

std::string Hdf5Reader::attributeText(const std::string& name) const
{
  const std::string long_text = kTextDatasetGroup + name;  // Hdf5Writer's form of a long text
  if (H5Aexists(file_, name.c_str()) <= 0 && hasDataset(long_text)) {
    const std::vector<long long> dims = datasetDims(long_text);
    if (dims.size() != 1) fail("dataset " + long_text + " is not a text");
    std::string text(std::size_t(dims[0]), '\0');
    H5Handle set(H5Dopen2(file_, long_text.c_str(), H5P_DEFAULT), H5Dclose);
    if (H5Dread(set.get(), H5T_NATIVE_UCHAR, H5S_ALL, H5S_ALL, H5P_DEFAULT, text.data()) < 0)
      fail("dataset " + long_text + " cannot be read");
    return text.substr(0, text.find('\0'));
  }
  H5Handle attribute(openAttribute(name), H5Aclose);
  H5Handle type(H5Aget_type(attribute.get()), H5Tclose);
  if (H5Tget_class(type.get()) != H5T_STRING || H5Tis_variable_str(type.get()) > 0)
    fail("attribute '" + name + "' is not a fixed-length text");
  std::string text(H5Tget_size(type.get()), '\0');
  if (H5Aread(attribute.get(), type.get(), text.data()) < 0) fail("attribute '" + name + "' cannot be read");
  return text.substr(0, text.find('\0'));
}

bool Hdf5Reader::hasDataset(const std::string& dataset) const
{
  // H5Lexists fails on a path whose intermediate groups are missing: test each part.
  std::size_t position = 0;
  while ((position = dataset.find('/', position + 1)) != std::string::npos)
    if (H5Lexists(file_, dataset.substr(0, position).c_str(), H5P_DEFAULT) <= 0) return false;
  return H5Lexists(file_, dataset.c_str(), H5P_DEFAULT) > 0;
}

std::vector<long long> Hdf5Reader::datasetDims(const std::string& dataset) const
{
  if (!hasDataset(dataset)) fail("no dataset " + dataset);
  H5Handle set(H5Dopen2(file_, dataset.c_str(), H5P_DEFAULT), H5Dclose);
  H5Handle space(H5Dget_space(set.get()), H5Sclose);
  const int rank = H5Sget_simple_extent_ndims(space.get());
  if (set.get() < 0 || rank < 0) fail("dataset " + dataset + " cannot be read");
  std::vector<hsize_t> dims(std::size_t(rank), 0);
  H5Sget_simple_extent_dims(space.get(), dims.data(), nullptr);
  return std::vector<long long>(dims.begin(), dims.end());
}

void Hdf5Reader::readTable(const OutputLayout& layout, const std::string& dataset, int columns, double* values) const
{
  const std::vector<long long> expected = cfdmpm::datasetDims(layout, columns);
  const std::vector<long long> found = datasetDims(dataset);
  if (found != expected) fail("dataset " + dataset + " has shape " + shape(found) + ", expected " + shape(expected));
  H5Handle set(H5Dopen2(file_, dataset.c_str(), H5P_DEFAULT), H5Dclose);
  H5Handle file_space = io_detail::ownedSelection(layout, columns);
  const long long count = ownedCount(layout) * columns;
  const hsize_t memory_length = count > 0 ? hsize_t(count) : 1;
  H5Handle memory_space(H5Screate_simple(1, &memory_length, nullptr), H5Sclose);
  if (count == 0) H5Sselect_none(memory_space.get());
  H5Handle transfer(H5Pcreate(H5P_DATASET_XFER), H5Pclose);
  H5Pset_dxpl_mpio(transfer.get(), H5FD_MPIO_COLLECTIVE);
  double unused = 0;
  const herr_t status =
      H5Dread(set.get(), H5T_NATIVE_DOUBLE, memory_space.get(), file_space.get(), transfer.get(), count > 0 ? values : &unused);
  if (anyRank(comm_, status < 0)) fail("reading dataset " + dataset + " failed");
}

void Hdf5Reader::readRows(const std::string& dataset, long long first, long long rows, int columns, double* values) const
{
  const std::vector<long long> found = datasetDims(dataset);
  const bool matches = (found.size() == 1 && columns == 1) || (found.size() == 2 && found[1] == columns);
  if (!matches)
    fail("dataset " + dataset + " has shape " + shape(found) + ", expected (N, " + std::to_string(columns) + ")");
  if (anyRank(comm_, first < 0 || rows < 0 || first + rows > found[0]))
    fail("dataset " + dataset + " has " + std::to_string(found[0]) + " rows, fewer than the particle counts say");
  H5Handle set(H5Dopen2(file_, dataset.c_str(), H5P_DEFAULT), H5Dclose);
  H5Handle file_space(H5Dget_space(set.get()), H5Sclose);
  std::vector<hsize_t> start{hsize_t(first)}, extent{hsize_t(rows)};
  if (found.size() == 2) start.push_back(0), extent.push_back(hsize_t(columns));
  if (rows > 0)
    H5Sselect_hyperslab(file_space.get(), H5S_SELECT_SET, start.data(), nullptr, extent.data(), nullptr);
  else
    H5Sselect_none(file_space.get());
  const hsize_t memory_length = rows > 0 ? hsize_t(rows * columns) : 1;
  H5Handle memory_space(H5Screate_simple(1, &memory_length, nullptr), H5Sclose);
  if (rows == 0) H5Sselect_none(memory_space.get());
  H5Handle transfer(H5Pcreate(H5P_DATASET_XFER), H5Pclose);
  H5Pset_dxpl_mpio(transfer.get(), H5FD_MPIO_COLLECTIVE);
  double unused = 0;
  // An empty dataset has no storage: nothing to read on any rank.
  herr_t status = 0;
  if (found[0] > 0)
    status = H5Dread(set.get(), H5T_NATIVE_DOUBLE, memory_space.get(), file_space.get(), transfer.get(),
                     rows > 0 ? values : &unused);
  if (anyRank(comm_, status < 0)) fail("reading dataset " + dataset + " failed");
}

}  // namespace cfdmpm
