#!/usr/bin/env python3
"""bench/peers_table.py [RUN.tsv ...]: bench/run.sh's rows (stdin or files) as two Markdown
tables: per mesh and tool, metro's RMS (relative to the bounding-box diagonal) at each ratio;
then per mesh and tool, the seconds to the smallest ratio and their ratio to meshoptimizer's."""
import sys
from collections import OrderedDict

TOOLS = ["parapm-quadric", "parapm-energy", "meshopt", "openmesh", "cgal-gh", "cgal-lt"]


def main():
    lines = []
    for path in sys.argv[1:] or ["-"]:
        lines += (sys.stdin if path == "-" else open(path)).read().splitlines()
    rows = [l.split("\t") for l in lines if l and not l.startswith("mesh\t")]
    cells = OrderedDict()  # (mesh, tool) -> {ratio: (seconds, rms)}
    ratios = []
    for mesh, tool, ratio, _faces, seconds, _h, rms, *_ in rows:
        cells.setdefault((mesh, tool), {})[ratio] = (float(seconds), float(rms))
        if ratio not in ratios:
            ratios.append(ratio)
    ratios.sort(key=lambda r: -float(r))
    meshes = list(OrderedDict.fromkeys(m for m, _ in cells))
    print("| mesh | tool | " + " | ".join(f"RMS at {float(r):.0%}" for r in ratios) + " |")
    print("|---|---|" + "---:|" * len(ratios))
    for mesh in meshes:
        for tool in TOOLS:
            if (mesh, tool) in cells:
                c = cells[(mesh, tool)]
                print(f"| {mesh} | {tool} | " +
                      " | ".join(f"{c[r][1]:.3g}" if r in c else "-" for r in ratios) + " |")
    smallest = ratios[-1]
    print()
    print(f"| mesh | tool | seconds to {float(smallest):.0%} | / meshoptimizer |")
    print("|---|---|---:|---:|")
    for mesh in meshes:
        base = cells.get((mesh, "meshopt"), {}).get(smallest)
        for tool in TOOLS:
            c = cells.get((mesh, tool), {})
            if smallest in c:
                ratio = f"{c[smallest][0] / base[0]:.1f}x" if base else "-"
                print(f"| {mesh} | {tool} | {c[smallest][0]:.3f} | {ratio} |")


if __name__ == "__main__":
    main()
