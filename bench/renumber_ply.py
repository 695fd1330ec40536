#!/usr/bin/env python3
"""bench/renumber_ply.py IN.ply OUT.ply [--shuffle SEED] [--rotate SEED]

The same surface under another numbering (and/or a random rotation), to measure what a
mesh's numbering alone does to the engine's speed and levels (docs/decisions/notebook-2026-11.md, "Memory
order"). IN: a triangle PLY as `parapm lod` writes it (binary little-endian, double x y z,
uchar/int vertex lists) or ASCII; OUT: ASCII PLY, doubles printed exactly (repr).

  parapm lod X.pm --faces 1000000000 -o full.ply      # the input's surface, from its PM
  bench/renumber_ply.py full.ply s1.ply --shuffle 1 --rotate 1
  parapm simplify s1.ply -o s1.pm --metric energy
"""
import argparse
import math
import random
import struct


def read_ply(path):
    data = open(path, "rb").read()
    if not data.startswith(b"ply\n") or b"end_header\n" not in data:
        raise SystemExit(f"{path}: not a PLY file (write one with parapm lod)")
    end = data.index(b"end_header\n") + len(b"end_header\n")
    header = data[:end].decode().split("\n")
    counts = {l.split()[1]: int(l.split()[2]) for l in header if l.startswith("element")}
    nv, nf = counts["vertex"], counts["face"]
    if any(l.startswith("format ascii") for l in header):
        lines = data[end:].decode().split("\n")
        positions = [tuple(map(float, lines[i].split()[:3])) for i in range(nv)]
        faces = [tuple(map(int, lines[nv + i].split()[1:4])) for i in range(nf)]
        return positions, faces
    vertex_properties = header[header.index(f"element vertex {nv}") + 1:][:3]
    if "format binary_little_endian 1.0" not in header or vertex_properties != [
            "property double x", "property double y", "property double z"]:
        raise SystemExit(f"{path}: expected parapm's binary PLY (double x y z) or ASCII")
    offset = end
    positions = [struct.unpack_from("<3d", data, offset + 24 * i) for i in range(nv)]
    offset += 24 * nv
    faces = []
    for _ in range(nf):
        if data[offset] != 3:
            raise SystemExit(f"{path}: a face is not a triangle")
        faces.append(struct.unpack_from("<3i", data, offset + 1))
        offset += 13
    return positions, faces


def random_rotation(rng):
    a, b, c, d = (rng.gauss(0, 1) for _ in range(4))
    n = math.sqrt(a * a + b * b + c * c + d * d)
    a, b, c, d = a / n, b / n, c / n, d / n
    return [[a*a + b*b - c*c - d*d, 2 * (b*c - a*d), 2 * (b*d + a*c)],
            [2 * (b*c + a*d), a*a - b*b + c*c - d*d, 2 * (c*d - a*b)],
            [2 * (b*d - a*c), 2 * (c*d + a*b), a*a - b*b - c*c + d*d]]


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[2])
    parser.add_argument("input")
    parser.add_argument("output")
    parser.add_argument("--shuffle", type=int, help="random vertex and face order from SEED")
    parser.add_argument("--rotate", type=int, help="random rotation from SEED")
    args = parser.parse_args()
    positions, faces = read_ply(args.input)
    order = list(range(len(positions)))
    if args.shuffle is not None:
        rng = random.Random(args.shuffle)
        rng.shuffle(order)
        faces = list(faces)
        rng.shuffle(faces)
    new_id = [0] * len(order)
    for k, v in enumerate(order):
        new_id[v] = k
    rotation = random_rotation(random.Random(args.rotate)) if args.rotate is not None else None
    with open(args.output, "w") as out:
        out.write("ply\nformat ascii 1.0\n"
                  f"element vertex {len(positions)}\n"
                  "property double x\nproperty double y\nproperty double z\n"
                  f"element face {len(faces)}\nproperty list uchar int vertex_indices\n"
                  "end_header\n")
        for v in order:
            p = positions[v]
            if rotation:
                p = tuple(sum(rotation[i][j] * p[j] for j in range(3)) for i in range(3))
            out.write("%r %r %r\n" % tuple(p))
        for a, b, c in faces:
            out.write(f"3 {new_id[a]} {new_id[b]} {new_id[c]}\n")


if __name__ == "__main__":
    main()
