#pragma once
// Types shared by every module: Tpetra's ordinals and node, Kokkos spaces, fixed-size vectors.
#include <Tpetra_Map.hpp>
#include <Kokkos_Core.hpp>

#include <array>

namespace cfdmpm {

using Scalar = double;
using LocalOrdinal = Tpetra::Map<>::local_ordinal_type;    // int
using GlobalOrdinal = Tpetra::Map<>::global_ordinal_type;  // long long
using Node = Tpetra::Map<>::node_type;
using ExecutionSpace = Node::execution_space;
using MemorySpace = Node::memory_space;

using Map = Tpetra::Map<LocalOrdinal, GlobalOrdinal, Node>;

/// A point or a vector in Dim dimensions (Dim = 2 or 3).
template <int Dim>
using Vec = std::array<double, Dim>;

/// Integer index in Dim dimensions.
template <int Dim>
using Index = std::array<long long, Dim>;

}  // namespace cfdmpm
