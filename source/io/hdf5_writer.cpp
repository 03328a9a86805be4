#include "io/hdf5_writer.hpp"

#include "io/collective.hpp"
#include "io/hdf5_common.hpp"

#include <hdf5.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <stdexcept>
#include <type_traits>
#include <utility>

namespace cfdmpm {

static_assert(std::is_same_v<hid_t, std::int64_t>, "Hdf5Writer keeps HDF5 ids as std::int64_t");

namespace {

using io_detail::anyRank;
using io_detail::checked;
using io_detail::H5Handle;
using io_detail::kLargestTextAttribute;
using io_detail::kTextDatasetGroup;
using io_detail::onRankZero;
using io_detail::rankOf;

void writeRawAttribute(hid_t object, const char* name, hid_t memory_type, hid_t file_type,
                    const void* data, hsize_t length)
{
  H5Handle space(checked(length == 1 ? H5Screate(H5S_SCALAR) : H5Screate_simple(1, &length, nullptr),
                         std::string("dataspace of attribute ") + name),
                 H5Sclose);
  H5Handle attribute(checked(H5Acreate2(object, name, file_type, space.get(), H5P_DEFAULT, H5P_DEFAULT),
                             std::string("creating attribute ") + name),
                     H5Aclose);
  checked(H5Awrite(attribute.get(), memory_type, data), std::string("writing attribute ") + name);
}

/// The location's grid description, x first, as attributes of its group.
void writeLayoutAttributes(hid_t group, const OutputLayout& layout)
{
  const hsize_t n = static_cast<hsize_t>(layout.dimension);
  writeRawAttribute(group, "count_xyz", H5T_NATIVE_LLONG, H5T_STD_I64LE, layout.global_count.data(), n);
  writeRawAttribute(group, "origin_xyz", H5T_NATIVE_DOUBLE, H5T_IEEE_F64LE, layout.origin.data(), n);
  writeRawAttribute(group, "spacing_xyz", H5T_NATIVE_DOUBLE, H5T_IEEE_F64LE, layout.spacing.data(), n);
}

bool isNameCharacter(char c)
{
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' ||
         c == '-' || c == '.';
}

/// Field names become HDF5 paths and XDMF attribute names: slash-separated parts of
/// letters, digits, '_', '-', '.'.
void checkFieldName(const std::string& name)
{
  std::size_t start = 0;
  while (true) {
    std::size_t end = name.find('/', start);
    std::string part = name.substr(start, end == std::string::npos ? std::string::npos : end - start);
    bool valid = !part.empty() && part != "." && part != "..";
    for (char c : part) valid = valid && isNameCharacter(c);
    if (!valid)
      throw std::invalid_argument("output field name '" + name +
                                  "': parts separated by '/' must be non-empty and use only "
                                  "letters, digits, '_', '-', '.'");
    if (end == std::string::npos) break;
    start = end + 1;
  }
}

bool isPathPrefix(const std::string& prefix, const std::string& path)
{
  return path.size() > prefix.size() && path.compare(0, prefix.size(), prefix) == 0 &&
         path[prefix.size()] == '/';
}

/// Empty if the layout is usable, otherwise what is wrong with it.
std::string layoutProblem(const OutputLayout& layout, const char* location)
{
  const std::string where = std::string("output layout of ") + location + ": ";
  if (layout.dimension != 2 && layout.dimension != 3) return where + "dimension must be 2 or 3";
  for (int d = 0; d < 3; ++d) {
    if (d < layout.dimension && layout.global_count[d] < 1)
      return where + "global_count must be at least 1 in every used direction";
    if (d >= layout.dimension && layout.global_count[d] != 1)
      return where + "global_count must be 1 in unused directions";
    if (d < layout.dimension && !(layout.spacing[d] > 0)) return where + "spacing must be positive";
  }
  for (const Box& box : layout.owned_boxes)
    for (int d = 0; d < 3; ++d)
      if (box.lower[d] < 0 || box.upper[d] < box.lower[d] || box.upper[d] > layout.global_count[d])
        return where + "an owned box lies outside the grid";
  return {};
}

}  // namespace

H5Handle io_detail::ownedSelection(const OutputLayout& grid, int components)
{
  const std::vector<long long> dims = datasetDims(grid, components);
  std::vector<hsize_t> file_dims(dims.begin(), dims.end());
  H5Handle space(checked(H5Screate_simple(static_cast<int>(file_dims.size()), file_dims.data(), nullptr),
                         "file dataspace"),
                 H5Sclose);
  checked(H5Sselect_none(space.get()), "H5Sselect_none");
  bool first = true;
  for (const Box& box : grid.owned_boxes) {
    if (box.count() == 0) continue;
    std::vector<hsize_t> start, extent;
    for (int d = grid.dimension - 1; d >= 0; --d) {
      start.push_back(static_cast<hsize_t>(box.lower[d]));
      extent.push_back(static_cast<hsize_t>(box.extent(d)));
    }
    if (components > 1) {
      start.push_back(0);
      extent.push_back(static_cast<hsize_t>(components));
    }
    checked(H5Sselect_hyperslab(space.get(), first ? H5S_SELECT_SET : H5S_SELECT_OR, start.data(),
                                nullptr, extent.data(), nullptr),
            "selecting an owned box");
    first = false;
  }
  return space;
}

std::string stepFileName(const std::string& run_name, long long step)
{
  char number[32];
  std::snprintf(number, sizeof number, "%06lld", step);
  return run_name + "_" + number + ".h5";
}

struct Hdf5Writer::OpenStep {
  H5Handle file;
  H5Handle transfer;  // dataset transfer properties: collective MPI-IO
  H5Handle link_creation;  // creates the groups on a field's path
  H5Handle dataset_creation;
  H5Handle group_creation;
  std::string temporary_path;
  std::string final_path;
  WrittenStep record;
  // Particles of this step: set by the first particle field.
  bool have_particles = false;
  std::size_t particle_local = 0;    // this rank's particles
  long long particle_offset = 0;     // particles on the ranks before this one
  long long particle_total = 0;
};

Hdf5Writer::Hdf5Writer(MPI_Comm comm, std::string directory, std::string run_name,
                       OutputLayout cells, OutputLayout nodes)
    : comm_(comm),
      directory_(std::move(directory)),
      run_name_(std::move(run_name)),
      cells_(std::move(cells)),
      nodes_(std::move(nodes))
{
  std::string problem = layoutProblem(cells_, "cells");
  if (problem.empty()) problem = layoutProblem(nodes_, "nodes");
  if (problem.empty() && cells_.dimension != nodes_.dimension)
    problem = "output layouts of cells and nodes have different dimensions";
  if (anyRank(comm_, !problem.empty()))
    throw std::invalid_argument(problem.empty() ? "output layout invalid on another rank" : problem);

  // Owned entries over all ranks must cover the grid; with disjoint boxes this means exactly once.
  for (const OutputLayout* layout : {&cells_, &nodes_}) {
    long long owned = ownedCount(*layout), total = 0;
    MPI_Allreduce(&owned, &total, 1, MPI_LONG_LONG, MPI_SUM, comm_);
    if (total != globalCount(*layout))
      throw std::invalid_argument(std::string("output layout of ") +
                                  (layout == &cells_ ? "cells" : "nodes") + ": ranks own " +
                                  std::to_string(total) + " entries, the grid has " +
                                  std::to_string(globalCount(*layout)));
  }
}

Hdf5Writer::~Hdf5Writer()
{
  abandonStep();
  // After MPI_Finalize HDF5 has closed itself and the ids are gone.
  for (const auto& selection : selections_)
    if (H5Iis_valid(selection.second) > 0) H5Sclose(selection.second);
}

bool Hdf5Writer::stepOpen() const { return open_ != nullptr; }

const OutputLayout& Hdf5Writer::layout(OutputLocation location) const
{
  return location == OutputLocation::Cells ? cells_ : nodes_;
}

void Hdf5Writer::beginStep(long long step, double time)
{
  if (open_) throw std::logic_error("Hdf5Writer::beginStep: the previous step was not ended");
  auto open = std::make_unique<OpenStep>();
  open->record.file = stepFileName(run_name_, step);
  open->record.step = step;
  open->record.time = time;
  open->final_path = (std::filesystem::path(directory_) / open->record.file).string();
  open->temporary_path = open->final_path + ".tmp";

  H5Handle access(checked(H5Pcreate(H5P_FILE_ACCESS), "file access properties"), H5Pclose);
  checked(H5Pset_fapl_mpio(access.get(), comm_, MPI_INFO_NULL), "H5Pset_fapl_mpio");
  // Metadata reads and writes collective too: one rank touches the file system, not all of them.
  checked(H5Pset_all_coll_metadata_ops(access.get(), true), "H5Pset_all_coll_metadata_ops");
  checked(H5Pset_coll_metadata_write(access.get(), true), "H5Pset_coll_metadata_write");
  open->file = H5Handle(checked(H5Fcreate(open->temporary_path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT,
                                          access.get()),
                                "creating " + open->temporary_path),
                        H5Fclose);

  open->transfer = H5Handle(checked(H5Pcreate(H5P_DATASET_XFER), "transfer properties"), H5Pclose);
  checked(H5Pset_dxpl_mpio(open->transfer.get(), H5FD_MPIO_COLLECTIVE), "H5Pset_dxpl_mpio");
  open->link_creation = H5Handle(checked(H5Pcreate(H5P_LINK_CREATE), "link properties"), H5Pclose);
  checked(H5Pset_create_intermediate_group(open->link_creation.get(), 1),
          "H5Pset_create_intermediate_group");
  open->dataset_creation =
      H5Handle(checked(H5Pcreate(H5P_DATASET_CREATE), "dataset properties"), H5Pclose);
  // Every entry is written, so HDF5 need not write fill values first.
  checked(H5Pset_fill_time(open->dataset_creation.get(), H5D_FILL_TIME_NEVER), "H5Pset_fill_time");
  // No modification times in the object headers: the same data gives the same bytes, so the step
  // files of a restarted run compare equal (cmp) with those of a run that never stopped.
  checked(H5Pset_obj_track_times(open->dataset_creation.get(), false), "H5Pset_obj_track_times");
  open->group_creation = H5Handle(checked(H5Pcreate(H5P_GROUP_CREATE), "group properties"), H5Pclose);
  checked(H5Pset_obj_track_times(open->group_creation.get(), false), "H5Pset_obj_track_times");

  writeRawAttribute(open->file.get(), "time", H5T_NATIVE_DOUBLE, H5T_IEEE_F64LE, &time, 1);
  writeRawAttribute(open->file.get(), "step", H5T_NATIVE_LLONG, H5T_STD_I64LE, &step, 1);
  for (OutputLocation location : {OutputLocation::Cells, OutputLocation::Nodes}) {
    H5Handle group(checked(H5Gcreate2(open->file.get(), locationName(location), H5P_DEFAULT,
                                      open->group_creation.get(), H5P_DEFAULT),
                           std::string("creating group /") + locationName(location)),
                   H5Gclose);
    writeLayoutAttributes(group.get(), layout(location));
  }
  open_ = std::move(open);
}

void Hdf5Writer::writeScalar(OutputLocation location, const std::string& name,
                             const double* values, std::size_t count)
{
  writeField(location, name, 1, values, count);
}

void Hdf5Writer::writeVector(OutputLocation location, const std::string& name,
                             const double* values, std::size_t count)
{
  writeField(location, name, layout(location).dimension, values, count);
}

void Hdf5Writer::writeTable(OutputLocation location, const std::string& name, const double* values,
                            std::size_t count, int columns)
{
  if (columns < 1) throw std::invalid_argument("output table '" + name + "': columns must be at least 1");
  writeField(location, name, columns, values, count, false);
}

void Hdf5Writer::writeAttribute(const std::string& name, double value)
{
  if (!open_) throw std::logic_error("Hdf5Writer: attribute '" + name + "' outside beginStep/endStep");
  writeRawAttribute(open_->file.get(), name.c_str(), H5T_NATIVE_DOUBLE, H5T_IEEE_F64LE, &value, 1);
}

void Hdf5Writer::writeAttribute(const std::string& name, long long value)
{
  if (!open_) throw std::logic_error("Hdf5Writer: attribute '" + name + "' outside beginStep/endStep");
  writeRawAttribute(open_->file.get(), name.c_str(), H5T_NATIVE_LLONG, H5T_STD_I64LE, &value, 1);
}

void Hdf5Writer::writeAttribute(const std::string& name, const std::vector<long long>& values)
{
  if (!open_) throw std::logic_error("Hdf5Writer: attribute '" + name + "' outside beginStep/endStep");
  if (values.empty()) throw std::invalid_argument("Hdf5Writer: attribute '" + name + "' has no values");
  const hsize_t length = values.size();
  H5Handle space(checked(H5Screate_simple(1, &length, nullptr), "dataspace of attribute " + name), H5Sclose);
  H5Handle attribute(checked(H5Acreate2(open_->file.get(), name.c_str(), H5T_STD_I64LE, space.get(), H5P_DEFAULT,
                                        H5P_DEFAULT),
                             "creating attribute " + name),
                     H5Aclose);
  checked(H5Awrite(attribute.get(), H5T_NATIVE_LLONG, values.data()), "writing attribute " + name);
}

void Hdf5Writer::writeAttribute(const std::string& name, const std::string& text)
{
  if (!open_) throw std::logic_error("Hdf5Writer: attribute '" + name + "' outside beginStep/endStep");
  const std::string stored = text.empty() ? std::string(1, '\0') : text;
  if (stored.size() > kLargestTextAttribute) {
    // An object header holds at most 64 KiB of attributes (HDF5's compact storage), and a run's
    // record of written steps outgrows that after some tens of outputs: a long text goes into the
    // byte dataset /attributes/<name> instead, which Hdf5Reader::attributeText reads the same way.
    const hsize_t length = stored.size();
    H5Handle file_space(checked(H5Screate_simple(1, &length, nullptr), "dataspace of " + name), H5Sclose);
    H5Handle memory_space(checked(H5Screate_simple(1, &length, nullptr), "memory dataspace"), H5Sclose);
    const std::string path = std::string(kTextDatasetGroup) + name;
    H5Handle dataset(checked(H5Dcreate2(open_->file.get(), path.c_str(), H5T_STD_U8LE, file_space.get(),
                                        open_->link_creation.get(), open_->dataset_creation.get(), H5P_DEFAULT),
                             "creating dataset " + path),
                     H5Dclose);
    // The same text on every rank: rank 0 writes it, the others select nothing (collective write).
    int rank = 0;
    MPI_Comm_rank(comm_, &rank);
    if (rank != 0) {
      checked(H5Sselect_none(file_space.get()), "H5Sselect_none");
      checked(H5Sselect_none(memory_space.get()), "H5Sselect_none");
    }
    checked(H5Dwrite(dataset.get(), H5T_NATIVE_UCHAR, memory_space.get(), file_space.get(), open_->transfer.get(),
                     stored.data()),
            "writing dataset " + path);
    return;
  }
  // A variable-length string would be stored in the global heap; a fixed-length one of the text's
  // size (at least 1) reads back with h5py as bytes and needs no collective heap writes.
  H5Handle type(checked(H5Tcopy(H5T_C_S1), "string type"), H5Tclose);
  checked(H5Tset_size(type.get(), stored.size()), "H5Tset_size");
  checked(H5Tset_strpad(type.get(), H5T_STR_NULLPAD), "H5Tset_strpad");
  H5Handle space(checked(H5Screate(H5S_SCALAR), "dataspace of attribute " + name), H5Sclose);
  H5Handle attribute(checked(H5Acreate2(open_->file.get(), name.c_str(), type.get(), space.get(), H5P_DEFAULT,
                                        H5P_DEFAULT),
                             "creating attribute " + name),
                     H5Aclose);
  checked(H5Awrite(attribute.get(), type.get(), stored.data()), "writing attribute " + name);
}

void Hdf5Writer::writeField(OutputLocation location, const std::string& name, int components,
                            const double* values, std::size_t count, bool display_copy)
{
  if (!open_) throw std::logic_error("Hdf5Writer: write '" + name + "' outside beginStep/endStep");
  if (location == OutputLocation::Particles)
    throw std::invalid_argument("Hdf5Writer: particle field '" + name +
                                "' goes through writeParticleScalar/writeParticleVector");
  checkNewField(location, name);
  const std::string dataset_path = std::string("/") + locationName(location) + "/" + name;

  const OutputLayout& grid = layout(location);
  const std::size_t expected = static_cast<std::size_t>(ownedCount(grid)) * components;
  if (anyRank(comm_, count != expected || (count > 0 && values == nullptr)))
    throw std::invalid_argument("output field '" + dataset_path + "': a rank passed " +
                                (count != expected ? std::to_string(count) + " values for " +
                                                         std::to_string(expected) + " owned"
                                                   : std::string("wrong buffer sizes")));

  writeDataset(grid, dataset_path, components, values, count);
  WrittenField field{location, name, dataset_path, components, datasetDims(grid, components),
                     dataset_path, datasetDims(grid, components)};
  if (components == 2 && display_copy) {
    std::vector<double> padded(count / 2 * 3, 0.0);
    for (std::size_t entry = 0; entry < count / 2; ++entry) {
      padded[3 * entry] = values[2 * entry];
      padded[3 * entry + 1] = values[2 * entry + 1];
    }
    field.display_dataset = std::string("/padded/") + locationName(location) + "/" + name;
    field.display_dims = datasetDims(grid, 3);
    writeDataset(grid, field.display_dataset, 3, padded.data(), padded.size());
  }
  open_->record.fields.push_back(std::move(field));
}

void Hdf5Writer::checkNewField(OutputLocation location, const std::string& name)
{
  checkFieldName(name);
  const std::string dataset_path = std::string("/") + locationName(location) + "/" + name;
  for (const WrittenField& field : open_->record.fields)
    if (field.location == location &&
        (field.name == name || isPathPrefix(field.name, name) || isPathPrefix(name, field.name)))
      throw std::invalid_argument("output field '" + dataset_path + "' clashes with '" +
                                  field.dataset + "' already written in this step");
}

void Hdf5Writer::writeParticleScalar(const std::string& name, const double* values,
                                     std::size_t local_count)
{
  writeParticleField(name, 1, values, local_count);
}

void Hdf5Writer::writeParticleVector(const std::string& name, const double* values,
                                     std::size_t local_count, int components)
{
  writeParticleField(name, components, values, local_count);
}

void Hdf5Writer::writeParticleField(const std::string& name, int components, const double* values,
                                    std::size_t local_count)
{
  if (!open_) throw std::logic_error("Hdf5Writer: write '" + name + "' outside beginStep/endStep");
  checkNewField(OutputLocation::Particles, name);
  const std::string dataset_path = "/particles/" + name;
  if (anyRank(comm_, components < 1 || (local_count > 0 && values == nullptr) ||
                         (open_->have_particles && local_count != open_->particle_local)))
    throw std::invalid_argument(
        "output field '" + dataset_path + "': " +
        (components < 1 ? std::string("components must be at least 1")
         : open_->have_particles && local_count != open_->particle_local
             ? "a rank passed " + std::to_string(local_count) + " particles, earlier fields of this step " +
                   std::to_string(open_->particle_local)
             : std::string("a rank passed wrong buffer sizes or particle counts")));

  if (!open_->have_particles) {
    long long local = static_cast<long long>(local_count), offset = 0, total = 0;
    MPI_Exscan(&local, &offset, 1, MPI_LONG_LONG, MPI_SUM, comm_);
    if (rankOf(comm_) == 0) offset = 0;  // MPI_Exscan leaves rank 0's result undefined
    MPI_Allreduce(&local, &total, 1, MPI_LONG_LONG, MPI_SUM, comm_);
    H5Handle group(checked(H5Gcreate2(open_->file.get(), "particles", H5P_DEFAULT, open_->group_creation.get(),
                                      H5P_DEFAULT),
                           "creating group /particles"),
                   H5Gclose);
    writeRawAttribute(group.get(), "count", H5T_NATIVE_LLONG, H5T_STD_I64LE, &total, 1);
    open_->have_particles = true;
    open_->particle_local = local_count;
    open_->particle_offset = offset;
    open_->particle_total = total;
  }

  const long long n = open_->particle_total;
  std::vector<long long> dims{n};
  if (components > 1) dims.push_back(components);
  writeParticleDataset(dataset_path, components, values, local_count);
  WrittenField field{OutputLocation::Particles, name, dataset_path, components, dims, dataset_path, dims};
  if (components == 2) {
    std::vector<double> padded(local_count * 3, 0.0);
    for (std::size_t p = 0; p < local_count; ++p) {
      padded[3 * p] = values[2 * p];
      padded[3 * p + 1] = values[2 * p + 1];
    }
    field.display_dataset = "/padded/particles/" + name;
    field.display_dims = {n, 3};
    writeParticleDataset(field.display_dataset, 3, padded.data(), local_count);
  }
  open_->record.fields.push_back(std::move(field));
}

void Hdf5Writer::writeParticleDataset(const std::string& dataset_path, int components,
                                      const double* values, std::size_t local_count)
{
  // File: (N) or (N, components); this rank's rows [offset, offset + local_count).
  std::vector<hsize_t> file_dims{static_cast<hsize_t>(open_->particle_total)};
  std::vector<hsize_t> start{static_cast<hsize_t>(open_->particle_offset)};
  std::vector<hsize_t> extent{static_cast<hsize_t>(local_count)};
  if (components > 1) {
    file_dims.push_back(static_cast<hsize_t>(components));
    start.push_back(0);
    extent.push_back(static_cast<hsize_t>(components));
  }
  H5Handle file_space(checked(H5Screate_simple(static_cast<int>(file_dims.size()), file_dims.data(),
                                               nullptr),
                              "file dataspace"),
                      H5Sclose);
  if (local_count > 0)
    checked(H5Sselect_hyperslab(file_space.get(), H5S_SELECT_SET, start.data(), nullptr,
                                extent.data(), nullptr),
            "selecting this rank's particles");
  else
    checked(H5Sselect_none(file_space.get()), "H5Sselect_none");

  const std::size_t count = local_count * static_cast<std::size_t>(components);
  const hsize_t memory_length = count > 0 ? static_cast<hsize_t>(count) : 1;
  H5Handle memory_space(checked(H5Screate_simple(1, &memory_length, nullptr), "memory dataspace"),
                        H5Sclose);
  if (count == 0) checked(H5Sselect_none(memory_space.get()), "H5Sselect_none");
  static const double no_values = 0;

  // Dataset creation is collective and needs the whole dataspace, whatever is selected.
  H5Handle dataset(checked(H5Dcreate2(open_->file.get(), dataset_path.c_str(), H5T_IEEE_F64LE,
                                      file_space.get(), open_->link_creation.get(),
                                      open_->dataset_creation.get(), H5P_DEFAULT),
                           "creating dataset " + dataset_path),
                   H5Dclose);
  // A step without any particle has empty datasets: HDF5 gives an empty contiguous dataset no
  // storage, and a write to it fails even with nothing selected. Every rank knows the total.
  if (open_->particle_total == 0) return;
  checked(H5Dwrite(dataset.get(), H5T_NATIVE_DOUBLE, memory_space.get(), file_space.get(),
                   open_->transfer.get(), count > 0 ? values : &no_values),
          "writing dataset " + dataset_path);
}

hid_t Hdf5Writer::fileSelection(const OutputLayout& grid, int components)
{
  const std::pair<const OutputLayout*, int> key{&grid, components};
  for (const auto& [cached_key, space] : selections_)
    if (cached_key == key) return space;

  // Built once per location and component count: OR-ing thousands of patch boxes costs more than
  // the transfer.
  H5Handle space = io_detail::ownedSelection(grid, components);
  selections_.emplace_back(key, space.get());
  return space.release();  // closed by the destructor
}

void Hdf5Writer::writeDataset(const OutputLayout& grid, const std::string& dataset_path,
                              int components, const double* values, std::size_t count)
{
  const hid_t file_space = fileSelection(grid, components);

  // A rank without entries still takes part in the collective write, with empty selections.
  const hsize_t memory_length = count > 0 ? static_cast<hsize_t>(count) : 1;
  H5Handle memory_space(checked(H5Screate_simple(1, &memory_length, nullptr), "memory dataspace"),
                        H5Sclose);
  if (count == 0) checked(H5Sselect_none(memory_space.get()), "H5Sselect_none");
  static const double no_values = 0;

  H5Handle dataset(checked(H5Dcreate2(open_->file.get(), dataset_path.c_str(), H5T_IEEE_F64LE,
                                      file_space, open_->link_creation.get(),
                                      open_->dataset_creation.get(), H5P_DEFAULT),
                           "creating dataset " + dataset_path),
                   H5Dclose);
  checked(H5Dwrite(dataset.get(), H5T_NATIVE_DOUBLE, memory_space.get(), file_space,
                   open_->transfer.get(), count > 0 ? values : &no_values),
          "writing dataset " + dataset_path);
}

WrittenStep Hdf5Writer::endStep()
{
  if (!open_) throw std::logic_error("Hdf5Writer::endStep without beginStep");
  std::unique_ptr<OpenStep> open = std::move(open_);
  open->transfer.reset();
  open->link_creation.reset();
  open->dataset_creation.reset();
  open->group_creation.reset();
  const bool closed = open->file.close();
  if (anyRank(comm_, !closed)) throw std::runtime_error("HDF5: closing " + open->temporary_path + " failed");

  // Every rank has closed its part; only now does the file get its final name.
  MPI_Barrier(comm_);
  onRankZero(comm_, [&] {
    std::error_code error;
    std::filesystem::rename(open->temporary_path, open->final_path, error);
    if (error)
      throw std::runtime_error("renaming " + open->temporary_path + " to " + open->final_path +
                               ": " + error.message());
  });
  return std::move(open->record);
}

void Hdf5Writer::abandonStep() noexcept
{
  if (!open_) return;
  std::unique_ptr<OpenStep> open = std::move(open_);
  open->transfer.reset();
  open->link_creation.reset();
  open->dataset_creation.reset();
  open->group_creation.reset();
  open->file.reset();
  if (rankOf(comm_) == 0) {
    std::error_code ignored;
    std::filesystem::remove(open->temporary_path, ignored);
  }
}

}  // namespace cfdmpm
