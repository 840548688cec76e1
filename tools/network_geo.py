#!/usr/bin/python3
"""A gmsh .geo (built-in kernel) of straight fractures in a rectangle, each
fracture a physical group of its own, the points where fractures cross or
touch one another shared (what the split needs to see them meet):

    /usr/bin/python3 tools/network_geo.py NETWORK.json --out meshes/NAME.geo

NETWORK.json: {"box": [x0, y0, x1, y1], "h": mesh size, "fractures":
{"name": [xa, ya, xb, yb], ...}, "comment": "..."}; the rectangle's sides are
the groups "left", "right", "bottom" and "top". A fracture reaching a side
ends on it (its end point joins the side's points).
"""
import argparse
import json

import numpy as np

TOLERANCE = 1e-9  # of the rectangle's size: points closer than this are one


def crossing(a, b, c, d):
    """The parameters (s, t) in [0, 1]^2 where segments a-b and c-d meet,
    or None (parallel segments do not meet here)."""
    r, q = b - a, d - c
    denominator = r[0] * q[1] - r[1] * q[0]
    if abs(denominator) < 1e-14:
        return None
    s = ((c - a)[0] * q[1] - (c - a)[1] * q[0]) / denominator
    t = ((c - a)[0] * r[1] - (c - a)[1] * r[0]) / denominator
    eps = 1e-12
    return (s, t) if -eps <= s <= 1 + eps and -eps <= t <= 1 + eps else None


def split_points(box, fractures):
    """Per fracture the parameters of its end points and of every point
    where it meets another fracture or a side, sorted."""
    x0, y0, x1, y1 = box
    sides = [np.array(p) for p in ((x0, y0), (x1, y0), (x1, y1), (x0, y1))]
    cuts = {name: {0.0, 1.0} for name in fractures}
    segments = {name: (np.array(f[:2]), np.array(f[2:])) for name, f in fractures.items()}
    names = list(fractures)
    for i, m in enumerate(names):
        for n in names[i + 1:]:
            found = crossing(*segments[m], *segments[n])
            if found:
                cuts[m].add(min(max(found[0], 0.0), 1.0))
                cuts[n].add(min(max(found[1], 0.0), 1.0))
    return {name: sorted(cuts[name]) for name in names}, sides, segments


def write_geo(network, out):
    box, h = network["box"], network["h"]
    cuts, sides, segments = split_points(box, network["fractures"])
    size = max(box[2] - box[0], box[3] - box[1])
    points = []  # coordinates, shared within TOLERANCE * size

    def point(x):
        for k, p in enumerate(points):
            if np.linalg.norm(p - x) <= TOLERANCE * size:
                return k + 1
        points.append(x)
        return len(points)
    corners = [point(c) for c in sides]
    chains = {name: [point(segments[name][0] + s * (segments[name][1] - segments[name][0])) for s in cuts[name]]
              for name in cuts}
    lines, groups = [], {}
    # the sides, through the fractures' end points on them
    for k, side in enumerate(("bottom", "right", "top", "left")):
        a, b = sides[k], sides[(k + 1) % 4]
        on = [(float(np.dot(points[p - 1] - a, b - a) / np.dot(b - a, b - a)), p) for p in range(1, len(points) + 1)
              if p not in (corners[k], corners[(k + 1) % 4])
              and abs(np.cross(b - a, points[p - 1] - a)) <= TOLERANCE * size * np.linalg.norm(b - a)]
        chain = [corners[k]] + [p for _, p in sorted(on)] + [corners[(k + 1) % 4]]
        groups[side] = [len(lines) + i + 1 for i in range(len(chain) - 1)]
        lines += list(zip(chain, chain[1:]))
    boundary = len(lines)
    for name, chain in chains.items():
        groups[name] = [len(lines) + i + 1 for i in range(len(chain) - 1)]
        lines += list(zip(chain, chain[1:]))
    with open(out, "w") as f:
        for line in network.get("comment", "").splitlines():
            f.write(f"// {line}\n")
        f.write(f"// Written by tools/network_geo.py.\nSetFactory(\"Built-in\");\nh = {h};\n")
        for k, p in enumerate(points):
            f.write(f"Point({k + 1}) = {{{p[0]!r}, {p[1]!r}, 0, h}};\n")
        for k, (a, b) in enumerate(lines):
            f.write(f"Line({k + 1}) = {{{a}, {b}}};\n")
        f.write(f"Curve Loop(1) = {{1:{boundary}}}; Plane Surface(1) = {{1}};\n")
        f.write(f"Line{{{boundary + 1}:{len(lines)}}} In Surface{{1}};\n")
        for name, ids in groups.items():
            f.write(f'Physical Curve("{name}") = {{{", ".join(map(str, ids))}}};\n')
        f.write('Physical Surface("rock") = {1};\n')
    print(f"wrote {out}: {len(network['fractures'])} fractures, {len(points)} points, {len(lines)} lines")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("network")
    parser.add_argument("--out", required=True)
    args = parser.parse_args()
    with open(args.network) as f:
        write_geo(json.load(f), args.out)


if __name__ == "__main__":
    main()
