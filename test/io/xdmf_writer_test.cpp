// The XDMF sidecars: well-formed XML, a time series listing every step, and every reference to
// heavy data naming a dataset that exists with the dimensions the XML claims.
#include "io/hdf5_writer.hpp"
#include "io/xdmf_writer.hpp"
#include "io_test_support.hpp"

#include <gtest/gtest.h>

namespace cfdmpm {
namespace {

using namespace io_test;

struct WrittenRun {
  std::string directory;
  OutputLayout cells, nodes;
  std::vector<WrittenStep> steps;
};

/// Writes `times.size()` steps of a pressure, a nested scalar and a velocity on cells and a
/// velocity on nodes, with HDF5 files and XDMF sidecars.
WrittenRun writeRun(const std::string& name, int dimension, const std::vector<double>& times)
{
  WrittenRun run;
  run.directory = freshDirectory(name);
  const std::array<long long, 3> cells = dimension == 2 ? std::array<long long, 3>{13, 7, 1}
                                                        : std::array<long long, 3>{5, 4, 3};
  std::array<long long, 3> nodes = cells;
  for (int d = 0; d < dimension; ++d) nodes[d] += 1;
  const std::array<double, 3> origin{-1.0, 0.5, dimension == 3 ? 2.0 : 0.0};
  const std::array<double, 3> spacing{0.25, 0.5, dimension == 3 ? 0.125 : 1.0};
  auto cuts = [](const std::array<long long, 3>& count) {
    std::array<std::vector<long long>, 3> c;
    for (int d = 0; d < 3; ++d)
      c[d] = count[d] > 2 ? std::vector<long long>{0, count[d] / 2, count[d]}
                          : std::vector<long long>{0, count[d]};
    return c;
  };
  run.cells = splitLayout(dimension, cells, origin, spacing, cuts(cells), Ownership::RoundRobin);
  run.nodes = splitLayout(dimension, nodes, origin, spacing, cuts(nodes), Ownership::LastRankOwnsNothing);

  Hdf5Writer hdf5(MPI_COMM_WORLD, run.directory, "run", run.cells, run.nodes);
  XdmfWriter xdmf(MPI_COMM_WORLD, run.directory, "run", run.cells, run.nodes);
  for (std::size_t s = 0; s < times.size(); ++s) {
    hdf5.beginStep(static_cast<long long>(10 * s), times[s]);
    const std::vector<double> pressure = knownBuffer(run.cells, 1, 1);
    const std::vector<double> fraction = knownBuffer(run.cells, 2, 1);
    const std::vector<double> cell_velocity = knownBuffer(run.cells, 3, dimension);
    const std::vector<double> node_velocity = knownBuffer(run.nodes, 4, dimension);
    hdf5.writeScalar(OutputLocation::Cells, "pressure", pressure.data(), pressure.size());
    hdf5.writeScalar(OutputLocation::Cells, "water/volume_fraction", fraction.data(), fraction.size());
    hdf5.writeVector(OutputLocation::Cells, "velocity", cell_velocity.data(), cell_velocity.size());
    hdf5.writeVector(OutputLocation::Nodes, "velocity", node_velocity.data(), node_velocity.size());
    run.steps.push_back(hdf5.endStep());
    xdmf.addStep(run.steps.back());
  }
  EXPECT_EQ(xdmf.steps().size(), times.size());
  EXPECT_EQ(xdmf.seriesPath(), run.directory + "/run.xmf");
  return run;
}

std::vector<long long> integersIn(const std::string& text)
{
  std::vector<long long> values;
  for (double x : numbersIn(text)) values.push_back(static_cast<long long>(x));
  return values;
}

/// Checks one uniform grid: topology, geometry and that every HDF DataItem names a dataset of the
/// claimed dimensions in its file.
void expectGridMatchesFiles(const XmlElement& grid, const WrittenRun& run, const WrittenStep& step)
{
  const OutputLayout& cells = run.cells;
  const int dimension = cells.dimension;
  EXPECT_EQ(grid.attribute("GridType"), "Uniform");
  ASSERT_EQ(grid.all("Time").size(), 1u);
  EXPECT_EQ(std::stod(grid.all("Time")[0]->attribute("Value")), step.time);

  // 2-D grids are 3-D grids one node thick at z = 0 (see xdmf_writer.hpp).
  ASSERT_EQ(grid.all("Topology").size(), 1u);
  const XmlElement& topology = *grid.all("Topology")[0];
  EXPECT_EQ(topology.attribute("TopologyType"), "3DCoRectMesh");
  std::vector<long long> node_dims;  // z y x
  if (dimension == 2) node_dims.push_back(1);
  for (int d = dimension - 1; d >= 0; --d) node_dims.push_back(cells.global_count[d] + 1);
  EXPECT_EQ(integersIn(topology.attribute("Dimensions")), node_dims);

  ASSERT_EQ(grid.all("Geometry").size(), 1u);
  const XmlElement& geometry = *grid.all("Geometry")[0];
  EXPECT_EQ(geometry.attribute("GeometryType"), "ORIGIN_DXDYDZ");
  ASSERT_EQ(geometry.children.size(), 2u);
  std::vector<double> origin, spacing;  // z y x, written with 17 digits: exact
  if (dimension == 2) {
    origin.push_back(0.0);
    spacing.push_back(std::min(cells.spacing[0], cells.spacing[1]));
  }
  for (int d = dimension - 1; d >= 0; --d) {
    origin.push_back(cells.origin[d]);
    spacing.push_back(cells.spacing[d]);
  }
  EXPECT_EQ(numbersIn(geometry.children[0].text), origin);
  EXPECT_EQ(numbersIn(geometry.children[1].text), spacing);

  const auto attributes = grid.all("Attribute");
  ASSERT_EQ(attributes.size(), step.fields.size());
  for (std::size_t a = 0; a < attributes.size(); ++a) {
    const XmlElement& attribute = *attributes[a];
    const WrittenField& field = step.fields[a];
    EXPECT_EQ(attribute.attribute("Name"), field.name);
    EXPECT_EQ(attribute.attribute("Center"), field.location == OutputLocation::Cells ? "Cell" : "Node");
    EXPECT_EQ(attribute.attribute("AttributeType"), field.components > 1 ? "Vector" : "Scalar");
    ASSERT_EQ(attribute.children.size(), 1u);

    // What a reader gets: entries (z y x) and, for vectors, three components.
    std::vector<long long> expected;
    const OutputLayout& layout = field.location == OutputLocation::Cells ? run.cells : run.nodes;
    for (int d = dimension - 1; d >= 0; --d) expected.push_back(layout.global_count[d]);
    if (field.components > 1) expected.push_back(3);
    EXPECT_EQ(integersIn(attribute.children[0].attribute("Dimensions")), expected) << field.name;

    for (const XmlElement* item : attribute.all("DataItem")) {
      if (item->attribute("Format") != "HDF") continue;
      const std::string reference = item->text;
      const std::size_t colon = reference.find(':');
      ASSERT_NE(colon, std::string::npos) << reference;
      const std::string file_name = reference.substr(0, colon), dataset = reference.substr(colon + 1);
      EXPECT_EQ(file_name, step.file);
      EXPECT_EQ(dataset, field.display_dataset);
      hid_t file = H5Fopen((run.directory + "/" + file_name).c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
      ASSERT_GE(file, 0) << reference;
      EXPECT_EQ(datasetDimsInFile(file, dataset), integersIn(item->attribute("Dimensions"))) << reference;
      H5Fclose(file);
    }
  }
}

void expectRunDescribedByXdmf(const WrittenRun& run)
{
  if (rank() != 0) return;
  // The series: one temporal collection with every step, in order.
  const XmlElement series = XmlReader::parse(readText(run.directory + "/run.xmf"));
  EXPECT_EQ(series.name, "Xdmf");
  ASSERT_EQ(series.children.size(), 1u);
  ASSERT_EQ(series.children[0].name, "Domain");
  ASSERT_EQ(series.children[0].children.size(), 1u);
  const XmlElement& collection = series.children[0].children[0];
  EXPECT_EQ(collection.attribute("GridType"), "Collection");
  EXPECT_EQ(collection.attribute("CollectionType"), "Temporal");
  ASSERT_EQ(collection.children.size(), run.steps.size());
  for (std::size_t s = 0; s < run.steps.size(); ++s)
    expectGridMatchesFiles(collection.children[s], run, run.steps[s]);

  // Each step's own sidecar.
  for (const WrittenStep& step : run.steps) {
    const std::string stem = step.file.substr(0, step.file.size() - 3);
    const XmlElement document = XmlReader::parse(readText(run.directory + "/" + stem + ".xmf"));
    const auto grids = document.all("Grid");
    ASSERT_EQ(grids.size(), 1u) << stem;
    expectGridMatchesFiles(*grids[0], run, step);
  }

  for (const std::string& name : listDirectory(run.directory))
    EXPECT_EQ(name.find(".tmp"), std::string::npos) << name;
}

TEST(XdmfWriter, SeriesAndStepFilesDescribeTheHdf5Files2D)
{
  const WrittenRun run = writeRun("xdmf_2d", 2, {0.0, 0.05, 0.1});
  expectRunDescribedByXdmf(run);
  MPI_Barrier(MPI_COMM_WORLD);
}

TEST(XdmfWriter, SeriesAndStepFilesDescribeTheHdf5Files3D)
{
  const WrittenRun run = writeRun("xdmf_3d", 3, {0.0, 1.0 / 3.0});
  expectRunDescribedByXdmf(run);
  MPI_Barrier(MPI_COMM_WORLD);
}

// ParaView's vectors have three components: a 2-D vector attribute references the (x, y, 0) copy.
TEST(XdmfWriter, TwoDimensionalVectorsAreShownWithAZeroZComponent)
{
  const WrittenRun run = writeRun("xdmf_2d_vector", 2, {0.25});
  if (rank() == 0) {
    const XmlElement document = XmlReader::parse(readText(run.directory + "/run_000000.xmf"));
    hid_t file = H5Fopen((run.directory + "/run_000000.h5").c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
    ASSERT_GE(file, 0);
    int vectors = 0;
    for (const XmlElement* attribute : document.all("Attribute")) {
      if (attribute->attribute("AttributeType") != "Vector") continue;
      ++vectors;
      const bool on_cells = attribute->attribute("Center") == "Cell";
      const XmlElement& item = attribute->children.at(0);
      EXPECT_EQ(item.text, std::string("run_000000.h5:/padded/") + (on_cells ? "cells" : "nodes") + "/velocity");
      const std::vector<double> xyz = readDataset(file, item.text.substr(item.text.find(':') + 1));
      const OutputLayout& layout = on_cells ? run.cells : run.nodes;
      ASSERT_EQ(static_cast<long long>(xyz.size()), 3 * globalCount(layout));
      const int id = on_cells ? 3 : 4;  // as in writeRun
      for (long long gid = 0; gid < globalCount(layout); ++gid) {
        EXPECT_EQ(xyz[3 * gid], knownValue(id, gid, 0));
        EXPECT_EQ(xyz[3 * gid + 1], knownValue(id, gid, 1));
        EXPECT_EQ(xyz[3 * gid + 2], 0.0);
      }
    }
    H5Fclose(file);
    EXPECT_EQ(vectors, 2);
  }
  MPI_Barrier(MPI_COMM_WORLD);
}

TEST(XdmfWriter, NodeLayoutOfAnotherGridIsRefused)
{
  OutputLayout cells, nodes;
  cells.global_count = {4, 3, 1};
  nodes.global_count = {4, 3, 1};  // should be 5 x 4
  EXPECT_THROW(XdmfWriter(MPI_COMM_WORLD, ".", "run", cells, nodes), std::invalid_argument);
}

TEST(XmlReader, UnbalancedTagsAreRejected)
{
  EXPECT_NO_THROW(XmlReader::parse("<?xml version=\"1.0\" ?><a x=\"1\"><b/><c>t</c></a>"));
  EXPECT_THROW(XmlReader::parse("<a><b></a></b>"), std::runtime_error);
  EXPECT_THROW(XmlReader::parse("<a><b></b>"), std::runtime_error);
}

}  // namespace
}  // namespace cfdmpm
