#include "assembly/fault_aperture.h"

#include "assembly/petsc_error.h"

#include <dolfinx/fem/DirichletBC.h>
#include <dolfinx/fem/assembler.h>
#include <bit>
#include <set>

namespace biotcontact
{
using namespace dolfinx;

FaultNodes fault_nodes(const Domain& domain, const fem::FunctionSpace& V)
{
  const mesh::Mesh& mesh = *domain.mesh;
  const int tdim = mesh.topology().dim();
  std::set<std::int64_t> wanted;
  for (const auto& [name, fault] : domain.faults)
  {
    for (const auto& pair : fault.pairs)
      wanted.insert(pair.begin(), pair.end());
    wanted.insert(fault.cells.keys.begin(), fault.cells.keys.end());
  }
  // Vertex k of a cell is its DOF k of a P1 space.
  const std::vector<std::int64_t> input = vertex_input_indices(mesh);
  const auto c_to_v = mesh.topology().connectivity(tdim, 0);
  FaultNodes nodes;
  for (std::int32_t cell = 0; cell < c_to_v->num_nodes(); ++cell)
  {
    auto vertices = c_to_v->links(cell);
    auto dofs = V.dofmap()->cell_dofs(cell);
    for (std::size_t k = 0; k < vertices.size(); ++k)
      if (wanted.count(input[vertices[k]]))
        nodes.local[input[vertices[k]]] = dofs[k];
  }
  // Every rank learns the global node of each fault node from its owner.
  const auto& map = *V.dofmap()->index_map;
  std::vector<std::int64_t> mine;
  for (const auto& [index, node] : nodes.local)
    if (node < map.size_local())
      mine.insert(mine.end(), {index, map.local_range()[0] + node});
  const std::vector<std::int64_t> all = all_gather(mine, mesh.comm()).values;
  for (std::size_t i = 0; i < all.size(); i += 2)
    nodes.global[all[i]] = all[i + 1];
  return nodes;
}

FaultAperture::FaultAperture(const Scene& scene, const Domain& domain, const fem::FunctionSpace& V)
    : _comm(domain.mesh->comm()), _rows(fault_rows(scene, domain))
{
  const int d = domain.dim();
  _size = _rows.size();
  const FaultNodes nodes = fault_nodes(domain, V);
  const auto columns = static_cast<PetscInt>(d * V.dofmap()->index_map->size_local());
  check_petsc(MatCreateAIJ(_comm, _rows.owned(), columns, PETSC_DETERMINE, PETSC_DETERMINE, 2 * d * d, nullptr,
                           2 * d * d, nullptr, &_J),
              "the fault apertures: MatCreateAIJ of J");
  std::int64_t cell = 0; // among every conduit's cells
  for (const auto& [name, f] : scene.faults)
  {
    const auto index = static_cast<std::int64_t>(_fault_index.size());
    _fault_index[name] = index;
    if (f.flow != FaultFlow::conduit)
      continue;
    const FaultCells& cells = domain.faults.at(name).cells;
    _keys.insert(_keys.end(), cells.keys.begin(), cells.keys.end());
    _fault.insert(_fault.end(), cells.size(), index);
    for (std::size_t k = 0; k < cells.size(); ++k, ++cell)
    {
      if (!_rows.owns(cell))
        continue;
      const PetscInt row = _rows.row[cell];
      double gap = 0;
      for (int i = 0; i < d; ++i)
      {
        gap += f.gap(cells.vertices[d * k + i].data(), 0.0) / d;
        for (const auto& [node, sign] : {std::pair{cells.keys[d * k + i], 1.0}, {cells.twins[d * k + i], -1.0}})
          for (int j = 0; j < d; ++j)
            check_petsc(MatSetValue(_J, row, static_cast<PetscInt>(d * nodes.global.at(node) + j),
                                    sign * cells.normals[k][j] / d, ADD_VALUES),
                        "the fault apertures: MatSetValue of J");
      }
      _gap.push_back(gap);
      _measures.push_back(cells.measures[k]);
    }
  }
  check_petsc(MatAssemblyBegin(_J, MAT_FINAL_ASSEMBLY), "the fault apertures: MatAssemblyBegin of J");
  check_petsc(MatAssemblyEnd(_J, MAT_FINAL_ASSEMBLY), "the fault apertures: MatAssemblyEnd of J");
  check_petsc(MatCreateVecs(_J, nullptr, &_cells), "the fault apertures: MatCreateVecs of J");
}

FaultAperture::~FaultAperture()
{
  warn_petsc(MatDestroy(&_J), "the fault apertures: MatDestroy of J");
  warn_petsc(VecDestroy(&_cells), "the fault apertures: VecDestroy");
}

std::vector<double> FaultAperture::opening(la::Vector<double>& u) const
{
  la::petsc::Vector x = wrap(u);
  check_petsc(MatMult(_J, x.vec(), _cells), "the fault apertures' opening: MatMult");
  std::vector<double> w(_gap.size());
  const PetscScalar* W;
  check_petsc(VecGetArrayRead(_cells, &W), "the fault apertures' opening: VecGetArrayRead");
  for (std::size_t k = 0; k < _gap.size(); ++k)
    w[k] = _gap[k] + W[k];
  check_petsc(VecRestoreArrayRead(_cells, &W), "the fault apertures' opening: VecRestoreArrayRead");
  return _rows.everywhere(w);
}

std::vector<double> FaultAperture::cell_means(const std::map<std::pair<std::string, std::int64_t>, double>& nodal) const
{
  std::vector<std::int64_t> mine; // (fault, node, value's bits)
  for (const auto& [key, value] : nodal)
    mine.insert(mine.end(), {_fault_index.at(key.first), key.second, std::bit_cast<std::int64_t>(value)});
  const std::vector<std::int64_t> all = all_gather(mine, _comm).values;
  std::map<std::pair<std::int64_t, std::int64_t>, double> values;
  for (std::size_t i = 0; i < all.size(); i += 3)
    values[{all[i], all[i + 1]}] = std::bit_cast<double>(all[i + 2]);
  const std::size_t d = _keys.size() / std::max<std::int64_t>(_size, 1);
  std::vector<double> means(_size, 0.0);
  for (std::int64_t k = 0; k < _size; ++k)
  {
    int n = 0;
    for (std::size_t i = 0; i < d; ++i)
      if (const auto found = values.find({_fault[k], _keys[d * k + i]}); found != values.end())
        means[k] += found->second, ++n;
    means[k] /= std::max(n, 1);
  }
  return means;
}

void FaultAperture::add_load(std::span<const double> p_f, const BCs& bcs, la::Vector<double>& b) const
{
  PetscScalar* P;
  check_petsc(VecGetArray(_cells, &P), "the fault pressure's load: VecGetArray");
  for (std::size_t k = 0; k < _measures.size(); ++k)
    P[k] = _measures[k] * p_f[k];
  check_petsc(VecRestoreArray(_cells, &P), "the fault pressure's load: VecRestoreArray");
  la::Vector<double> load(b.map(), b.bs());
  la::petsc::Vector l = wrap(load);
  check_petsc(MatMultTranspose(_J, _cells, l.vec()), "the fault pressure's load: MatMultTranspose");
  fem::set_bc(load.mutable_array(), bcs, 0.0);
  std::span<double> B = b.mutable_array();
  const std::span<const double> L = load.array();
  const std::size_t owned = b.bs() * b.map()->size_local();
  for (std::size_t i = 0; i < owned; ++i)
    B[i] += L[i];
}

} // namespace biotcontact
