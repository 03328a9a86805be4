#pragma once
// Shared by the io tests: grids split into boxes among ranks, known field values, reading files
// back on rank 0, and a small XML reader for the XDMF files.
#include "io/output_layout.hpp"

#include <gtest/gtest.h>
#include <hdf5.h>
#include <mpi.h>

#include <algorithm>
#include <cctype>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace cfdmpm::io_test {

inline int rank()
{
  int r = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &r);
  return r;
}

inline int size()
{
  int s = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &s);
  return s;
}

/// An empty directory for one test: io_output_np<N>/<name> under the test's working directory.
inline std::string freshDirectory(const std::string& name)
{
  const std::string path = "io_output_np" + std::to_string(size()) + "/" + name;
  if (rank() == 0) {
    std::filesystem::remove_all(path);
    std::filesystem::create_directories(path);
  }
  MPI_Barrier(MPI_COMM_WORLD);
  return path;
}

/// Which rank owns tile t of a grid cut into tiles.
enum class Ownership {
  RoundRobin,         // tile t -> t % ranks: with 2 or 3 ranks each rank owns non-adjacent tiles
  LastRankOwnsNothing,  // tile t -> t % (ranks - 1): the last rank of several owns no entry
  AllOnRankZero,      // every other rank owns nothing
};

inline int tileOwner(int tile, int ranks, Ownership ownership)
{
  switch (ownership) {
    case Ownership::RoundRobin: return tile % ranks;
    case Ownership::LastRankOwnsNothing: return ranks > 1 ? tile % (ranks - 1) : 0;
    case Ownership::AllOnRankZero: return 0;
  }
  return 0;
}

/// A layout of `count` entries per direction cut at `cuts` (per direction, including 0 and count),
/// tiles numbered x fastest, this rank's tiles chosen by `ownership`.
inline OutputLayout splitLayout(int dimension, std::array<long long, 3> count,
                                std::array<double, 3> origin, std::array<double, 3> spacing,
                                const std::array<std::vector<long long>, 3>& cuts,
                                Ownership ownership)
{
  OutputLayout layout;
  layout.dimension = dimension;
  layout.global_count = count;
  layout.origin = origin;
  layout.spacing = spacing;
  std::array<std::size_t, 3> tiles{};
  for (int d = 0; d < 3; ++d) tiles[d] = cuts[d].size() - 1;
  int tile = 0;
  for (std::size_t k = 0; k < tiles[2]; ++k)
    for (std::size_t j = 0; j < tiles[1]; ++j)
      for (std::size_t i = 0; i < tiles[0]; ++i, ++tile) {
        if (tileOwner(tile, size(), ownership) != rank()) continue;
        Box box;
        box.lower = {cuts[0][i], cuts[1][j], cuts[2][k]};
        box.upper = {cuts[0][i + 1], cuts[1][j + 1], cuts[2][k + 1]};
        layout.owned_boxes.push_back(box);
      }
  return layout;
}

/// This rank's global indices (x fastest), ascending: the order of a field's buffer.
inline std::vector<long long> ownedGlobalIndices(const OutputLayout& layout)
{
  std::vector<long long> gids;
  const auto& n = layout.global_count;
  for (const Box& box : layout.owned_boxes)
    for (long long k = box.lower[2]; k < box.upper[2]; ++k)
      for (long long j = box.lower[1]; j < box.upper[1]; ++j)
        for (long long i = box.lower[0]; i < box.upper[0]; ++i)
          gids.push_back(i + n[0] * (j + n[1] * k));
  std::sort(gids.begin(), gids.end());
  return gids;
}

/// The known value of component c of field `field` at global index gid; exact in double.
inline double knownValue(int field, long long gid, int component)
{
  return 1.0e6 * field + 1.5 * static_cast<double>(gid) + 0.25 * component;
}

