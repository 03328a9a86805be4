#include "io/output_directory.hpp"

#include "common/error.hpp"
#include "io/collective.hpp"

#include <filesystem>
#include <vector>

namespace cfdmpm {
namespace {

namespace fs = std::filesystem;

constexpr const char* kKey = "output.directory";

bool endsWith(const std::string& text, const std::string& suffix)
{
  return text.size() >= suffix.size() &&
         text.compare(text.size() - suffix.size(), suffix.size(), suffix) == 0;
}

InputError directoryError(const std::string& directory, const std::string& problem)
{
  return InputError(std::string(kKey) + ": '" + directory + "' " + problem);
}

void prepareOnThisRank(const std::string& directory, bool overwrite)
{
  if (directory.empty()) throw InputError(std::string(kKey) + ": must not be empty");
  const fs::path path(directory);
  std::error_code error;
  const fs::file_status status = fs::status(path, error);
  if (!fs::exists(status)) {
    fs::create_directories(path, error);
    if (error) throw directoryError(directory, "cannot be created: " + error.message());
    return;
  }
  if (!fs::is_directory(status))
    throw directoryError(directory, "exists and is not a directory; choose another directory");

  // Decide before removing anything: a refused directory is left exactly as it was.
  fs::directory_iterator first(path, error);
  if (error) throw directoryError(directory, "cannot be read: " + error.message());
  if (first == fs::directory_iterator()) return;
  if (!overwrite)
    throw directoryError(directory,
                         "exists and is not empty; choose another directory or set "
                         "output.overwrite: true");
  std::vector<fs::path> old_output;
  for (const fs::directory_entry& entry : fs::directory_iterator(path))
    if (entry.is_regular_file() && isOutputFile(entry.path().filename().string()))
      old_output.push_back(entry.path());
  for (const fs::path& file : old_output) {
    fs::remove(file, error);
    if (error)
      throw directoryError(directory, "cannot remove the old output file " +
                                          file.filename().string() + ": " + error.message());
  }
}

}  // namespace

bool isOutputFile(const std::string& file_name)
{
  for (const char* suffix : {".h5", ".xmf", ".csv", ".tmp"})
    if (endsWith(file_name, suffix)) return true;
  return false;
}

void prepareOutputDirectory(MPI_Comm comm, const std::string& directory, bool overwrite)
{
  io_detail::onRankZero(comm, [&] { prepareOnThisRank(directory, overwrite); });
}

}  // namespace cfdmpm
