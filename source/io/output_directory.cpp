#include "io/output_directory.hpp"

#include "common/error.hpp"
#include "io/collective.hpp"

#include <filesystem>
#include <unistd.h>
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

// The refusals of prepareOnThisRank for an existing path; true when it is a directory that holds
// something (and overwrite allows it).
bool checkExisting(const std::string& directory, bool overwrite)
{
  const fs::path path(directory);
  std::error_code error;
  if (!fs::is_directory(fs::status(path, error)))
    throw directoryError(directory, "exists and is not a directory; choose another directory");
  fs::directory_iterator first(path, error);
  if (error) throw directoryError(directory, "cannot be read: " + error.message());
  if (first == fs::directory_iterator()) return false;
  if (!overwrite)
    throw directoryError(directory,
                         "exists and is not empty; choose another directory or set "
                         "output.overwrite: true");
  return true;
}

void checkOnThisRank(const std::string& directory, bool overwrite)
{
  if (directory.empty()) throw InputError(std::string(kKey) + ": must not be empty");
  std::error_code error;
  fs::path path = fs::absolute(fs::path(directory), error);
  if (fs::exists(fs::status(path, error))) {
    checkExisting(directory, overwrite);
    return;
  }
  // The nearest existing parent must be a directory this process may create entries in.
  while (path.has_parent_path() && path != path.parent_path() && !fs::exists(fs::status(path, error)))
    path = path.parent_path();
  if (!fs::is_directory(fs::status(path, error)) || ::access(path.c_str(), W_OK | X_OK) != 0)
    throw directoryError(directory, "cannot be created: '" + path.string() + "' is not a writable directory");
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
  // Decide before removing anything: a refused directory is left exactly as it was.
  if (!checkExisting(directory, overwrite)) return;
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

void checkOutputDirectory(MPI_Comm comm, const std::string& directory, bool overwrite)
{
  io_detail::onRankZero(comm, [&] { checkOnThisRank(directory, overwrite); });
}

}  // namespace cfdmpm
