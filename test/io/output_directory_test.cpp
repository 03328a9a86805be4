// The output directory: created when missing, refused when it holds anything and overwrite is
// off, and cleaned of cfdmpm's own files only when overwrite is on; every rank sees the same outcome.
#include "common/error.hpp"
#include "io/output_directory.hpp"
#include "io_test_support.hpp"

#include <gtest/gtest.h>

namespace cfdmpm {
namespace {

using namespace io_test;

void touch(const std::string& path, const std::string& text = "x")
{
  std::ofstream(path) << text;
}

TEST(OutputDirectory, MissingDirectoryIsCreatedWithItsParents)
{
  const std::string base = freshDirectory("create");
  const std::string directory = base + "/a/b/c";
  prepareOutputDirectory(MPI_COMM_WORLD, directory, false);
  EXPECT_TRUE(std::filesystem::is_directory(directory));
  MPI_Barrier(MPI_COMM_WORLD);
}

TEST(OutputDirectory, EmptyDirectoryIsAcceptedWithoutOverwrite)
{
  const std::string directory = freshDirectory("empty");
  EXPECT_NO_THROW(prepareOutputDirectory(MPI_COMM_WORLD, directory, false));
  MPI_Barrier(MPI_COMM_WORLD);
}

TEST(OutputDirectory, NonEmptyDirectoryIsRefusedWithoutOverwriteAndLeftAlone)
{
  const std::string directory = freshDirectory("refused");
  if (rank() == 0) {
    touch(directory + "/run_000000.h5", "old results");
    touch(directory + "/notes.txt");
  }
  MPI_Barrier(MPI_COMM_WORLD);

  std::string message;
  try {
    prepareOutputDirectory(MPI_COMM_WORLD, directory, false);
  } catch (const InputError& e) {
    message = e.what();
  }
  // Every rank gets the same InputError.
  EXPECT_EQ(message, "cfdmpm.output.directory: '" + directory +
                         "' exists and is not empty; choose another directory or set "
                         "output.overwrite: true");
  if (rank() == 0) {
    EXPECT_EQ(listDirectory(directory), (std::vector<std::string>{"notes.txt", "run_000000.h5"}));
    EXPECT_EQ(readText(directory + "/run_000000.h5"), "old results");
  }
  MPI_Barrier(MPI_COMM_WORLD);
}

TEST(OutputDirectory, OverwriteRemovesOnlyTheFilesCfdmpmWrites)
{
  const std::string directory = freshDirectory("overwrite");
  if (rank() == 0) {
    for (const char* name : {"run_000000.h5", "run_000000.xmf", "run.xmf", "run.csv",
                             "run_000010.h5.tmp", "notes.txt", "scene.yaml"})
      touch(directory + "/" + name);
    std::filesystem::create_directory(directory + "/plots");
    touch(directory + "/plots/old.h5");
  }
  MPI_Barrier(MPI_COMM_WORLD);
  prepareOutputDirectory(MPI_COMM_WORLD, directory, true);
  if (rank() == 0) {
    EXPECT_EQ(listDirectory(directory), (std::vector<std::string>{"notes.txt", "plots", "scene.yaml"}));
    EXPECT_TRUE(std::filesystem::exists(directory + "/plots/old.h5"));  // not recursive
  }
  MPI_Barrier(MPI_COMM_WORLD);
}

TEST(OutputDirectory, PathThatIsAFileIsRefused)
{
  const std::string base = freshDirectory("not_a_directory");
  const std::string path = base + "/file";
  if (rank() == 0) touch(path);
  MPI_Barrier(MPI_COMM_WORLD);
  EXPECT_THROW(prepareOutputDirectory(MPI_COMM_WORLD, path, true), InputError);
}

TEST(OutputDirectory, OwnFilesAreRecognisedByTheirSuffix)
{
  EXPECT_TRUE(isOutputFile("dam_000120.h5"));
  EXPECT_TRUE(isOutputFile("dam.xmf"));
  EXPECT_TRUE(isOutputFile("dam.csv"));
  EXPECT_TRUE(isOutputFile("dam.xmf.tmp"));
  EXPECT_FALSE(isOutputFile("dam.yaml"));
  EXPECT_FALSE(isOutputFile("h5"));
}

}  // namespace
}  // namespace cfdmpm
