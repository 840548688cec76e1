#!/usr/bin/python3
"""A gmsh .geo (built-in kernel) of straight fractures in a rectangle, each
fracture a physical group of its own, the points where fractures cross or
touch one another shared (what the split needs to see them meet).
NETWORK.json: {"box": [x0, y0, x1, y1], "h": mesh size, "fractures":
{"name": [xa, ya, xb, yb], ...}, "comment": "..."}; the rectangle's sides are
the groups "left", "right", "bottom" and "top". A fracture reaching a side
ends on it (its end point joins the side's points). --draw writes a
NETWORK.json of random fractures that a mesh of size h resolves (draw).
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


def _distance(p, a, b):
    """The distance from point p to segment a-b."""
    s = min(max(np.dot(p - a, b - a) / np.dot(b - a, b - a), 0.0), 1.0)
    return np.linalg.norm(p - a - s * (b - a))


def _crossings(segment, others):
    """The points where `segment` meets each of `others` (crossing or T)."""
    found = [(o, crossing(*segment, *o)) for o in others]
    return [(o, segment[0] + f[0] * (segment[1] - segment[0])) for o, f in found if f is not None]


def _resolved(segment, others, clearance):
    """Whether `segment` (a, b) meets each of `others` only at a crossing or
    T at an angle of at least 30 degrees, at least `clearance` from either's
    end points and from every other crossing on either, and passes the
    others it does not meet at least `clearance` away."""
    a, b = segment
    mine = _crossings(segment, others)
    met = {id(o) for o, _ in mine}
    for o in others:
        if id(o) not in met and min(_distance(a, *o), _distance(b, *o), _distance(o[0], a, b),
                                    _distance(o[1], a, b)) < clearance:
            return False
    for o, x in mine:
        r, q = b - a, o[1] - o[0]
        sine = abs(r[0] * q[1] - r[1] * q[0]) / (np.linalg.norm(r) * np.linalg.norm(q))
        ends_here = min(np.linalg.norm(x - a), np.linalg.norm(x - b))  # 0 at a T: the segment ending on o
        on_o = [y for _, y in _crossings(o, [p for p in others if p is not o])]
        if sine < 0.5 or min(np.linalg.norm(x - o[0]), np.linalg.norm(x - o[1])) < clearance \
                or 0.0 < ends_here < clearance or any(np.linalg.norm(x - y) < clearance for y in on_o):
            return False
    points = [x for _, x in mine]
    return all(np.linalg.norm(p - q) >= clearance for i, p in enumerate(points) for q in points[i + 1:])


def draw(count, seed, box, h, lengths=(80.0, 200.0)):
    """`count` fractures of two sets (strikes about 35 and 125 degrees from
    the x axis, lengths uniform in `lengths`) drawn inside `box` by a seeded
    generator, each kept only if it crosses or ends on the others where a
    mesh of size h resolves it (_resolved, clearance 2h). A fracture whose
    end falls within 2h past another is cut back onto it: a T."""
    rng = np.random.default_rng(seed)
    x0, y0, x1, y1 = box
    kept = []
    for _ in range(200 * count):
        if len(kept) == count:
            break
        angle = np.radians(rng.normal(35.0 if rng.random() < 0.5 else 125.0, 8.0))
        half = 0.5 * rng.uniform(*lengths) * np.array([np.cos(angle), np.sin(angle)])
        centre = np.array([rng.uniform(x0, x1), rng.uniform(y0, y1)])
        a, b = centre - half, centre + half
        for o in kept:  # an end just past o: ended on o
            found = crossing(a, b, *o)
            if found is not None and found[0] * np.linalg.norm(b - a) < 2 * h:
                a = a + found[0] * (b - a)
            elif found is not None and (1 - found[0]) * np.linalg.norm(b - a) < 2 * h:
                b = a + found[0] * (b - a)
        inside = all(x0 + 2 * h <= p[0] <= x1 - 2 * h and y0 + 2 * h <= p[1] <= y1 - 2 * h for p in (a, b))
        if inside and np.linalg.norm(b - a) >= lengths[0] / 2 and _resolved((a, b), kept, 2 * h):
            kept.append((a, b))
    if len(kept) < count:
        raise SystemExit(f"network_geo.py: --draw {count}: only {len(kept)} fractures fit in the box at h = {h}")
    fractures = {f"f{k + 1:02d}": [round(float(v), 3) for v in (*a, *b)] for k, (a, b) in enumerate(kept)}
    return {"comment": f"{count} fractures drawn by tools/network_geo.py --draw {count} --seed {seed}",
            "box": list(box), "h": h, "fractures": fractures}


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
    parser.add_argument("network", nargs="?", help="NETWORK.json to write a .geo of")
    parser.add_argument("--out", required=True)
    parser.add_argument("--draw", type=int, metavar="COUNT", help="draw COUNT fractures into --out (a .json)")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--box", default="0,0,1000,500", help="x0,y0,x1,y1 of the rectangle (m)")
    parser.add_argument("--h", type=float, default=10.0, help="the mesh size the fractures must be resolved at")
    args = parser.parse_args()
    if args.draw:
        network = draw(args.draw, args.seed, [float(v) for v in args.box.split(",")], args.h)
        with open(args.out, "w") as f:
            json.dump(network, f, indent=2)
        print(f"wrote {args.out}: {args.draw} fractures")
        return
    if not args.network:
        parser.error("give NETWORK.json, or --draw COUNT")
    with open(args.network) as f:
        write_geo(json.load(f), args.out)


if __name__ == "__main__":
    main()