/// This rank's buffer of field `field`: owned entries ascending, components interleaved.
inline std::vector<double> knownBuffer(const OutputLayout& layout, int field, int components)
{
  std::vector<double> values;
  for (long long gid : ownedGlobalIndices(layout))
    for (int c = 0; c < components; ++c) values.push_back(knownValue(field, gid, c));
  return values;
}

/// True if every link on `path` ("/a/b/c") exists in the file.
inline bool pathExists(hid_t file, const std::string& path)
{
  std::size_t end = 0;
  while ((end = path.find('/', end + 1)) != std::string::npos)
    if (H5Lexists(file, path.substr(0, end).c_str(), H5P_DEFAULT) <= 0) return false;
  return H5Lexists(file, path.c_str(), H5P_DEFAULT) > 0;
}

/// Dims of a dataset, slowest first; empty if there is no such dataset.
inline std::vector<long long> datasetDimsInFile(hid_t file, const std::string& path)
{
  if (!pathExists(file, path)) return {};
  hid_t dataset = H5Oopen(file, path.c_str(), H5P_DEFAULT);
  if (dataset < 0) return {};
  if (H5Iget_type(dataset) != H5I_DATASET) {
    H5Oclose(dataset);
    return {};
  }
  hid_t space = H5Dget_space(dataset);
  const int ndims = H5Sget_simple_extent_ndims(space);
  std::vector<hsize_t> dims(static_cast<std::size_t>(std::max(ndims, 0)));
  H5Sget_simple_extent_dims(space, dims.data(), nullptr);
  H5Sclose(space);
  H5Oclose(dataset);
  return std::vector<long long>(dims.begin(), dims.end());
}

/// The whole dataset as doubles, in file order.
inline std::vector<double> readDataset(hid_t file, const std::string& path)
{
  std::vector<long long> dims = datasetDimsInFile(file, path);
  if (dims.empty()) throw std::runtime_error("no dataset " + path);
  long long total = 1;
  for (long long n : dims) total *= n;
  std::vector<double> values(static_cast<std::size_t>(total));
  hid_t dataset = H5Dopen2(file, path.c_str(), H5P_DEFAULT);
  herr_t status = H5Dread(dataset, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data());
  H5Dclose(dataset);
  if (status < 0) throw std::runtime_error("cannot read " + path);
  return values;
}

/// An attribute of an object as `length` values of `memory_type`.
template <class T>
std::vector<T> readAttribute(hid_t file, const std::string& object, const std::string& name,
                             hid_t memory_type, std::size_t length)
{
  std::vector<T> values(length);
  hid_t attribute = H5Aopen_by_name(file, object.c_str(), name.c_str(), H5P_DEFAULT, H5P_DEFAULT);
  if (attribute < 0) throw std::runtime_error("no attribute " + object + " " + name);
  hid_t space = H5Aget_space(attribute);
  const hssize_t stored = H5Sget_simple_extent_npoints(space);
  H5Sclose(space);
  if (stored != static_cast<hssize_t>(length)) {
    H5Aclose(attribute);
    throw std::runtime_error("attribute " + object + " " + name + " has " +
                             std::to_string(stored) + " values");
  }
  H5Aread(attribute, memory_type, values.data());
  H5Aclose(attribute);
  return values;
}

