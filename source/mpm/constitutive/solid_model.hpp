#pragma once
// SolidModel: one material's constitutive model as a tagged union of the concrete model types, so
// particle kernels call the right model with no virtual call and no allocation.
//
// Preferred use: dispatch once per material, outside the particle loop, with visit(); the kernel
// then holds the concrete model by value and the compiler inlines its update:
//
//     material.model.visit([&](const auto& model) {
//       Kokkos::parallel_for("mpm::stress_update", Kokkos::RangePolicy<>(begin, end),
//                            KOKKOS_LAMBDA(const int p) {
//                              ... model.update(kinematics, state, stress) ...
//                            });
//     });
//
// For code that mixes materials in one loop, SolidModel::update() switches on the tag per call.
//
// Every model type provides
//     template <int Dim> KOKKOS_INLINE_FUNCTION
//     void update(const StepKinematics<Dim>&, MaterialState&, Mat<Dim>& stress) const;
//     KOKKOS_INLINE_FUNCTION double waveSpeed(double density) const;
// Adding a model: doc/mpm-models.md, "Adding a model".
#include "mpm/constitutive/drucker_prager.hpp"
#include "mpm/constitutive/linear_elastic.hpp"
#include "mpm/constitutive/neo_hookean.hpp"
#include "mpm/constitutive/rigid.hpp"
#include "mpm/constitutive/tresca.hpp"

#include <type_traits>

namespace cfdmpm::mpm {

enum class SolidModelKind { LinearElastic, NeoHookean, Tresca, DruckerPrager, Rigid };

/// Name of a model kind as written in input files.
inline const char* solidModelName(SolidModelKind kind)
{
  switch (kind) {
    case SolidModelKind::LinearElastic: return "linear_elastic";
    case SolidModelKind::NeoHookean: return "neo_hookean";
    case SolidModelKind::Tresca: return "tresca";
    case SolidModelKind::DruckerPrager: return "drucker_prager";
    case SolidModelKind::Rigid: return "rigid";
  }
  return "unknown";
}

class SolidModel {
 public:
  SolidModel(const LinearElastic& model) : kind_(SolidModelKind::LinearElastic), model_(model) {}
  SolidModel(const NeoHookean& model) : kind_(SolidModelKind::NeoHookean), model_(model) {}
  SolidModel(const Tresca& model) : kind_(SolidModelKind::Tresca), model_(model) {}
  SolidModel(const DruckerPrager& model) : kind_(SolidModelKind::DruckerPrager), model_(model) {}
  SolidModel(const Rigid& model) : kind_(SolidModelKind::Rigid), model_(model) {}

  KOKKOS_INLINE_FUNCTION SolidModelKind kind() const { return kind_; }
  const char* name() const { return solidModelName(kind_); }

  /// Calls visitor(const Model&) with the concrete model and returns its result (every overload
  /// must return the same type).
  template <class Visitor>
  KOKKOS_INLINE_FUNCTION decltype(auto) visit(Visitor&& visitor) const
  {
    switch (kind_) {
      case SolidModelKind::NeoHookean: return visitor(model_.neo_hookean);
      case SolidModelKind::Tresca: return visitor(model_.tresca);
      case SolidModelKind::DruckerPrager: return visitor(model_.drucker_prager);
      case SolidModelKind::Rigid: return visitor(model_.rigid);
      case SolidModelKind::LinearElastic: break;
    }
    return visitor(model_.linear_elastic);
  }

  /// The concrete model if it is a T, else nullptr.
  template <class T>
  KOKKOS_INLINE_FUNCTION const T* getIf() const
  {
    if constexpr (std::is_same_v<T, LinearElastic>)
      return kind_ == SolidModelKind::LinearElastic ? &model_.linear_elastic : nullptr;
    else if constexpr (std::is_same_v<T, NeoHookean>)
      return kind_ == SolidModelKind::NeoHookean ? &model_.neo_hookean : nullptr;
    else if constexpr (std::is_same_v<T, Tresca>)
      return kind_ == SolidModelKind::Tresca ? &model_.tresca : nullptr;
    else if constexpr (std::is_same_v<T, DruckerPrager>)
      return kind_ == SolidModelKind::DruckerPrager ? &model_.drucker_prager : nullptr;
    else {
      static_assert(std::is_same_v<T, Rigid>, "not a SolidModel alternative");
      return kind_ == SolidModelKind::Rigid ? &model_.rigid : nullptr;
    }
  }

  /// Stress update with a switch on the tag (per call). Prefer visit() outside the loop.
  template <int Dim>
  KOKKOS_INLINE_FUNCTION void update(const StepKinematics<Dim>& kinematics, MaterialState& state,
                                     Mat<Dim>& stress) const
  {
    switch (kind_) {
      case SolidModelKind::LinearElastic:
        model_.linear_elastic.update(kinematics, state, stress);
        return;
      case SolidModelKind::NeoHookean: model_.neo_hookean.update(kinematics, state, stress); return;
      case SolidModelKind::Tresca: model_.tresca.update(kinematics, state, stress); return;
      case SolidModelKind::DruckerPrager:
        model_.drucker_prager.update(kinematics, state, stress);
        return;
      case SolidModelKind::Rigid: model_.rigid.update(kinematics, state, stress); return;
    }
  }

  /// Dilatational wave speed (m/s) at the given density, for the time step (0 for Rigid).
  KOKKOS_INLINE_FUNCTION double waveSpeed(double density) const
  {
    switch (kind_) {
      case SolidModelKind::LinearElastic: return model_.linear_elastic.waveSpeed(density);
      case SolidModelKind::NeoHookean: return model_.neo_hookean.waveSpeed(density);
      case SolidModelKind::Tresca: return model_.tresca.waveSpeed(density);
      case SolidModelKind::DruckerPrager: return model_.drucker_prager.waveSpeed(density);
      case SolidModelKind::Rigid: return model_.rigid.waveSpeed(density);
    }
    return 0.0;
  }

 private:
  // The alternatives are trivially copyable value types, so the union (and SolidModel) is too:
  // Kokkos lambdas capture it by plain copy.
  union Storage {
    LinearElastic linear_elastic;
    NeoHookean neo_hookean;
    Tresca tresca;
    DruckerPrager drucker_prager;
    Rigid rigid;
    Storage(const LinearElastic& m) : linear_elastic(m) {}
    Storage(const NeoHookean& m) : neo_hookean(m) {}
    Storage(const Tresca& m) : tresca(m) {}
    Storage(const DruckerPrager& m) : drucker_prager(m) {}
    Storage(const Rigid& m) : rigid(m) {}
  };

  SolidModelKind kind_;
  Storage model_;
};

static_assert(std::is_trivially_copyable_v<SolidModel>,
              "SolidModel must be trivially copyable to live in kernels");

}  // namespace cfdmpm::mpm
