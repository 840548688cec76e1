// The change of variables that turns each Signorini constraint into a bound.
//
// At a contact node with displacement u (d components) the constraints
//     nu_j . u <= g_j,   j = 1..m (m foundations touch the node, m <= d),
// are bounds on the new variables w = T u when the first m rows of the
// d x d matrix T are the normals nu_j: w_j <= g_j. The remaining rows
// complete the normals to a basis, orthonormally (Gram-Schmidt of the
// coordinate axes), so with one foundation T is a rotation into (normal,
// tangential) components, and with two it is the inverse of the matrix of
// their normals completed by the tangent they share.
//
// For the whole system x' = T x, T block-diagonal (T_node at the transformed
// nodes, the identity elsewhere), and A x = b becomes
//     A' x' = b',   A' = T^{-T} A T^{-1},   b' = T^{-T} b,
// the same energy in the new variables: A' is symmetric (SPD) when A is,
// and its residual F' = A' x' - b' = T^{-T} F holds, in row j of a node,
// the multiplier of constraint j: F = T^T F' = sum_j F'_j nu_j. Nodes whose
// normals are coordinate axes need no change (their bound is on u_i
// itself); when every node is such, T is the identity and never formed.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <petscmat.h>
#include <vector>

namespace biotcontact
{

/// A d x d matrix, row-major in the first d*d entries.
using NodeMatrix = std::array<double, 9>;

/// T_node for the unit normals of the foundations at one node: their rows
/// first, completed orthonormally. `prescribed[i]` says the node's
/// displacement component i is prescribed (a Dirichlet condition): the
/// change must keep that component (every normal perpendicular to it), or
/// the node must be prescribed entirely. Returns nothing when the normals
/// are not independent (condition number of their rows above 1e8) or the
/// change would mix a prescribed component with a free one.
std::optional<NodeMatrix> node_change_of_variables(const std::vector<std::array<double, 3>>& normals, int d,
                                                   const std::array<bool, 3>& prescribed);

/// The inverse of a d x d matrix (d = 2, 3).
NodeMatrix inverse(const NodeMatrix& T, int d);

/// The axis of a unit normal that is a coordinate axis (to round-off
/// 1e-14), with its sign; nothing otherwise.
std::optional<std::pair<int, int>> coordinate_axis(const std::array<double, 3>& normal, int d);

/// @brief The block-diagonal change of variables x' = T x of a system
/// (vectors like A's columns), and the operators it makes.
class ChangeOfVariables
{
public:
  /// One transformed node: its d DOFs (local indices of a vector like A's
  /// columns, owned here) and T_node.
  struct Node
  {
    std::array<std::int32_t, 3> dofs;
    NodeMatrix T;
  };

  /// `spd`: A is symmetric positive definite (so is A').
  ChangeOfVariables(Mat A, int d, const std::vector<Node>& nodes, bool spd);
  ~ChangeOfVariables();
  ChangeOfVariables(const ChangeOfVariables&) = delete;
  ChangeOfVariables& operator=(const ChangeOfVariables&) = delete;

  /// y = T x.
  void forward(Vec x, Vec y) const;
  /// x = T^{-1} y.
  void backward(Vec y, Vec x) const;
  /// g = T^{-T} f: a load or a residual in the new variables.
  void dual(Vec f, Vec g) const;
  /// A' = T^{-T} A T^{-1} (collective); reuses A''s structure when *At is
  /// already made. A's near-nullspace, transformed, carries over.
  void congruence(Mat A, Mat* At) const;
  /// The vectors T v of a near-nullspace (rigid-body modes for AMG),
  /// orthonormalised. Its vectors are like A's columns, or, given `dofs`,
  /// those of a field (the global indices of their entries in a vector like
  /// `layout`).
  MatNullSpace transformed(MatNullSpace modes, const std::vector<PetscInt>* dofs = nullptr,
                           Vec layout = nullptr) const;

private:
  void forward_field(Vec v, Vec t, const std::vector<PetscInt>& dofs, Vec layout) const;

  Mat _T = nullptr, _T_inverse = nullptr;
  bool _spd;
};

} // namespace biotcontact