/// Names in a directory, sorted.
inline std::vector<std::string> listDirectory(const std::string& path)
{
  std::vector<std::string> names;
  for (const auto& entry : std::filesystem::directory_iterator(path))
    names.push_back(entry.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

inline std::string readText(const std::string& path)
{
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// --- A small XML reader: enough to check that every tag is closed by its own end tag and to walk
// the XDMF tree. Handles the declaration, comments, attributes in double quotes, self-closing tags.

struct XmlElement {
  std::string name;
  std::map<std::string, std::string> attributes;
  std::string text;  // character data directly inside, entities left as they are
  std::vector<XmlElement> children;

  std::vector<const XmlElement*> all(const std::string& element_name) const
  {
    std::vector<const XmlElement*> found;
    collect(element_name, found);
    return found;
  }
  void collect(const std::string& element_name, std::vector<const XmlElement*>& found) const
  {
    if (name == element_name) found.push_back(this);
    for (const XmlElement& child : children) child.collect(element_name, found);
  }
  std::string attribute(const std::string& key) const
  {
    auto it = attributes.find(key);
    return it == attributes.end() ? std::string() : it->second;
  }
};

class XmlReader {
 public:
  /// Parses a document with one root element; throws std::runtime_error on unbalanced tags.
  static XmlElement parse(const std::string& text)
  {
    XmlReader reader(text);
    reader.skipMisc();
    XmlElement root = reader.element();
    reader.skipMisc();
    if (reader.at_ != text.size()) reader.fail("content after the root element");
    return root;
  }

 private:
  explicit XmlReader(const std::string& text) : text_(text) {}

  [[noreturn]] void fail(const std::string& what) const
  {
    throw std::runtime_error("XML: " + what + " at offset " + std::to_string(at_));
  }
  bool startsWith(const char* prefix) const { return text_.compare(at_, std::strlen(prefix), prefix) == 0; }
  void skipSpace()
  {
    while (at_ < text_.size() && std::isspace(static_cast<unsigned char>(text_[at_]))) ++at_;
  }
  void skipPast(const char* end)
  {
    std::size_t found = text_.find(end, at_);
    if (found == std::string::npos) fail(std::string("missing ") + end);
    at_ = found + std::strlen(end);
  }
  void skipMisc()
  {
    while (true) {
      skipSpace();
      if (startsWith("<?")) skipPast("?>");
      else if (startsWith("<!--")) skipPast("-->");
      else if (startsWith("<!DOCTYPE")) skipPast(">");
      else return;
    }
  }
  std::string name()
  {
    std::size_t start = at_;
    while (at_ < text_.size() && (std::isalnum(static_cast<unsigned char>(text_[at_])) ||
                                  text_[at_] == '_' || text_[at_] == ':' || text_[at_] == '-' ||
                                  text_[at_] == '.'))
      ++at_;
    if (at_ == start) fail("expected a name");
    return text_.substr(start, at_ - start);
  }
  XmlElement element()
  {
    if (!startsWith("<")) fail("expected '<'");
    ++at_;
    XmlElement node;
    node.name = name();
    while (true) {
      skipSpace();
      if (startsWith("/>")) {
        at_ += 2;
        return node;
      }
      if (startsWith(">")) {
        ++at_;
        break;
      }
      std::string key = name();
      skipSpace();
      if (!startsWith("=\"")) fail("expected =\" after attribute " + key);
      at_ += 2;
      std::size_t end = text_.find('"', at_);
      if (end == std::string::npos) fail("unterminated attribute value");
      if (!node.attributes.emplace(key, text_.substr(at_, end - at_)).second)
        fail("repeated attribute " + key);
      at_ = end + 1;
    }
    while (true) {
      if (at_ >= text_.size()) fail("element <" + node.name + "> is not closed");
      if (startsWith("<!--")) {
        skipPast("-->");
      } else if (startsWith("</")) {
        at_ += 2;
        std::string closing = name();
        if (closing != node.name) fail("<" + node.name + "> closed by </" + closing + ">");
        skipSpace();
        if (!startsWith(">")) fail("expected '>'");
        ++at_;
        return node;
      } else if (startsWith("<")) {
        node.children.push_back(element());
      } else {
        node.text += text_[at_++];
      }
    }
  }

  const std::string& text_;
  std::size_t at_ = 0;
};

/// Whitespace-separated numbers of a text.
inline std::vector<double> numbersIn(const std::string& text)
{
  std::istringstream in(text);
  std::vector<double> numbers;
  double x;
  while (in >> x) numbers.push_back(x);
  return numbers;
}

}  // namespace cfdmpm::io_test
