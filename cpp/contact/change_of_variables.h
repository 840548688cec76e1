// The change of variables that turns each Signorini constraint into a bound
// (derived in docs/theory.md, "Constraints as bounds: the change of
// variables" and "Faults"). At a contact node the constraints nu_j . u <= g_j
// (m foundations touch the node, m <= d) are bounds w_j <= g_j on w = T u,
// the first m rows of the d x d matrix T the normals nu_j, the rest
// completing them to a basis (node_change_of_variables). At a fault's node
// pair (u+, u-) a 2d x 2d block makes the jump and the mean the new variables
// (pair_change_of_variables), where faults meet one block each pair's normal
// jump (junction_change_of_variables). For x' = T x, T block-diagonal,
// A x = b becomes A' x' = b', A' = T^{-T} A T^{-1}, b' = T^{-T} b: the same
// energy; its residual F' = T^{-T} F holds, in a constraint's row, its
// multiplier. Without a fault or a normal off the axes T is never formed.
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
/// first, completed to a basis orthonormally (Gram-Schmidt of the
/// coordinate axes), so with one foundation T_node is a rotation into
/// (normal, tangential) components, and with two the rows are the two
/// normals and the tangent they share (T_node is then not orthogonal, but
/// invertible). `prescribed[i]` says the node's displacement component i
/// is prescribed (a Dirichlet condition): the change must keep that
/// component (every normal perpendicular to it), or the node must be
/// prescribed entirely. Returns nothing when the normals are not
/// independent (a normal within 1e-8 of the span of the ones before it) or
/// the change would mix a prescribed component with a free one.
std::optional<NodeMatrix> node_change_of_variables(const std::vector<std::array<double, 3>>& normals, int d,
                                                   const std::array<bool, 3>& prescribed);

/// The inverse of an n x n matrix (row-major; Gauss-Jordan elimination
/// with partial pivoting, for the small blocks of T).
std::vector<double> inverse(const std::vector<double>& T, int n);

/// The d x d matrix of T_node, row-major in n x n = d x d entries.
std::vector<double> node_block(const NodeMatrix& T, int d);

/// The 2d x 2d block of a fault's node pair for the rotation R (T_node of
/// the constraint normal nu): rows [R, -R] (the jump) and [I/2, I/2] (the
/// mean), columns (u+, u-). The constraint is on the jump, nu . (u+ - u-)
/// <= g with nu = -n (n the fault's normal, pointing into the + side), and
///     [w_J]   [R  -R ] [u+]        [u+]   [R^T/2  I] [w_J]
///     [w_M] = [I/2 I/2] [u-],       [u-] = [-R^T/2 I] [w_M]
/// makes the jump in (normal, tangential) components w_J (in u+'s rows)
/// and the mean w_M (in u-'s rows) the new variables: the constraint is
/// the bound w_J0 <= g.
std::vector<double> pair_change_of_variables(const NodeMatrix& R, int d);

/// @brief A fault pair at a junction (where faults cross or end on one
/// another), as the junction's block sees it: the positions of its + and -
/// nodes among the block's nodes, the row of its + node that carries its
/// constraint (0..d-1), and the constraint's normal nu = -n.
struct JunctionPair
{
  int plus = 0, minus = 0, row = 0;
  std::array<double, 3> normal{0, 0, 0};
};

/// The block of T at a junction (its m nodes, the pieces around it, d DOFs
/// each in node order): row d plus + row of each pair is its constraint
/// nu . (u+ - u-), so each is a bound on an unknown of its own; the row of
/// each `prescribed` DOF is its unit vector (the DOF stays its own unknown);
/// the other rows complete them to a basis, orthonormal and orthogonal to
/// the rows before (Gram-Schmidt of the unit vectors). Around a junction
/// the jumps of its pairs sum to zero, so they cannot all be unknowns as at
/// a lone pair; their normal components are independent wherever the faces
/// bounding each piece are not all parallel. Returns nothing when they are
/// not (to 1e-8), or a constraint sits in a prescribed row or reaches a
/// prescribed DOF.
std::optional<std::vector<double>> junction_change_of_variables(const std::vector<JunctionPair>& pairs, int m,
                                                                int d, const std::vector<char>& prescribed);

/// The axis of a unit normal that is a coordinate axis (to round-off
/// 1e-14), with its sign; nothing otherwise. A node whose normals are all
/// coordinate axes needs no change: its bound is on u_i itself.
std::optional<std::pair<int, int>> coordinate_axis(const std::array<double, 3>& normal, int d);

/// @brief The block-diagonal change of variables x' = T x of a system
/// (vectors like A's columns; the blocks at the transformed nodes and
/// pairs, the identity elsewhere), and the operators it makes.
class ChangeOfVariables
{
public:
  /// @brief One block of T: the DOFs it mixes (global indices of a vector
  /// like A's columns, on any rank: a fault's two faces may be owned by two)
  /// and its n x n matrix, row-major.
  struct Block
  {
    std::vector<PetscInt> dofs;
    std::vector<double> T;
  };

  /// T from its blocks (each given on one rank; collective). `spd`: A is
  /// symmetric positive definite (so is A').
  ChangeOfVariables(Mat A, const std::vector<Block>& blocks, bool spd);
  ~ChangeOfVariables();
  ChangeOfVariables(const ChangeOfVariables&) = delete;
  ChangeOfVariables& operator=(const ChangeOfVariables&) = delete;

  /// y = T x.
  void forward(Vec x, Vec y) const;
  /// x = T^{-1} y.
  void backward(Vec y, Vec x) const;
  /// g = T^{-T} f: a load or a residual in the new variables. A residual
  /// F' = T^{-T} F holds, in the row of a constraint, its multiplier:
  /// F = T^T F' = sum_j F'_j (row j of T).
  void dual(Vec f, Vec g) const;
  /// A' = T^{-T} A T^{-1} (collective), the same energy in the new
  /// variables: symmetric (SPD) when A is. Reuses A''s structure when *At
  /// is already made. A's near-nullspace, transformed, carries over.
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
