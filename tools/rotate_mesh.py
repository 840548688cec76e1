#!/usr/bin/python3
"""A scene built in a rotated frame: its gmsh mesh with every node rotated,
and its scene file with its vectors (tractions, foundation normals)
rotated. A check of rotation invariance (tests/test_rotation_invariance.py)
and of what an inclined foundation costs (bench/inclined.py): it
meshes the geometry with gmsh (msh 2.2, `--clscale` scales its element
sizes), and writes the mesh with its nodes rotated by `--angle` degrees
(about z in 2D, about `--axis` in 3D).
"""
import argparse
import re
import subprocess

import numpy as np


def rotation(angle, d, axis=(0.0, 0.0, 1.0)):
    """The d x d rotation by `angle` degrees (about `axis` in 3D: Rodrigues)."""
    a = np.radians(angle)
    if d == 2:
        return np.array([[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]])
    k = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    K = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + np.sin(a) * K + (1 - np.cos(a)) * K @ K


def mesh(geo, d, out, clscale=1.0, algorithm=None):
    """Meshes a gmsh geometry into `out` (msh 2.2), with gmsh's `-algo
    algorithm` if given ("hxt": gmsh 4.8's parallel tetrahedra)."""
    subprocess.run(["gmsh", f"-{d}", geo, "-format", "msh22", "-clscale", str(clscale), "-o", out]
                   + (["-algo", algorithm] if algorithm else []), check=True, capture_output=True)


def rotate_msh(source, out, R):
    """Writes the msh 2.2 file `source` to `out` with its nodes rotated by R."""
    d = len(R)
    with open(source) as f:
        lines = f.read().splitlines()
    first = lines.index("$Nodes") + 2
    for k in range(first, first + int(lines[first - 1])):
        i, *x = lines[k].split()
        x = np.array([float(v) for v in x])
        x[:d] = R @ x[:d]
        lines[k] = " ".join([i] + [repr(float(v)) for v in x])
    with open(out, "w") as f:
        f.write("\n".join(lines) + "\n")


def on_mesh(text, mesh_file, d=2):
    """A scene's text with its [mesh] table replaced by a gmsh mesh file."""
    return re.sub(r"\[mesh\]\n(.*\n)*?(?=\n\[)", f'[mesh]\ntype = "gmsh"\nfile = "{mesh_file}"\ndimension = {d}\n',
                  text)


def vector(v):
    return "[" + ", ".join(repr(float(c)) for c in v) + "]"


def rotate_scene(text, R, keys=("traction", "normal")):
    """A scene's text with the constant vectors of `keys` rotated by R."""
    for key in keys:
        for match in re.finditer(key + r" = (\[[^]\"']*\])", text):
            turned = R @ np.array([float(v) for v in match.group(1).strip("[]").split(",")])
            text = text.replace(match.group(0), f"{key} = {vector(turned)}")
    return text


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("geometry")
    parser.add_argument("out")
    parser.add_argument("--angle", type=float, required=True, help="degrees")
    parser.add_argument("--axis", default="0,0,1", help="3D: the axis, e.g. 1,1,1")
    parser.add_argument("--dimension", type=int, default=2)
    parser.add_argument("--clscale", type=float, default=1.0)
    args = parser.parse_args()
    base = args.out + ".base.msh"
    mesh(args.geometry, args.dimension, base, args.clscale)
    rotate_msh(base, args.out, rotation(args.angle, args.dimension, [float(v) for v in args.axis.split(",")]))
    print(f"wrote {args.out} (and the unrotated {base})")


if __name__ == "__main__":
    main()
