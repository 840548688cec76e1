"""The fields of a mixed system and how a PETSc field split learns them
(cpp/solvers/field_split.h): index sets, the block size and near-nullspace AMG needs
of a field's block, and splits nested inside a split."""
from dataclasses import dataclass, field as dataclass_field

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

from .options import OptionsError, system_name


@dataclass
class Field:
    name: str
    dofs: np.ndarray  # global indices of the owned DOFs, ascending
    block_size: int = 1  # DOFs per node when they come node by node
    near_nullspace: object = None  # of the field's block, in its own numbering
    fields: list = dataclass_field(default_factory=list)  # splits, numbered within the block


def is_coupled(fields):
    """The fields of the coupled system: some are split further."""
    return any(f.fields for f in fields)


def block_offset(whole, comm):
    """The first row of this rank in the block of `whole`, which numbers its
    rows rank by rank: the number of DOFs of `whole` on the ranks before it
    (collective)."""
    return comm.exscan(len(whole.dofs), op=MPI.SUM) or 0


def part_of(whole, name, dofs, comm):
    """The field `name` made of `dofs` (a subset of whole's), numbered
    within the block of `whole`: its rows are whole's DOFs in order, rank by
    rank (collective)."""
    offset = block_offset(whole, comm)
    position = np.searchsorted(whole.dofs, dofs)
    if np.any(position >= len(whole.dofs)) or np.any(whole.dofs[np.minimum(position, len(whole.dofs) - 1)] != dofs):
        raise RuntimeError(f"field {name} is not a part of field {whole.name}")
    return Field(name, (offset + position).astype(PETSc.IntType))


def set_fields(pc, fields, prefix):
    """If `pc` is a field split without fields yet, gives it `fields` and,
    for a field with its own splits, sets its sub-solver from the options
    and gives it those too (cpp/solvers/field_split.cpp)."""
    if pc.getType() != PETSc.PC.Type.FIELDSPLIT:
        return
    if not fields:
        raise OptionsError(f"-{prefix}pc_type fieldsplit: {system_name(prefix)} system has no fields to split")
    comm = pc.getComm()
    splits = []
    for f in fields:
        index_set = PETSc.IS().createGeneral(np.asarray(f.dofs, dtype=PETSc.IntType), comm=comm)
        index_set.setBlockSize(f.block_size)
        if f.near_nullspace is not None:
            index_set.compose("nearnullspace", f.near_nullspace)
        splits.append((f.name, index_set))
    pc.setFieldSplitIS(*splits)
    if not is_coupled(fields):
        return
    for f, sub in zip(fields, pc.getFieldSplitSubKSP()):
        if f.fields:
            sub.setFromOptions()
            set_fields(sub.getPC(), f.fields, sub.getOptionsPrefix())
