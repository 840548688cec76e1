// How a factorised VI's Newton steps meet a changed Jacobian: by GMRES on an
// earlier factorisation where a factorisation costs about 100 back-solves
// (3D friction, a 3D conduit fault's apertures), or by factorising each
// change with a cheap analysis where it costs fewer (2D friction, a 2D
// conduit fault). docs/theory.md, "Solvers"; docs/performance.md,
// "thirty-fourth session", "fortieth session".
#pragma once

#include <petscsnes.h>
#include <string>
#include <utility>
#include <vector>

namespace biotcontact
{

/// The options (name without its dash, value) under which the Newton steps
/// of the VI with options prefix `prefix` run GMRES on the last
/// factorisation: to 1e-12 (near a direct solve's round-off) in at most
/// 100 iterations, each unless the user gave it. SNES VI sets its KSP up
/// from the options again when the inactive set changes, hence options.
std::vector<std::pair<std::string, std::string>> reuse_options(const std::string& prefix);

/// The largest system whose factorisations analyse_quickly hands to AMD:
/// above it AMD's fill costs more than METIS's analysis saves (a 2D
/// frictional crack of 3.7e5 unknowns 3 % slower, factorised twice).
constexpr PetscInt quick_analysis_rows = 300000;

/// MUMPS's analysis by AMD instead of its own choice (METIS) for the
/// factorisations of K, the system with options prefix `prefix` (or of
/// its copy on each rank), unless the user chose or K has more than
/// quick_analysis_rows rows: 0.009 s against 0.13 s at 13,414 unknowns,
/// for back-solves about 10 % dearer.
void analyse_quickly(const std::string& prefix, Mat K);

/// @brief reuse_options in PETSc's database while the VI solves (the
/// system's own solvers share its prefix and stay direct), the values
/// before restored after.
class KrylovOnReuse
{
public:
  KrylovOnReuse(SNES snes, const std::vector<std::pair<std::string, std::string>>& options);
  ~KrylovOnReuse();
  KrylovOnReuse(const KrylovOnReuse&) = delete;
  KrylovOnReuse& operator=(const KrylovOnReuse&) = delete;

private:
  std::vector<std::pair<std::string, std::string>> _before;
};

} // namespace biotcontact
