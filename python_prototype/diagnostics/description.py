"""What a run says of its scene before it starts: what the scene leaves
out, its mesh and regions, and warnings where the method is known to
degrade, instead of returning poor numbers silently (docs/stability.md);
cpp/diagnostics/description.h."""
from dataclasses import dataclass, field

from ..assembly.materials import gamma_warning


@dataclass
class Description:
    """The description of a run: "; "-joined lists for summary.json and the
    lines printed at the start (warnings among them, prefixed)."""
    left_out: str = ""
    warnings: str = ""
    lines: list = field(default_factory=list)


def _left_out(scene):
    """The physics and terms the scene leaves out."""
    found = []
    if not scene.flow:
        found.append("flow (no [flow] table): no flux or pressure unknowns")
    if not scene.mechanics:
        found.append("mechanics (no [mechanics] table): no displacement unknowns")
    if scene.mechanics and not scene.has_contact():
        found.append("contact solver (no contact boundary): linear mechanics solve")
    if scene.flow and not scene.flow.gravity:
        found.append("gravity")
    if scene.mechanics and not scene.mechanics.body_force and not scene.cellwise_body_force():
        found.append("body force")
    return "; ".join(found)


def _warnings(problem):
    """Near-incompressible materials (P1 locks) and a gamma near 1 (the split
    contracts slowly or not at all)."""
    scene, regions, materials = problem.scene, problem.domain.regions, problem.materials
    found = []
    for r, m in enumerate(materials.regions + [materials.top] if scene.mechanics else []):
        nu = m.lmbda / (2 * (m.lmbda + m.G))
        if nu > 0.49 and (r < len(regions.names) or regions.outside > 0):
            found.append((f"region {regions.names[r]}: " if r < len(regions.names) else "")
                         + f"nu = {nu:f} > 0.49: P1 displacements lock as nu -> 0.5 "
                         "(too stiff a response, worse on coarse meshes)")
    if warning := gamma_warning(scene, materials.gamma_peak()):
        found.append(warning)
    return found


def describe(problem):
    """The Description of a run of problem.scene on problem.domain."""
    scene, domain = problem.scene, problem.domain
    d = Description(_left_out(scene))
    dim = domain.dim
    d.lines.append(f"biotcontact (python prototype): scene {scene.name} ({scene.file}), {dim}D, "
                   f"{domain.mesh.topology.index_map(dim).size_global} cells")
    d.lines.append("left out: " + (d.left_out or "nothing"))
    regions = domain.regions
    for name, count, m in zip(regions.names, regions.counts, problem.materials.regions):
        d.lines.append(f"region {name}: {count} cells" + (f", gamma = {m.gamma:f}" if scene.coupling else ""))
    warnings = _warnings(problem)
    d.warnings = "; ".join(warnings)
    d.lines += ["warning: " + w for w in warnings]
    return d
