#include "fields/field.hpp"

#include <stdexcept>
#include <utility>

namespace cfdmpm {

template <int Dim>
Field<Dim>::Field(std::shared_ptr<const Layout<Dim>> layout, Location location, int columns, std::string name)
    : layout_(std::move(layout)), location_(location), name_(std::move(name))
{
  overlap_ = Teuchos::rcp(new MultiVector(overlapMap(), columns, true));
  owned_ = overlap_->offsetViewNonConst(ownedMap(), 0);
}

template <int Dim>
const Teuchos::RCP<const Map>& Field<Dim>::ownedMap() const
{
  return location_ == Location::Cell ? layout_->ownedCellMap() : layout_->ownedNodeMap();
}

template <int Dim>
const Teuchos::RCP<const Map>& Field<Dim>::overlapMap() const
{
  return location_ == Location::Cell ? layout_->overlapCellMap() : layout_->overlapNodeMap();
}

template <int Dim>
const Teuchos::RCP<const typename Layout<Dim>::Import>& Field<Dim>::importer() const
{
  return location_ == Location::Cell ? layout_->cellImport() : layout_->nodeImport();
}

template <int Dim>
bool Field<Dim>::selfOnly() const
{
  const auto& import = *importer();
  return layout_->comm()->getSize() == 1 && import.getNumRemoteIDs() == 0 && import.getNumPermuteIDs() == 0 &&
         import.getNumExportIDs() == 0;
}

template <int Dim>
void Field<Dim>::exchangeHalo()
{
  // The owned rows are shared with the target, so the Import's "same" part copies onto itself.
  // With nothing to receive, send or permute on one rank, that copy is all it would do: skipped.
  if (selfOnly()) return;
  overlap_->doImport(*owned_, *importer(), Tpetra::INSERT);
}

template <int Dim>
void Field<Dim>::sumToOwners()
{
  // Reverse-mode Export with ADD: the owned prefix of the source is the target itself, which
  // Tpetra copies in place (not added), so each owned entry is counted once; remote ghosts add in.
  if (selfOnly()) return;
  owned_->doExport(*overlap_, *importer(), Tpetra::ADD);
  exchangeHalo();
}

template <int Dim>
void Field<Dim>::swapValues(Field& other)
{
  if (other.layout_ != layout_ || other.location_ != location_ || other.columns() != columns())
    throw std::invalid_argument("Field::swapValues: '" + name_ + "' and '" + other.name_ +
                                "' differ in layout, location or columns");
  std::swap(overlap_, other.overlap_);
  std::swap(owned_, other.owned_);
}

template <int Dim>
void Field<Dim>::repartition(std::shared_ptr<const Layout<Dim>> new_layout)
{
  const Teuchos::RCP<MultiVector> old_owned = owned_;
  const Teuchos::RCP<const Map> old_map = ownedMap();
  layout_ = std::move(new_layout);
  const typename Layout<Dim>::Import move(old_map, ownedMap());
  Teuchos::RCP<MultiVector> overlap = Teuchos::rcp(new MultiVector(overlapMap(), old_owned->getNumVectors(), true));
  Teuchos::RCP<MultiVector> owned = overlap->offsetViewNonConst(ownedMap(), 0);
  owned->doImport(*old_owned, move, Tpetra::INSERT);
  overlap_ = overlap;
  owned_ = owned;
  exchangeHalo();
}

template <int Dim>
void Field<Dim>::importOwned(const Field& source)
{
  if (source.location_ != location_ || source.columns() != columns())
    throw std::invalid_argument("Field::importOwned: '" + source.name_ + "' and '" + name_ +
                                "' differ in location or columns");
  const typename Layout<Dim>::Import move(source.ownedMap(), ownedMap());
  owned_->doImport(*source.owned_, move, Tpetra::INSERT);
}

template class Field<2>;
template class Field<3>;

}  // namespace cfdmpm
