// Particle output: every rank's particles land in /particles of the step file in rank order (an
// empty rank included), the count may change from step to step, and the XDMF sidecar describes
// them as a Polyvertex grid next to the cell grid whose DataItems name existing datasets.
#include "io/hdf5_writer.hpp"
#include "io/xdmf_writer.hpp"
#include "io_test_support.hpp"

#include <gtest/gtest.h>

namespace cfdmpm {
namespace {

using namespace io_test;

/// Uneven particle counts per rank; on 2 and more ranks rank 1 has none. `variant` changes them
/// from step to step.
long long particleCount(int r, int variant)
{
  if (size() > 1 && r == (variant == 0 ? 1 : 0)) return 0;
  return variant == 0 ? 5 + 3 * r : 2 + 7 * r;
}

long long particleOffset(int r, int variant)
{
  long long offset = 0;
  for (int q = 0; q < r; ++q) offset += particleCount(q, variant);
  return offset;
}

long long particleTotal(int variant) { return particleOffset(size(), variant); }

struct ParticleField {
  std::string name;
  int components;  // 0: the grid dimension
  int id;          // selects the known values
};

std::vector<ParticleField> particleFields()
{
  return {{"position", 0, 21}, {"velocity", 0, 22}, {"stress", 9, 23}, {"plastic_strain", 1, 24},
          {"material", 1, 25}};
}

/// This rank's values of a field: particle p has the global index offset + p.
std::vector<double> particleBuffer(int id, int components, int variant)
{
  std::vector<double> values;
  const long long offset = particleOffset(rank(), variant);
  for (long long p = 0; p < particleCount(rank(), variant); ++p)
    for (int c = 0; c < components; ++c) values.push_back(knownValue(id, offset + p, c));
  return values;
}

struct ParticleRun {
  std::string directory;
  int dimension = 2;
  OutputLayout cells, nodes;
  std::vector<WrittenStep> steps;
  std::vector<int> variants;
};

ParticleRun writeParticleRun(const std::string& name, int dimension)
{
  ParticleRun run;
  run.directory = freshDirectory(name);
  run.dimension = dimension;
  const std::array<long long, 3> cells = dimension == 2 ? std::array<long long, 3>{4, 3, 1}
                                                        : std::array<long long, 3>{3, 2, 2};
  std::array<long long, 3> nodes = cells;
  for (int d = 0; d < dimension; ++d) nodes[d] += 1;
  auto whole = [](const std::array<long long, 3>& count) {
    return std::array<std::vector<long long>, 3>{{{0, count[0]}, {0, count[1]}, {0, count[2]}}};
  };
  const std::array<double, 3> origin{0, 0, 0}, spacing{0.5, 0.5, dimension == 3 ? 0.5 : 1.0};
  run.cells = splitLayout(dimension, cells, origin, spacing, whole(cells), Ownership::AllOnRankZero);
  run.nodes = splitLayout(dimension, nodes, origin, spacing, whole(nodes), Ownership::AllOnRankZero);

  Hdf5Writer hdf5(MPI_COMM_WORLD, run.directory, "run", run.cells, run.nodes);
  XdmfWriter xdmf(MPI_COMM_WORLD, run.directory, "run", run.cells, run.nodes);
  run.variants = {0, 1};
  for (std::size_t s = 0; s < run.variants.size(); ++s) {
    const int variant = run.variants[s];
    hdf5.beginStep(static_cast<long long>(s), 0.5 * static_cast<double>(s));
    const std::vector<double> pressure = knownBuffer(run.cells, 1, 1);
    hdf5.writeScalar(OutputLocation::Cells, "pressure", pressure.data(), pressure.size());
    const std::size_t local = static_cast<std::size_t>(particleCount(rank(), variant));
    for (const ParticleField& field : particleFields()) {
      const int components = field.components == 0 ? dimension : field.components;
      const std::vector<double> values = particleBuffer(field.id, components, variant);
      if (components == 1)
        hdf5.writeParticleScalar(field.name, values.data(), local);
      else
        hdf5.writeParticleVector(field.name, values.data(), local, components);
    }
    run.steps.push_back(hdf5.endStep());
    xdmf.addStep(run.steps.back());
  }
  return run;
}

void expectParticlesInFiles(const ParticleRun& run)
{
  if (rank() != 0) return;
  for (std::size_t s = 0; s < run.steps.size(); ++s) {
    const WrittenStep& step = run.steps[s];
    const int variant = run.variants[s];
    const long long total = particleTotal(variant);
    hid_t file = H5Fopen((run.directory + "/" + step.file).c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
    ASSERT_GE(file, 0) << step.file;
    EXPECT_EQ(readAttribute<long long>(file, "/particles", "count", H5T_NATIVE_LLONG, 1)[0], total);
    EXPECT_TRUE(pathExists(file, "/cells/pressure"));  // the same step file as the cells
    for (const ParticleField& field : particleFields()) {
      const int components = field.components == 0 ? run.dimension : field.components;
      const std::string dataset = "/particles/" + field.name;
      std::vector<long long> dims{total};
      if (components > 1) dims.push_back(components);
      ASSERT_EQ(datasetDimsInFile(file, dataset), dims) << step.file << dataset;
      const std::vector<double> values = readDataset(file, dataset);
      long long wrong = 0;  // exact: the values are copied, never computed
      for (long long id = 0; id < total; ++id)
        for (int c = 0; c < components; ++c)
          if (values[static_cast<std::size_t>(id * components + c)] != knownValue(field.id, id, c) &&
              wrong++ < 5)
            ADD_FAILURE() << step.file << dataset << " particle " << id << " component " << c;
      EXPECT_EQ(wrong, 0) << dataset;
      if (components == 2) {  // 2-D position and velocity also as (x, y, 0)
        const std::string padded = "/padded/particles/" + field.name;
        ASSERT_EQ(datasetDimsInFile(file, padded), (std::vector<long long>{total, 3})) << padded;
        const std::vector<double> xyz = readDataset(file, padded);
        for (long long id = 0; id < total; ++id)
          for (int c = 0; c < 3; ++c)
            if (xyz[static_cast<std::size_t>(3 * id + c)] != (c < 2 ? knownValue(field.id, id, c) : 0.0))
              ++wrong;
        EXPECT_EQ(wrong, 0) << padded;
      }
      // The record says the same.
      bool recorded = false;
      for (const WrittenField& written : step.fields)
        if (written.location == OutputLocation::Particles && written.name == field.name) {
          recorded = true;
          EXPECT_EQ(written.dataset, dataset);
          EXPECT_EQ(written.components, components);
          EXPECT_EQ(written.dims, dims);
        }
      EXPECT_TRUE(recorded) << field.name;
    }
    H5Fclose(file);
  }
}

/// Dims of the dataset an HDF DataItem names, checked against its Dimensions attribute.
void expectDataItemMatchesFile(const XmlElement& item, const ParticleRun& run, const WrittenStep& step,
                               const std::vector<long long>& expected_dims)
{
  ASSERT_EQ(item.attribute("Format"), "HDF");
  const std::string reference = item.text;
  const std::size_t colon = reference.find(':');
  ASSERT_NE(colon, std::string::npos) << reference;
  EXPECT_EQ(reference.substr(0, colon), step.file);
  std::vector<long long> claimed;
  for (double x : numbersIn(item.attribute("Dimensions"))) claimed.push_back(static_cast<long long>(x));
  EXPECT_EQ(claimed, expected_dims) << reference;
  hid_t file = H5Fopen((run.directory + "/" + step.file).c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(file, 0) << reference;
  EXPECT_EQ(datasetDimsInFile(file, reference.substr(colon + 1)), claimed) << reference;
  H5Fclose(file);
}

void expectParticleGrid(const XmlElement& collection, const ParticleRun& run, std::size_t s)
{
  const WrittenStep& step = run.steps[s];
  const long long total = particleTotal(run.variants[s]);
  EXPECT_EQ(collection.attribute("GridType"), "Collection");
  EXPECT_EQ(collection.attribute("CollectionType"), "Spatial");
  std::vector<const XmlElement*> grids;
  for (const XmlElement& child : collection.children) {
    if (child.name == "Time") {
      EXPECT_EQ(std::stod(child.attribute("Value")), step.time);
    }
    if (child.name == "Grid") grids.push_back(&child);
  }
  ASSERT_EQ(grids.size(), 2u);
  EXPECT_EQ(grids[0]->all("Topology").at(0)->attribute("TopologyType"), "3DCoRectMesh");
  EXPECT_EQ(grids[0]->all("Attribute").size(), 1u);  // pressure only

  const XmlElement& particles = *grids[1];
  EXPECT_EQ(particles.attribute("Name"), "particles");
  ASSERT_EQ(particles.all("Topology").size(), 1u);
  const XmlElement& topology = *particles.all("Topology")[0];
  EXPECT_EQ(topology.attribute("TopologyType"), "Polyvertex");
  EXPECT_EQ(topology.attribute("NumberOfElements"), std::to_string(total));
  ASSERT_EQ(particles.all("Geometry").size(), 1u);
  const XmlElement& geometry = *particles.all("Geometry")[0];
  EXPECT_EQ(geometry.attribute("GeometryType"), "XYZ");
  ASSERT_EQ(geometry.children.size(), 1u);
  expectDataItemMatchesFile(geometry.children[0], run, step, {total, 3});
  EXPECT_EQ(geometry.children[0].text, step.file + (run.dimension == 2 ? ":/padded/particles/position"
                                                                        : ":/particles/position"));

  const auto attributes = particles.all("Attribute");
  const std::vector<ParticleField> fields = particleFields();
  ASSERT_EQ(attributes.size(), fields.size());
  for (std::size_t a = 0; a < attributes.size(); ++a) {
    const ParticleField& field = fields[a];
    const int components = field.components == 0 ? run.dimension : field.components;
    EXPECT_EQ(attributes[a]->attribute("Name"), field.name);
    EXPECT_EQ(attributes[a]->attribute("Center"), "Node");
    EXPECT_EQ(attributes[a]->attribute("AttributeType"),
              components == 1 ? "Scalar" : components == 9 ? "Tensor" : "Vector");
    std::vector<long long> dims{total};
    if (components > 1) dims.push_back(components == 2 ? 3 : components);
    ASSERT_EQ(attributes[a]->children.size(), 1u);
    expectDataItemMatchesFile(attributes[a]->children[0], run, step, dims);
  }
}

void expectParticlesInXdmf(const ParticleRun& run)
{
  if (rank() != 0) return;
  const XmlElement series = XmlReader::parse(readText(run.directory + "/run.xmf"));
  ASSERT_EQ(series.children.size(), 1u);
  ASSERT_EQ(series.children[0].children.size(), 1u);
  const XmlElement& temporal = series.children[0].children[0];
  EXPECT_EQ(temporal.attribute("CollectionType"), "Temporal");
  ASSERT_EQ(temporal.children.size(), run.steps.size());
  for (std::size_t s = 0; s < run.steps.size(); ++s) expectParticleGrid(temporal.children[s], run, s);

  for (std::size_t s = 0; s < run.steps.size(); ++s) {
    const std::string stem = run.steps[s].file.substr(0, run.steps[s].file.size() - 3);
    const XmlElement document = XmlReader::parse(readText(run.directory + "/" + stem + ".xmf"));
    ASSERT_EQ(document.children.at(0).children.size(), 1u);
    expectParticleGrid(document.children[0].children[0], run, s);
  }
}

TEST(ParticleOutput, EveryRanksParticlesInRankOrder2D)
{
  const ParticleRun run = writeParticleRun("particles_2d", 2);
  expectParticlesInFiles(run);
  expectParticlesInXdmf(run);
  MPI_Barrier(MPI_COMM_WORLD);
}

TEST(ParticleOutput, EveryRanksParticlesInRankOrder3D)
{
  const ParticleRun run = writeParticleRun("particles_3d", 3);
  expectParticlesInFiles(run);
  expectParticlesInXdmf(run);
  MPI_Barrier(MPI_COMM_WORLD);
}

TEST(ParticleOutput, ParticleCountMustNotChangeWithinAStep)
{
  const std::string directory = freshDirectory("particles_count_mismatch");
  std::array<std::vector<long long>, 3> cuts{{{0, 2}, {0, 2}, {0, 1}}};
  const OutputLayout cells = splitLayout(2, {2, 2, 1}, {0, 0, 0}, {1, 1, 1}, cuts, Ownership::AllOnRankZero);
  cuts = {{{0, 3}, {0, 3}, {0, 1}}};
  const OutputLayout nodes = splitLayout(2, {3, 3, 1}, {0, 0, 0}, {1, 1, 1}, cuts, Ownership::AllOnRankZero);
  Hdf5Writer hdf5(MPI_COMM_WORLD, directory, "run", cells, nodes);
  hdf5.beginStep(0, 0.0);
  const std::vector<double> values(8, 1.0);
  hdf5.writeParticleScalar("mass", values.data(), 4);
  // The last rank now passes another count: every rank throws.
  EXPECT_THROW(hdf5.writeParticleScalar("volume", values.data(), rank() == size() - 1 ? 3 : 4),
               std::invalid_argument);
  EXPECT_THROW(hdf5.writeScalar(OutputLocation::Particles, "x", values.data(), 4), std::invalid_argument);
  MPI_Barrier(MPI_COMM_WORLD);
}

}  // namespace
}  // namespace cfdmpm

namespace cfdmpm {
namespace {

using namespace io_test;

// A step in which no rank has a particle (every solid region left empty, say) still writes its
// particle fields: /particles with count 0 and empty datasets, and the cell fields of the step.
TEST(ParticleOutput, AStepWithoutAnyParticleWritesEmptyDatasets)
{
  const std::string directory = freshDirectory("no_particles");
  const std::array<long long, 3> cells{4, 3, 1}, nodes{5, 4, 1};
  auto whole = [](const std::array<long long, 3>& count) {
    return std::array<std::vector<long long>, 3>{{{0, count[0]}, {0, count[1]}, {0, count[2]}}};
  };
  const std::array<double, 3> origin{0, 0, 0}, spacing{0.5, 0.5, 1.0};
  const OutputLayout cell_layout = splitLayout(2, cells, origin, spacing, whole(cells), Ownership::AllOnRankZero);
  const OutputLayout node_layout = splitLayout(2, nodes, origin, spacing, whole(nodes), Ownership::AllOnRankZero);
  Hdf5Writer hdf5(MPI_COMM_WORLD, directory, "run", cell_layout, node_layout);
  XdmfWriter xdmf(MPI_COMM_WORLD, directory, "run", cell_layout, node_layout);
  hdf5.beginStep(0, 0.0);
  const std::vector<double> pressure = knownBuffer(cell_layout, 1, 1);
  hdf5.writeScalar(OutputLocation::Cells, "pressure", pressure.data(), pressure.size());
  hdf5.writeParticleVector("position", nullptr, 0, 2);
  hdf5.writeParticleScalar("material", nullptr, 0);
  const WrittenStep step = hdf5.endStep();
  xdmf.addStep(step);
  MPI_Barrier(MPI_COMM_WORLD);
  if (rank() != 0) return;
  hid_t file = H5Fopen((directory + "/" + step.file).c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(file, 0) << step.file;
  EXPECT_EQ(readAttribute<long long>(file, "/particles", "count", H5T_NATIVE_LLONG, 1)[0], 0);
  EXPECT_EQ(datasetDimsInFile(file, "/particles/position"), (std::vector<long long>{0, 2}));
  EXPECT_EQ(datasetDimsInFile(file, "/particles/material"), (std::vector<long long>{0}));
  EXPECT_EQ(readDataset(file, "/cells/pressure"), pressure);
  H5Fclose(file);
  // No particle grid in the time series: ParaView has nothing to draw.
  EXPECT_EQ(readText(directory + "/run.xmf").find("Polyvertex"), std::string::npos);
}

}  // namespace
}  // namespace cfdmpm
