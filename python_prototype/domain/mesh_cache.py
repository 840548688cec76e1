"""The mesh cache (BIOTCONTACT_MESH_CACHE=DIR), as cpp/domain/mesh_cache.h:
a .geo meshed once is kept in DIR as a binary MSH 4.1 file named by a hash
of all that gmsh's mesh depends on (the .geo's text, mesh.dimension,
mesh.size_factor, mesh.refine, the faults' tip grading, gmsh's version),
the same key and file as the C++ solver's; a binary MSH file gives back
the nodes, cells and groups bit for bit. The text of the files a .geo
reads is part of the key; a .geo that names a file gmsh computes is not
kept."""
import os
import re

from ..scene.scene import SceneError

VARIABLE = "BIOTCONTACT_MESH_CACHE"


def _fnv1a(data):
    """FNV-1a, 64 bits, in 16 hex digits."""
    h = 14695981039346656037
    for byte in data:
        h = ((h ^ byte) * 1099511628211) & 0xFFFFFFFFFFFFFFFF
    return f"{h:016x}"


def _geo_inputs(file, visited):
    """The bytes of a .geo followed by those of each file it reads (Include,
    Merge, ShapeFromFile with a name in quotes, relative to its directory),
    depth first in the order they appear, each once; None when a file
    cannot be read or names a file otherwise (a name gmsh computes)."""
    try:
        with open(file, "rb") as f:
            text = f.read()
    except OSError:
        return None  # gmsh's open says why
    named = re.compile(rb'(?:Include|Merge)\s*"([^"]*)"|ShapeFromFile\s*\(\s*"([^"]*)"\s*\)')
    matches = list(named.finditer(text))
    if len(re.findall(rb"Include|Merge|ShapeFromFile", text)) != len(matches):
        return None
    inputs = text
    for m in matches:
        name = m.group(1) if m.group(1) is not None else m.group(2)
        path = os.path.normpath(os.path.join(os.path.dirname(file), name.decode()))
        if path in visited:
            continue
        visited.add(path)
        read = _geo_inputs(path, visited)
        if read is None:
            return None
        inputs += b"\nreads " + name + b"\n" + read
    return inputs


def mesh_cache_key(scene, geo_text, gmsh_version):
    """The key of a .geo's mesh (geo_text: the bytes of the .geo and of the
    files it reads)."""
    m = scene.mesh
    inputs = (f"biotcontact mesh cache 1\ngmsh {gmsh_version}\ndimension {m.dimension}\n"
              f"size_factor {m.size_factor:.17g}\nrefine {m.refine}\n")
    for name in sorted(scene.faults):  # by name, as the C++ map holds them
        fault = scene.faults[name]
        if fault.tip_size > 0:
            inputs += f"tip {name} {fault.tip_size:.17g} {fault.tip_grading:.17g}\n"
    return _fnv1a(inputs.encode() + b"geo\n" + geo_text)


def mesh_cache_file(gmsh, scene):
    """The cache's file for the scene's mesh; None when the variable is
    unset or empty, the mesh is no .geo or a file it reads is not known.
    Makes the directory; SceneError naming the variable when it cannot."""
    directory = os.environ.get(VARIABLE, "")
    if not directory or os.path.splitext(scene.mesh.file)[1] != ".geo":
        return None
    text = _geo_inputs(scene.mesh.file, {os.path.normpath(scene.mesh.file)})
    if text is None:
        return None
    try:
        os.makedirs(directory, exist_ok=True)
    except OSError as e:
        raise SceneError(f"{VARIABLE}={directory}: cannot make the directory: {e.strerror}") from None
    key = mesh_cache_key(scene, text, gmsh.option.getString("General.Version"))
    return os.path.join(directory, key + ".msh")


def store_mesh(gmsh, file):
    """Writes gmsh's mesh to `file` (binary MSH 4.1, every element) through
    a temporary file renamed into place."""
    part = f"{os.path.splitext(file)[0]}.part{os.getpid()}.msh"  # gmsh knows a format by its extension
    gmsh.option.setNumber("Mesh.Binary", 1)
    gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
    gmsh.option.setNumber("Mesh.SaveAll", 1)  # cells outside the physical groups too
    try:
        gmsh.write(part)
    except Exception as e:
        if os.path.exists(part):
            os.remove(part)
        raise SceneError(f"{VARIABLE}: cannot write {part}: {e}") from None
    try:
        os.replace(part, file)
    except OSError as e:
        raise SceneError(f"{VARIABLE}: cannot write {file}: {e.strerror}") from None
