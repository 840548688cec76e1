"""Where the contact acts: the constraints of a scene's contact boundaries
against their foundations (foundation_pair.py) and of its faults' node
pairs (fault_pair.py), gathered into one ContactSet (contact_set.py).
Twin: cpp/contact/locate_contact.h."""
import numpy as np

from ..assembly.forms import Forms
from ..scene.scene import agree_on_error
from .contact_set import ContactSet
from .fault_pair import add_fault_pairs
from .foundation_pair import add_foundation_pairs


def locate_contact(scene, domain, F, V):
    """The ContactSet of the scene: its contact boundaries against their
    foundations (foundation_pair.py), then the faults' node pairs
    (fault_pair.py). Raises SceneError, the same on every rank, for the
    first bad input they find (collective)."""
    c = ContactSet(domain.dim, V.sub(0).collapse()[0], V.dofmap.index_map_bs * V.dofmap.index_map.local_range[0])
    error = []  # the first bad input on this rank
    add_foundation_pairs(scene, domain, F, V, c, error)
    add_fault_pairs(scene, domain, F, V, c, error)
    agree_on_error(error[0] if error else "", domain.mesh.comm)
    c.dofs, c.sign = np.array(c.dofs, dtype=np.int32), np.array(c.sign, dtype=np.int32)
    c.gap, c.lumped, c.normal = np.array(c.gap), np.array(c.lumped), np.array(c.normal)
    c.output_dofs = np.array(c.output_dofs, dtype=np.int32)
    c.boundary = np.array(c.boundary, dtype=np.int32)
    c.pair_node = np.array(c.pair_node, dtype=np.int64)
    c.junction_nodes = np.array(c.junction_nodes, dtype=np.int64).reshape(-1, 2)
    c.all_junction_nodes = np.array(c.all_junction_nodes, dtype=np.int64)
    c.frictional = np.array(c.frictional, dtype=bool)
    return c


def check_contact(scene, domain):
    """`check`'s look at the contact: the pairs made as a run makes them (a
    fault's gap and normal, where it meets a foundation) in the scene's
    displacement space; raises SceneError as locate_contact (collective)."""
    F = Forms(domain.mesh)
    locate_contact(scene, domain, F, F["V"])
