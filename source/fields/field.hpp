#pragma once
// Fields on cells or nodes: a Tpetra MultiVector on the layout's overlap map (one column per
// material or component) whose owned rows are a prefix of the same storage. Kernels read and write
// the local Kokkos view; the two parallel operations are the halo exchange (ghosts take their
// owner's value) and the node sum (owners add the ghosts' contributions, for particle-to-grid).
#include "common/types.hpp"
#include "grid/layout.hpp"

#include <Tpetra_MultiVector.hpp>

#include <memory>
#include <string>

namespace cfdmpm {

enum class Location { Cell, Node };

template <int Dim>
class Field {
 public:
  using MultiVector = Tpetra::MultiVector<Scalar, LocalOrdinal, GlobalOrdinal, Node>;
  using View = typename MultiVector::dual_view_type::t_dev;  // (local entry, column)
  using ConstView = typename View::const_type;

  /// A zero field with `columns` columns on the layout's cells or nodes.
  Field(std::shared_ptr<const Layout<Dim>> layout, Location location, int columns, std::string name);

  const std::string& name() const { return name_; }
  Location location() const { return location_; }
  int columns() const { return int(overlap_->getNumVectors()); }
  LocalOrdinal ownedCount() const { return LocalOrdinal(owned_->getLocalLength()); }
  LocalOrdinal overlapCount() const { return LocalOrdinal(overlap_->getLocalLength()); }
  const Layout<Dim>& layout() const { return *layout_; }

  /// Read-write view of all local entries (owned first, then ghosts).
  View view() { return overlap_->getLocalViewDevice(Tpetra::Access::ReadWrite); }
  ConstView view() const { return overlap_->getLocalViewDevice(Tpetra::Access::ReadOnly); }

  MultiVector& owned() { return *owned_; }
  const MultiVector& owned() const { return *owned_; }
  MultiVector& overlapped() { return *overlap_; }

  void fill(Scalar value) { overlap_->putScalar(value); }

  /// Ghost entries take the values of their owners (Tpetra Import, INSERT).
  void exchangeHalo();

  /// Owners add the values held in their ghost copies on other ranks (Tpetra Export, ADD), then
  /// the sums are copied back to the ghosts. Local ghost entries are set to the owners' sums.
  void sumToOwners();

  /// Moves the owned values to a new layout (new partition of the same grid) and refreshes ghosts.
  void repartition(std::shared_ptr<const Layout<Dim>> new_layout);

  /// Takes the owned values of `source`, a field of the same grid, location and columns on another
  /// layout (another partition), through a Tpetra Import between the owned maps. Ghosts are left
  /// as they were (exchangeHalo refreshes them).
  void importOwned(const Field& source);

  /// Exchanges the values (owned and ghost) with `other`, a field of the same layout, location and
  /// column count, without copying: a kernel can write new values into a second field and then
  /// make them this field's. Names stay with their fields.
  void swapValues(Field& other);

 private:
  void allocate();
  const Teuchos::RCP<const Map>& ownedMap() const;
  const Teuchos::RCP<const Map>& overlapMap() const;
  const Teuchos::RCP<const typename Layout<Dim>::Import>& importer() const;
  /// True on one rank when the halo Import only maps the owned rows onto themselves (no ghosts).
  bool selfOnly() const;

  std::shared_ptr<const Layout<Dim>> layout_;
  Location location_;
  std::string name_;
  Teuchos::RCP<MultiVector> overlap_;  // storage
  Teuchos::RCP<MultiVector> owned_;    // view of the owned prefix of overlap_
};

extern template class Field<2>;
extern template class Field<3>;

}  // namespace cfdmpm
