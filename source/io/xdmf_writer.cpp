#include "io/xdmf_writer.hpp"

#include "io/collective.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace cfdmpm {
namespace {

std::string number(double value)
{
  char text[32];
  std::snprintf(text, sizeof text, "%.17g", value);
  return text;
}

std::string escaped(const std::string& text)
{
  std::string out;
  for (char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

/// "a b c" from the dims, slowest first.
std::string dimensionList(const std::vector<long long>& dims)
{
  std::string out;
  for (std::size_t i = 0; i < dims.size(); ++i) out += (i ? " " : "") + std::to_string(dims[i]);
  return out;
}

/// Grid nodes per direction, slowest first: cells + 1; a 2-D grid is one node thick in z.
std::vector<long long> nodeDims(const OutputLayout& cells)
{
  std::vector<long long> dims;
  if (cells.dimension == 2) dims.push_back(1);
  for (int d = cells.dimension - 1; d >= 0; --d) dims.push_back(cells.global_count[d] + 1);
  return dims;
}

/// XDMF AttributeType for a field with this many components.
const char* attributeType(int components)
{
  switch (components) {
    case 1: return "Scalar";
    case 2:
    case 3: return "Vector";
    case 6: return "Tensor6";
    case 9: return "Tensor";
    default: return "Matrix";
  }
}

std::string attribute(const std::string& file, const WrittenField& field, const std::string& pad)
{
  return pad + "<Attribute Name=\"" + escaped(field.name) + "\" AttributeType=\"" +
         attributeType(field.components) + "\" Center=\"" +
         (field.location == OutputLocation::Cells ? "Cell" : "Node") + "\">\n" + pad +
         "  <DataItem Dimensions=\"" + dimensionList(field.display_dims) +
         "\" NumberType=\"Float\" Precision=\"8\" Format=\"HDF\">" + escaped(file) + ":" +
         escaped(field.display_dataset) + "</DataItem>\n" + pad + "</Attribute>\n";
}

std::string documentHead() { return "<?xml version=\"1.0\" ?>\n<Xdmf Version=\"2.0\">\n  <Domain>\n"; }
std::string documentTail() { return "  </Domain>\n</Xdmf>\n"; }

std::string stem(const std::string& file_name)
{
  return std::filesystem::path(file_name).stem().string();
}

bool nearlyEqual(double a, double b)
{
  return std::abs(a - b) <= 1e-12 * std::max({1.0, std::abs(a), std::abs(b)});
}

}  // namespace

std::string xdmfGrid(const OutputLayout& cells, const WrittenStep& step, int indent)
{
  const std::string pad(static_cast<std::size_t>(indent), ' ');
  // A 2-D grid is written as a 3-D grid one node thick at z = 0: ParaView's readers put a
  // 2DCoRectMesh in the plane x = 0 (its x along ParaView's y), which would not match the
  // (x, y, 0) vectors; this way both lie in the x-y plane.
  std::string origin = cells.dimension == 2 ? "0 " : "";
  std::string spacing =
      cells.dimension == 2 ? number(std::min(cells.spacing[0], cells.spacing[1])) + " " : "";
  for (int d = cells.dimension - 1; d >= 0; --d) {
    origin += number(cells.origin[d]) + (d ? " " : "");
    spacing += number(cells.spacing[d]) + (d ? " " : "");
  }

  std::string out = pad + "<Grid Name=\"" + escaped(stem(step.file)) + "\" GridType=\"Uniform\">\n";
  out += pad + "  <Time Value=\"" + number(step.time) + "\"/>\n";
  out += pad + "  <Topology TopologyType=\"3DCoRectMesh\" Dimensions=\"" +
         dimensionList(nodeDims(cells)) + "\"/>\n";
  out += pad + "  <Geometry GeometryType=\"ORIGIN_DXDYDZ\">\n";
  out += pad + "    <DataItem Name=\"Origin\" Dimensions=\"3\" NumberType=\"Float\" Precision=\"8\" "
               "Format=\"XML\">" + origin + "</DataItem>\n";
  out += pad + "    <DataItem Name=\"Spacing\" Dimensions=\"3\" NumberType=\"Float\" Precision=\"8\" "
               "Format=\"XML\">" + spacing + "</DataItem>\n";
  out += pad + "  </Geometry>\n";
  for (const WrittenField& field : step.fields)
    if (field.location != OutputLocation::Particles) out += attribute(step.file, field, pad + "  ");
  return out + pad + "</Grid>\n";
}

std::string xdmfParticleGrid(const WrittenStep& step, int indent)
{
  const WrittenField* position = nullptr;
  for (const WrittenField& field : step.fields)
    if (field.location == OutputLocation::Particles && field.name == "position") position = &field;
  if (!position || position->dims.empty() || position->dims[0] == 0 ||
      position->display_dims.size() != 2 || position->display_dims[1] != 3)
    return {};
  const long long count = position->dims[0];
  const std::string pad(static_cast<std::size_t>(indent), ' ');
  std::string out = pad + "<Grid Name=\"particles\" GridType=\"Uniform\">\n";
  out += pad + "  <Time Value=\"" + number(step.time) + "\"/>\n";
  out += pad + "  <Topology TopologyType=\"Polyvertex\" NumberOfElements=\"" + std::to_string(count) +
         "\" NodesPerElement=\"1\"/>\n";
  out += pad + "  <Geometry GeometryType=\"XYZ\">\n";
  out += pad + "    <DataItem Dimensions=\"" + dimensionList(position->display_dims) +
         "\" NumberType=\"Float\" Precision=\"8\" Format=\"HDF\">" + escaped(step.file) + ":" +
         escaped(position->display_dataset) + "</DataItem>\n";
  out += pad + "  </Geometry>\n";
  for (const WrittenField& field : step.fields)
    if (field.location == OutputLocation::Particles) out += attribute(step.file, field, pad + "  ");
  return out + pad + "</Grid>\n";
}

std::string xdmfStep(const OutputLayout& cells, const WrittenStep& step, int indent)
{
  const std::string particles = xdmfParticleGrid(step, indent + 2);
  if (particles.empty()) return xdmfGrid(cells, step, indent);
  const std::string pad(static_cast<std::size_t>(indent), ' ');
  return pad + "<Grid Name=\"" + escaped(stem(step.file)) +
         "\" GridType=\"Collection\" CollectionType=\"Spatial\">\n" + pad + "  <Time Value=\"" +
         number(step.time) + "\"/>\n" + xdmfGrid(cells, step, indent + 2) + particles + pad +
         "</Grid>\n";
}

void writeFileAtomically(const std::string& path, const std::string& text)
{
  const std::string temporary = path + ".tmp";
  {
    std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
    out << text;
    out.close();
    if (!out) throw std::runtime_error("writing " + temporary + " failed");
  }
  std::error_code error;
  std::filesystem::rename(temporary, path, error);
  if (error) throw std::runtime_error("renaming " + temporary + " to " + path + ": " + error.message());
}

XdmfWriter::XdmfWriter(MPI_Comm comm, std::string directory, std::string run_name,
                       const OutputLayout& cells, const OutputLayout& nodes)
    : comm_(comm), directory_(std::move(directory)), run_name_(std::move(run_name)), cells_(cells)
{
  bool same_grid = cells.dimension == nodes.dimension;
  for (int d = 0; d < cells.dimension && same_grid; ++d)
    same_grid = nodes.global_count[d] == cells.global_count[d] + 1 &&
                nearlyEqual(nodes.origin[d], cells.origin[d]) &&
                nearlyEqual(nodes.spacing[d], cells.spacing[d]);
  if (!same_grid)
    throw std::invalid_argument("XdmfWriter: the node layout must have one more node than cells in "
                                "each direction and the same origin and spacing");
}

std::string XdmfWriter::seriesPath() const
{
  return (std::filesystem::path(directory_) / (run_name_ + ".xmf")).string();
}

std::string XdmfWriter::stepPath(const WrittenStep& step) const
{
  return (std::filesystem::path(directory_) / (stem(step.file) + ".xmf")).string();
}

void XdmfWriter::addStep(const WrittenStep& step)
{
  bool replaced = false;
  for (WrittenStep& earlier : steps_)
    if (earlier.file == step.file) {
      earlier = step;
      replaced = true;
    }
  if (!replaced) steps_.push_back(step);

  io_detail::onRankZero(comm_, [&] {
    writeFileAtomically(stepPath(step), documentHead() + xdmfStep(cells_, step, 4) + documentTail());
    writeSeries();
  });
}

void XdmfWriter::restoreSteps(std::vector<WrittenStep> steps)
{
  steps_ = std::move(steps);
  io_detail::onRankZero(comm_, [&] { writeSeries(); });
}

void XdmfWriter::writeSeries() const
{
  std::string series = documentHead();
  series += "    <Grid Name=\"" + escaped(run_name_) +
            "\" GridType=\"Collection\" CollectionType=\"Temporal\">\n";
  for (const WrittenStep& written : steps_) series += xdmfStep(cells_, written, 6);
  series += "    </Grid>\n" + documentTail();
  writeFileAtomically(seriesPath(), series);
}

namespace {

std::string dimsText(const std::vector<long long>& dims)
{
  std::string text;
  for (std::size_t i = 0; i < dims.size(); ++i) text += (i ? " " : "") + std::to_string(dims[i]);
  return text;
}

std::vector<long long> dimsFromText(const std::string& text)
{
  std::istringstream in(text);
  std::vector<long long> dims;
  long long n = 0;
  while (in >> n) dims.push_back(n);
  return dims;
}

std::vector<std::string> tabFields(const std::string& line)
{
  std::vector<std::string> fields;
  std::size_t start = 0;
  while (true) {
    const std::size_t tab = line.find('\t', start);
    fields.push_back(line.substr(start, tab == std::string::npos ? std::string::npos : tab - start));
    if (tab == std::string::npos) return fields;
    start = tab + 1;
  }
}

}  // namespace

// step <TAB> number <TAB> time (%.17g, exact) <TAB> file
// field <TAB> location <TAB> components <TAB> name <TAB> dataset <TAB> dims <TAB> display dataset <TAB> display dims
std::string stepRecordsText(const std::vector<WrittenStep>& steps)
{
  std::string text;
  char time[32];
  for (const WrittenStep& step : steps) {
    std::snprintf(time, sizeof time, "%.17g", step.time);
    text += "step\t" + std::to_string(step.step) + "\t" + time + "\t" + step.file + "\n";
    for (const WrittenField& f : step.fields)
      text += "field\t" + std::to_string(int(f.location)) + "\t" + std::to_string(f.components) + "\t" + f.name +
              "\t" + f.dataset + "\t" + dimsText(f.dims) + "\t" + f.display_dataset + "\t" +
              dimsText(f.display_dims) + "\n";
  }
  return text;
}

std::vector<WrittenStep> stepRecordsFromText(const std::string& text)
{
  std::vector<WrittenStep> steps;
  std::istringstream in(text);
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    const std::vector<std::string> f = tabFields(line);
    try {
      if (f[0] == "step" && f.size() == 4) {
        WrittenStep step;
        step.step = std::stoll(f[1]);
        step.time = std::stod(f[2]);
        step.file = f[3];
        steps.push_back(step);
        continue;
      }
      if (f[0] == "field" && f.size() == 8 && !steps.empty()) {
        const int location = std::stoi(f[1]);
        if (location < 0 || location > int(OutputLocation::Particles)) throw std::invalid_argument("location");
        steps.back().fields.push_back(WrittenField{OutputLocation(location), f[3], f[4], std::stoi(f[2]),
                                                   dimsFromText(f[5]), f[6], dimsFromText(f[7])});
        continue;
      }
    } catch (const std::exception&) {
    }
    throw std::invalid_argument("output step records: line " + std::to_string(number) + " is not a record");
  }
  return steps;
}

}  // namespace cfdmpm
