// The parallel HDF5 writer: what each rank passes lands at the right place in the file, whatever
// boxes the ranks own, and a file with the final name is always complete.
#include "io/hdf5_writer.hpp"
#include "io/hdf5_reader.hpp"
#include "io_test_support.hpp"

#include <gtest/gtest.h>

namespace cfdmpm {
namespace {

using namespace io_test;

/// A grid and where to cut it into tiles for cells and for nodes (cut lists include 0 and count).
struct GridCase {
  int dimension;
  std::array<long long, 3> cells;
  std::array<std::vector<long long>, 3> cell_cuts;
  std::array<std::vector<long long>, 3> node_cuts;
};

// Four tiles along x so that round-robin gives every rank of 2 or 3 two tiles that do not touch.
GridCase grid2d()
{
  return {2, {13, 7, 1}, {{{0, 3, 6, 10, 13}, {0, 2, 5, 7}, {0, 1}}}, {{{0, 4, 9, 14}, {0, 3, 8}, {0, 1}}}};
}

GridCase grid3d()
{
  return {3, {5, 4, 3}, {{{0, 1, 2, 4, 5}, {0, 1, 4}, {0, 2, 3}}}, {{{0, 2, 4, 6}, {0, 2, 5}, {0, 1, 4}}}};
}

struct Layouts {
  OutputLayout cells, nodes;
};

Layouts makeLayouts(const GridCase& grid, Ownership cell_ownership, Ownership node_ownership)
{
  const std::array<double, 3> origin{-1.0, 0.5, 2.0}, spacing{0.25, 0.5, 0.125};
  std::array<long long, 3> nodes = grid.cells;
  for (int d = 0; d < grid.dimension; ++d) nodes[d] += 1;
  return {splitLayout(grid.dimension, grid.cells, origin, spacing, grid.cell_cuts, cell_ownership),
          splitLayout(grid.dimension, nodes, origin, spacing, grid.node_cuts, node_ownership)};
}

struct FieldCase {
  OutputLocation location;
  std::string name;
  bool vector;
  int id;  // selects the known values
};

std::vector<FieldCase> fieldCases()
{
  return {{OutputLocation::Cells, "pressure", false, 1},
          {OutputLocation::Cells, "water/volume_fraction", false, 2},
          {OutputLocation::Cells, "water/density", false, 3},
          {OutputLocation::Cells, "velocity", true, 4},
          {OutputLocation::Nodes, "mass", false, 5},
          {OutputLocation::Nodes, "velocity", true, 6},
          {OutputLocation::Nodes, "soil/stress/mean", false, 7}};
}

/// Writes every field case with its known values; returns the record.
WrittenStep writeKnownFields(Hdf5Writer& writer, long long step, double time)
{
  writer.beginStep(step, time);
  for (const FieldCase& field : fieldCases()) {
    const OutputLayout& layout = writer.layout(field.location);
    const int components = field.vector ? layout.dimension : 1;
    const std::vector<double> values = knownBuffer(layout, field.id, components);
    if (field.vector)
      writer.writeVector(field.location, field.name, values.data(), values.size());
    else
      writer.writeScalar(field.location, field.name, values.data(), values.size());
  }
  return writer.endStep();
}

/// Rank 0 reads the file with the serial HDF5 API and compares every value with the known one.
void expectKnownFieldsInFile(const std::string& path, const Layouts& layouts, long long step,
                             double time)
{
  if (rank() != 0) return;
  hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(file, 0) << path;
  EXPECT_EQ(readAttribute<double>(file, "/", "time", H5T_NATIVE_DOUBLE, 1)[0], time);
  EXPECT_EQ(readAttribute<long long>(file, "/", "step", H5T_NATIVE_LLONG, 1)[0], step);
  const int dimension = layouts.cells.dimension;
  for (const auto& [group, layout] : {std::pair{"/cells", &layouts.cells}, std::pair{"/nodes", &layouts.nodes}}) {
    const auto count = readAttribute<long long>(file, group, "count_xyz", H5T_NATIVE_LLONG, dimension);
    const auto origin = readAttribute<double>(file, group, "origin_xyz", H5T_NATIVE_DOUBLE, dimension);
    const auto spacing = readAttribute<double>(file, group, "spacing_xyz", H5T_NATIVE_DOUBLE, dimension);
    for (int d = 0; d < dimension; ++d) {
      EXPECT_EQ(count[d], layout->global_count[d]) << group;
      EXPECT_EQ(origin[d], layout->origin[d]) << group;
      EXPECT_EQ(spacing[d], layout->spacing[d]) << group;
    }
  }

  for (const FieldCase& field : fieldCases()) {
    const OutputLayout& layout = field.location == OutputLocation::Cells ? layouts.cells : layouts.nodes;
    const int components = field.vector ? dimension : 1;
    const std::string dataset = std::string("/") + locationName(field.location) + "/" + field.name;
    ASSERT_EQ(datasetDimsInFile(file, dataset), datasetDims(layout, components)) << dataset;
    const std::vector<double> values = readDataset(file, dataset);
    // Exact equality: the values are copied, never computed.
    long long wrong = 0;
    for (long long gid = 0; gid < globalCount(layout); ++gid)
      for (int c = 0; c < components; ++c) {
        const double stored = values[static_cast<std::size_t>(gid * components + c)];
        if (stored != knownValue(field.id, gid, c) && wrong++ < 5)
          ADD_FAILURE() << dataset << " gid " << gid << " component " << c << ": " << stored
                        << " instead of " << knownValue(field.id, gid, c);
      }
    EXPECT_EQ(wrong, 0) << dataset;

    // 2-D vectors also exist as (x, y, 0) for ParaView.
    if (field.vector && dimension == 2) {
      const std::string padded = std::string("/padded/") + locationName(field.location) + "/" + field.name;
      ASSERT_EQ(datasetDimsInFile(file, padded), datasetDims(layout, 3)) << padded;
      const std::vector<double> xyz = readDataset(file, padded);
      long long wrong_padded = 0;
      for (long long gid = 0; gid < globalCount(layout); ++gid)
        for (int c = 0; c < 3; ++c)
          if (xyz[static_cast<std::size_t>(gid * 3 + c)] != (c < 2 ? knownValue(field.id, gid, c) : 0.0))
            ++wrong_padded;
      EXPECT_EQ(wrong_padded, 0) << padded;
    }
  }
  H5Fclose(file);
}

void expectNoTemporaryFiles(const std::string& directory)
{
  if (rank() != 0) return;
  for (const std::string& name : listDirectory(directory))
    EXPECT_EQ(name.find(".tmp"), std::string::npos) << directory << "/" << name;
}

void writeReadBackCase(const GridCase& grid, Ownership cells, Ownership nodes, const std::string& name)
{
  const std::string directory = freshDirectory(name);
  const Layouts layouts = makeLayouts(grid, cells, nodes);
  Hdf5Writer writer(MPI_COMM_WORLD, directory, "run", layouts.cells, layouts.nodes);
  const WrittenStep step = writeKnownFields(writer, 42, 0.125);

  EXPECT_EQ(step.file, "run_000042.h5");
  EXPECT_EQ(step.step, 42);
  EXPECT_EQ(step.time, 0.125);
  ASSERT_EQ(step.fields.size(), fieldCases().size());
  EXPECT_EQ(step.fields[1].dataset, "/cells/water/volume_fraction");
  EXPECT_EQ(step.fields[3].components, grid.dimension);
  EXPECT_EQ(step.fields[3].display_dataset, grid.dimension == 2 ? "/padded/cells/velocity" : "/cells/velocity");
  EXPECT_EQ(step.fields[0].display_dataset, "/cells/pressure");
  expectKnownFieldsInFile(directory + "/run_000042.h5", layouts, 42, 0.125);
  expectNoTemporaryFiles(directory);
  MPI_Barrier(MPI_COMM_WORLD);
}

// The buffers hold owned entries by ascending global index; several boxes per rank (not touching
// each other) interleave in that order, so a wrong assumption about HDF5's transfer order of a
// union of hyperslabs would put values in the wrong place.
TEST(Hdf5Writer, NonAdjacentOwnedBoxesReadBackExactly2D)
{
  writeReadBackCase(grid2d(), Ownership::RoundRobin, Ownership::LastRankOwnsNothing, "read_back_2d");
}

TEST(Hdf5Writer, NonAdjacentOwnedBoxesReadBackExactly3D)
{
  writeReadBackCase(grid3d(), Ownership::RoundRobin, Ownership::LastRankOwnsNothing, "read_back_3d");
}

TEST(Hdf5Writer, RanksOwningNothingStillTakePart)
{
  writeReadBackCase(grid3d(), Ownership::AllOnRankZero, Ownership::AllOnRankZero, "rank_zero_owns_all");
  writeReadBackCase(grid2d(), Ownership::LastRankOwnsNothing, Ownership::AllOnRankZero,
                    "last_rank_owns_nothing");
}

TEST(Hdf5Writer, FileGetsItsFinalNameOnlyWhenComplete)
{
  const std::string directory = freshDirectory("final_name");
  const Layouts layouts = makeLayouts(grid2d(), Ownership::RoundRobin, Ownership::RoundRobin);
  Hdf5Writer writer(MPI_COMM_WORLD, directory, "run", layouts.cells, layouts.nodes);
  writer.beginStep(7, 1.5);
  const std::vector<double> pressure = knownBuffer(layouts.cells, 1, 1);
  writer.writeScalar(OutputLocation::Cells, "pressure", pressure.data(), pressure.size());
  MPI_Barrier(MPI_COMM_WORLD);
  if (rank() == 0) {
    EXPECT_EQ(listDirectory(directory), std::vector<std::string>{"run_000007.h5.tmp"});
  }
  MPI_Barrier(MPI_COMM_WORLD);
  writer.endStep();
  if (rank() == 0) {
    EXPECT_EQ(listDirectory(directory), std::vector<std::string>{"run_000007.h5"});
  }
  MPI_Barrier(MPI_COMM_WORLD);
}

// A text attribute of any length reads back unchanged: a checkpoint's record of the steps a run
// wrote grows by ~1.5 kB per output and passed HDF5's 64 KiB per object header at ~45 outputs.
TEST(Hdf5Writer, TextAttributesOfAnyLengthReadBack)
{
  const std::string directory = freshDirectory("long_text");
  const Layouts layouts = makeLayouts(grid2d(), Ownership::RoundRobin, Ownership::RoundRobin);
  Hdf5Writer writer(MPI_COMM_WORLD, directory, "run", layouts.cells, layouts.nodes);
  writer.beginStep(3, 0.5);
  std::string long_text;
  for (int line = 0; long_text.size() < 4 * 65536; ++line) long_text += "step " + std::to_string(line) + "\n";
  const std::string short_text = "scene: short";
  writer.writeAttribute("long_record", long_text);
  writer.writeAttribute("another_long_record", long_text + long_text);
  writer.writeAttribute("short_record", short_text);
  writer.endStep();
  Hdf5Reader reader(MPI_COMM_WORLD, directory + "/run_000003.h5");
  EXPECT_TRUE(reader.hasAttribute("long_record"));
  EXPECT_FALSE(reader.hasAttribute("missing_record"));
  EXPECT_EQ(reader.attributeText("long_record"), long_text);
  EXPECT_EQ(reader.attributeText("another_long_record"), long_text + long_text);
  EXPECT_EQ(reader.attributeText("short_record"), short_text);
}

TEST(Hdf5Writer, AbandonedStepLeavesNoFile)
{
  const std::string directory = freshDirectory("abandoned");
  const Layouts layouts = makeLayouts(grid3d(), Ownership::RoundRobin, Ownership::RoundRobin);
  {
    Hdf5Writer writer(MPI_COMM_WORLD, directory, "run", layouts.cells, layouts.nodes);
    writer.beginStep(3, 0.5);
    const std::vector<double> mass = knownBuffer(layouts.nodes, 5, 1);
    writer.writeScalar(OutputLocation::Nodes, "mass", mass.data(), mass.size());
  }  // destroyed without endStep, as when an exception unwinds the driver
  MPI_Barrier(MPI_COMM_WORLD);
  if (rank() == 0) {
    EXPECT_TRUE(listDirectory(directory).empty());
  }
  MPI_Barrier(MPI_COMM_WORLD);
}

TEST(Hdf5Writer, WrongValueCountThrowsOnEveryRank)
{
  const std::string directory = freshDirectory("wrong_count");
  const Layouts layouts = makeLayouts(grid2d(), Ownership::RoundRobin, Ownership::RoundRobin);
  Hdf5Writer writer(MPI_COMM_WORLD, directory, "run", layouts.cells, layouts.nodes);
  writer.beginStep(1, 0.0);
  std::vector<double> pressure = knownBuffer(layouts.cells, 1, 1);
  if (rank() == 0) pressure.push_back(0.0);  // one value too many on rank 0 only
  EXPECT_THROW(writer.writeScalar(OutputLocation::Cells, "pressure", pressure.data(), pressure.size()),
               std::invalid_argument);
  EXPECT_THROW(writer.writeScalar(OutputLocation::Cells, "bad//name", nullptr, 0), std::invalid_argument);
  writer.endStep();
}

TEST(Hdf5Writer, LayoutThatDoesNotCoverTheGridThrowsOnEveryRank)
{
  Layouts layouts = makeLayouts(grid2d(), Ownership::RoundRobin, Ownership::RoundRobin);
  if (rank() == size() - 1) layouts.cells.owned_boxes.pop_back();  // a tile nobody owns
  EXPECT_THROW(Hdf5Writer(MPI_COMM_WORLD, ".", "run", layouts.cells, layouts.nodes),
               std::invalid_argument);
}

TEST(Hdf5Writer, StepFileNameIsZeroPadded)
{
  EXPECT_EQ(stepFileName("dam", 0), "dam_000000.h5");
  EXPECT_EQ(stepFileName("dam", 1234567), "dam_1234567.h5");
}

}  // namespace
}  // namespace cfdmpm
