#include "io/output_directory.hpp"

#include "common/error.hpp"
#include "io/collective.hpp"

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <filesystem>
#include <stdexcept>
#include <system_error>
#include <utility>
#include <unistd.h>
#include <vector>

namespace cfdmpm {
namespace {

namespace fs = std::filesystem;

constexpr const char* kKey = "cfdmpm.output.directory";

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
  // Permission bits do not say everything (root passes access() everywhere, and /proc or a
  // read-only mount refuse new entries whatever the bits): create a scratch directory there and
  // remove it, so that what this check passes the run can create.
  std::string probe = (path / ".cfdmpm-check-XXXXXX").string();
  if (::mkdtemp(probe.data()) == nullptr) {
    const int reason = errno;  // before anything else can set it
    throw directoryError(directory, "cannot be created: no new entry can be made in '" + path.string() +
                                        "': " + std::generic_category().message(reason));
  }
  fs::remove(probe, error);
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
  // The old run's checkpoints go too: `--restart <directory>` must not find them.
  const fs::path checkpoints(checkpointDirectory(directory));
  if (fs::is_directory(fs::status(checkpoints, error)))
    for (const fs::directory_entry& entry : fs::directory_iterator(checkpoints))
      if (entry.is_regular_file() && isOutputFile(entry.path().filename().string()))
        old_output.push_back(entry.path());
  for (const fs::path& file : old_output) {
    fs::remove(file, error);
    if (error)
      throw directoryError(directory, "cannot remove the old output file " +
                                          file.filename().string() + ": " + error.message());
  }
}

void removeFile(const fs::path& file)
{
  std::error_code error;
  fs::remove(file, error);
  if (error) throw std::runtime_error("cannot remove " + file.string() + ": " + error.message());
}

}  // namespace

bool isOutputFile(const std::string& file_name)
{
  for (const char* suffix : {".h5", ".xmf", ".csv", ".tmp"})
    if (endsWith(file_name, suffix)) return true;
  return false;
}

std::string checkpointDirectory(const std::string& output_directory)
{
  return (fs::path(output_directory) / "checkpoints").string();
}

void createDirectory(MPI_Comm comm, const std::string& directory)
{
  io_detail::onRankZero(comm, [&] {
    std::error_code error;
    fs::create_directories(directory, error);
    if (error) throw std::runtime_error("cannot create " + directory + ": " + error.message());
  });
}

long long stepOfFile(const std::string& file_name, const std::string& run_name, const std::string& extension)
{
  const std::string prefix = run_name + "_";
  if (file_name.size() <= prefix.size() + extension.size() || file_name.compare(0, prefix.size(), prefix) != 0 ||
      !endsWith(file_name, extension))
    return -1;
  const std::string digits = file_name.substr(prefix.size(), file_name.size() - prefix.size() - extension.size());
  if (digits.empty() || digits.size() > 18 || digits.find_first_not_of("0123456789") != std::string::npos) return -1;
  return std::stoll(digits);
}

std::vector<std::string> listCheckpoints(const std::string& checkpoint_directory, const std::string& run_name)
{
  std::vector<std::pair<long long, std::string>> found;
  std::error_code error;
  if (!fs::is_directory(fs::status(checkpoint_directory, error))) return {};
  for (const fs::directory_entry& entry : fs::directory_iterator(checkpoint_directory, error)) {
    const std::string name = entry.path().filename().string();
    const long long step = stepOfFile(name, run_name, ".h5");
    if (step >= 0 && entry.is_regular_file()) found.emplace_back(step, entry.path().string());
  }
  std::sort(found.begin(), found.end());
  std::vector<std::string> paths;
  for (const auto& [step, path] : found) paths.push_back(path);
  return paths;
}

void prepareRestartDirectory(MPI_Comm comm, const std::string& directory, const std::string& run_name, long long step)
{
  io_detail::onRankZero(comm, [&] {
    std::error_code error;
    for (const fs::path& folder : {fs::path(directory), fs::path(checkpointDirectory(directory))}) {
      if (!fs::is_directory(fs::status(folder, error))) continue;
      std::vector<fs::path> later;
      for (const fs::directory_entry& entry : fs::directory_iterator(folder)) {
        const std::string name = entry.path().filename().string();
        if (!entry.is_regular_file()) continue;
        if (endsWith(name, ".tmp") || stepOfFile(name, run_name, ".h5") > step || stepOfFile(name, run_name, ".xmf") > step)
          later.push_back(entry.path());
      }
      for (const fs::path& file : later) removeFile(file);
    }
  });
}

void pruneCheckpoints(MPI_Comm comm, const std::string& output_directory, const std::string& run_name, int kept)
{
  io_detail::onRankZero(comm, [&] {
    const std::vector<std::string> all = listCheckpoints(checkpointDirectory(output_directory), run_name);
    for (std::size_t i = 0; i + std::size_t(std::max(kept, 1)) < all.size(); ++i) removeFile(all[i]);
  });
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
