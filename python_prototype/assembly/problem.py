"""The problem a run solves, made once in set-up and read by every step and
scheme (cpp/assembly/problem.h): the scene, its mesh and named boundaries,
the forms, the materials of its cells and the derived parameters. The parts
travel together; no signature lists them one by one. The constants of the
forms, a part of their own in C++, live in the forms here (Forms), as the
materials' cell values do."""
from dataclasses import dataclass, replace


@dataclass(frozen=True)
class Problem:
    """The scene, domain, forms, materials and parameters of a run: set-up
    makes them, steps and schemes hold this."""
    scene: object
    domain: object
    # Forms: the forms with their coefficients (the materials' cell values)
    # and constants.
    forms: object
    # Cell by cell (materials.py); the second pass of "multirate-two-pass"
    # holds a problem whose materials have L = 0.
    materials: object
    # Of the top-level material; gamma the largest of any cell.
    parameters: object

    def with_materials(self, other, forms):
        """The same problem with other materials, whose cell values are set
        in `forms` (Materials.without_stabilisation): in the prototype the
        forms hold the materials' coefficients, so other materials come
        with forms of their own."""
        return replace(self, materials=other, forms=forms)
