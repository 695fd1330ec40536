#!/usr/bin/env python3
"""The table of bench/fidelity.sh, from its rows (TSV files: mesh, ratio, tool, faces, rms_rel,
hausdorff_rel; tool "lt" is CGAL Lindstrom-Turk, the others ParaPM's metrics).

Prints, as TSV: one row per mesh and ratio (LT's faces and errors, then per metric its faces,
errors and their ratios to LT's, each error floored at 1e-5 (RMS) and 1e-4 (Hausdorff) of the
diagonal: below those no one can see it, and an exact LT would make any ratio infinite); the
geometric mean of those ratios per ratio and metric; and the cells over issue 33's targets,
worst last. A cell is over its target when its RMS is above 1.5x
LT's and above 1e-5 of the diagonal, or its Hausdorff above 2x LT's and above 1e-4."""
import math
import sys

RMS_LIMIT, RMS_FLOOR = 1.5, 1e-5
HAUSDORFF_LIMIT, HAUSDORFF_FLOOR = 2.0, 1e-4


def times(value, reference):
    """value / reference as text ("2.14x"; "LT exact" when the reference is 0)."""
    return f"{value / reference:.2f}x" if reference > 0 else "LT exact, not"


def floored_ratio(value, reference, floor):
    """value / reference, each floored: below the floor no one can see an error."""
    return max(value, floor) / max(reference, floor)


def read_rows(paths):
    cells = {}  # (mesh, ratio) -> tool -> (faces, rms, hausdorff)
    missing = []
    for path in paths:
        try:
            with open(path) as f:
                for line in f:
                    mesh, ratio, tool, faces, rms, hausdorff = line.rstrip("\n").split("\t")
                    cells.setdefault((mesh, ratio), {})[tool] = (
                        int(faces), float(rms), float(hausdorff))
        except FileNotFoundError:
            missing.append(path)
    return cells, missing


def main(paths):
    cells, missing = read_rows(paths)
    metrics = sorted({t for tools in cells.values() for t in tools if t != "lt"},
                     key=lambda t: (t != "quadric", t))
    ratios = sorted({r for _, r in cells}, key=lambda r: -float(r))
    header = ["mesh", "ratio", "lt_faces", "lt_rms", "lt_hausdorff"]
    for m in metrics:
        header += [f"{m}_faces", f"{m}_rms", f"{m}_hausdorff", f"{m}_rms/lt", f"{m}_hausdorff/lt"]
    print("\t".join(header))
    logs = {}  # (ratio, metric) -> ([log rms ratio], [log hausdorff ratio])
    over = []  # (severity, text)
    for (mesh, ratio), tools in sorted(cells.items(), key=lambda kv: (kv[0][0], -float(kv[0][1]))):
        if "lt" not in tools:
            continue
        lt_faces, lt_rms, lt_h = tools["lt"]
        row = [mesh, ratio, str(lt_faces), f"{lt_rms:.3g}", f"{lt_h:.3g}"]
        for m in metrics:
            if m not in tools:
                row += ["-"] * 5
                continue
            faces, rms, h = tools[m]
            rr = floored_ratio(rms, lt_rms, RMS_FLOOR)
            hr = floored_ratio(h, lt_h, HAUSDORFF_FLOOR)
            row += [str(faces), f"{rms:.3g}", f"{h:.3g}", f"{rr:.3f}", f"{hr:.3f}"]
            lr, lh = logs.setdefault((ratio, m), ([], []))
            lr.append(math.log(rr))
            lh.append(math.log(hr))
            # Over when above both the multiple of LT's error and the floor; how far over is
            # the error against the larger of the two (what the target allows).
            rms_allowed = max(RMS_LIMIT * lt_rms, RMS_FLOOR)
            h_allowed = max(HAUSDORFF_LIMIT * lt_h, HAUSDORFF_FLOOR)
            if rms > rms_allowed or h > h_allowed:
                severity = max(rms / rms_allowed, h / h_allowed)
                over.append((severity, f"{mesh}\t{ratio}\t{m}\tfaces {faces} (LT {lt_faces})"
                                       f"\tRMS {rms:.3g} ({times(rms, lt_rms)} LT's)"
                                       f"\tHausdorff {h:.3g} ({times(h, lt_h)} LT's)"
                                       f"\t{severity:.2f}x the target"))
        print("\t".join(row))
    print()
    print("geometric mean over the meshes (RMS / LT, Hausdorff / LT; errors floored at"
          f" {RMS_FLOOR:g} and {HAUSDORFF_FLOOR:g})")
    print("ratio\tmetric\tmeshes\trms/lt\thausdorff/lt")
    for r in ratios:
        for m in metrics:
            lr, lh = logs.get((r, m), ([], []))
            if lr:
                print(f"{r}\t{m}\t{len(lr)}\t{math.exp(sum(lr) / len(lr)):.3f}"
                      f"\t{math.exp(sum(lh) / len(lh)):.3f}")
    print()
    print(f"cells over the targets (RMS > {RMS_LIMIT}x LT and > {RMS_FLOOR:g}, or Hausdorff >"
          f" {HAUSDORFF_LIMIT}x LT and > {HAUSDORFF_FLOOR:g}; the last column: the larger error"
          f" over what the target allows): {len(over)}, worst last")
    for _, text in sorted(over):
        print(text)
    for path in missing:
        print(f"missing (its run failed): {path}", file=sys.stderr)
    return 1 if missing else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
