#include "mpmice/state_output.hpp"

#include "common/mpi_comm.hpp"

#include <algorithm>

namespace cfdmpm {

template <int Dim>
void StateOutput<Dim>::checkFields(const Scene& scene)
{
  // write() below writes each of these (the names the input accepts).
  const std::vector<std::string>& written = outputFieldNames();
  for (const std::string& f : scene.output.fields)
    if (std::find(written.begin(), written.end(), f) == written.end()) {
      std::string names;
      for (const std::string& name : written) names += (names.empty() ? "" : ", ") + name;
      throw InputError("cfdmpm.output.fields: got '" + f + "'; this version writes " + names);
    }
}

template <int Dim>
StateOutput<Dim>::StateOutput(const Scene& scene, const Layout<Dim>& layout, const std::string& run_name)
    : fields_(scene.output.fields), directory_(scene.output.directory), run_name_(run_name)
{
  for (const auto& m : scene.materials) material_names_.push_back(m.name);
  const MPI_Comm comm = rawMpiComm(layout.comm());
  const OutputLayout cells = outputLayout(layout.grid(), Location::Cell, layout.ownedCellBoxes());
  const OutputLayout nodes = outputLayout(layout.grid(), Location::Node, layout.ownedNodeBoxes());
  hdf5_ = std::make_unique<Hdf5Writer>(comm, directory_, run_name, cells, nodes);
  xdmf_ = std::make_unique<XdmfWriter>(comm, directory_, run_name, cells, nodes);
}

template <int Dim>
void StateOutput<Dim>::moveTo(const Layout<Dim>& layout)
{
  hdf5_ = std::make_unique<Hdf5Writer>(rawMpiComm(layout.comm()), directory_, run_name_,
                                       outputLayout(layout.grid(), Location::Cell, layout.ownedCellBoxes()),
                                       outputLayout(layout.grid(), Location::Node, layout.ownedNodeBoxes()));
}

template <int Dim>
void StateOutput<Dim>::writeColumns(const Field<Dim>& field, int first_column, int components, const std::string& name)
{
  // Owned rows are in ascending global id, the order the writer expects; components interleave.
  const auto v = field.view();
  const LocalOrdinal n = field.ownedCount();
  buffer_.resize(std::size_t(n) * components);
  for (LocalOrdinal l = 0; l < n; ++l)
    for (int c = 0; c < components; ++c) buffer_[std::size_t(l) * components + c] = v(l, first_column + c);
  if (components == 1)
    hdf5_->writeScalar(OutputLocation::Cells, name, buffer_.data(), buffer_.size());
  else
    hdf5_->writeVector(OutputLocation::Cells, name, buffer_.data(), buffer_.size());
}

template <int Dim>
std::string StateOutput<Dim>::write(long long step, double time, const CellState<Dim>& state,
                                    const mpm::ParticleOutput* particles)
{
  auto wanted = [&](const char* name) { return std::find(fields_.begin(), fields_.end(), name) != fields_.end(); };
  hdf5_->beginStep(step, time);
  if (wanted("pressure")) writeColumns(state.pressure, 0, 1, "pressure");
  for (int m = 0; m < state.materials; ++m) {
    const std::string prefix = material_names_[m] + "/";
    if (wanted("volume_fraction")) writeColumns(state.volume_fraction, m, 1, prefix + "volume_fraction");
    if (wanted("density")) writeColumns(state.density, m, 1, prefix + "density");
    if (wanted("specific_volume")) writeColumns(state.specific_volume, m, 1, prefix + "specific_volume");
    if (wanted("temperature")) writeColumns(state.temperature, m, 1, prefix + "temperature");
    if (wanted("velocity")) writeColumns(state.velocity, CellState<Dim>::velocityColumn(m, 0), Dim, prefix + "velocity");
  }
  if (particles) {
    // Positions and ids always (the particles' geometry, and what follows a particle from step to
    // step and across rank counts), then the particle fields asked for.
    const std::size_t n = particles->count;
    hdf5_->writeParticleVector("position", particles->position.data(), n, Dim);
    buffer_.assign(particles->id.begin(), particles->id.end());  // exact as float64 below 2^53
    hdf5_->writeParticleScalar("id", buffer_.data(), n);
    if (wanted("particle_velocity")) hdf5_->writeParticleVector("velocity", particles->velocity.data(), n, Dim);
    if (wanted("particle_stress")) hdf5_->writeParticleVector("stress", particles->stress.data(), n, 9);
    if (wanted("plastic_strain")) hdf5_->writeParticleScalar("plastic_strain", particles->plastic_strain.data(), n);
    if (wanted("particle_volume")) hdf5_->writeParticleScalar("volume", particles->volume.data(), n);
    if (wanted("particle_material")) {
      buffer_.assign(particles->material.begin(), particles->material.end());
      hdf5_->writeParticleScalar("material", buffer_.data(), n);
    }
  }
  const WrittenStep written = hdf5_->endStep();
  xdmf_->addStep(written);
  return directory_ + "/" + written.file;
}

template class StateOutput<2>;
template class StateOutput<3>;

}  // namespace cfdmpm
