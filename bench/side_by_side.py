#!/usr/bin/env python3
"""bench/side_by_side.py MESH... : the parallel build's critical path, and its subsets run one at
a time against side by side (issue 37: the jobs' slowdown beside each other must appear in the
model, not vanish).

For every MESH, metric of METRICS (default "energy quadric") and p of PS (default "4 16"),
REPEATS (default 3) times: `parapm simplify MESH --ratio RATIO --parallel p --json` with
`--threads 1` (each subset alone on the machine) and `--threads THREADS` (default 2: that many
side by side), and once sequentially. One TSV row per mesh, metric and p (medians): the
subsets' CPU seconds summed, alone and side by side, and their ratio (the slowdown of a job
beside others); the slowest subset of each round summed, alone; the critical path (a core per
subset, the jobs alone); its serial part (the critical path less the slowest subsets: set-up,
partitions, extraction, merges, band passes, final pass, PM assembly); the seconds outside the
build (read, repair, write; a parallel run reads and repairs in p chunks, counted with a core
per chunk); the sequential process's seconds; and the speed-up a core per
subset gives with the subsets slowed by 1, 1.23 and 1.46 (the slowdown issue 37 measured
beside 15 others on a 16-core machine): sequential process / (serial part + outside + the
slowest subsets x slowdown).

Environment: METRICS, PS, RATIO (default 0.02), REPEATS, THREADS, PARAPM_BUILD_DIR (default
build/).
"""
import json
import os
import statistics
import subprocess
import sys
import tempfile


def simplify(binary, mesh, metric, ratio, extra):
    with tempfile.TemporaryDirectory() as folder:
        out = subprocess.run(
            [binary, "simplify", mesh, "-o", os.path.join(folder, "x.pm"), "--metric", metric,
             "--ratio", ratio, "--json"] + extra,
            capture_output=True, text=True, check=True).stdout
    return json.loads(out)


def outside(run):
    """Read, repair (with a core per chunk where the run read and repaired in chunks) and write."""
    return (run.get("read_critical_seconds", run["read_seconds"]) +
            run.get("repair_critical_seconds", run["repair_seconds"]) +
            run.get("write_critical_seconds", run["write_seconds"]))


def parallel_figures(run):
    par = run["parallel"]
    rounds = par["round_stats"]
    return {
        "subsets_cpu": sum(s["cpu_seconds"] for r in rounds for s in r["subsets"]),
        "slowest": sum(r["slowest_subset_cpu_seconds"] for r in rounds),
        "critical": par["critical_path_seconds"],
        "outside": outside(run),
    }


def main():
    meshes = sys.argv[1:]
    if not meshes:
        print(f"usage: {sys.argv[0]} MESH...", file=sys.stderr)
        return 2
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    binary = os.path.join(os.environ.get("PARAPM_BUILD_DIR", os.path.join(root, "build")),
                          "bin", "parapm")
    metrics = os.environ.get("METRICS", "energy quadric").split()
    ps = os.environ.get("PS", "4 16").split()
    ratio = os.environ.get("RATIO", "0.02")
    repeats = int(os.environ.get("REPEATS", "3"))
    threads = os.environ.get("THREADS", "2")
    slowdowns = (1.0, 1.23, 1.46)
    print("\t".join(["mesh", "metric", "p", "subsets_cpu_alone_s", "subsets_cpu_side_by_side_s",
                     "slowdown", "slowest_alone_s", "critical_path_s", "serial_s", "outside_s",
                     "sequential_process_s"] + [f"speedup_at_{s}" for s in slowdowns]))
    for mesh in meshes:
        for metric in metrics:
            runs = [simplify(binary, mesh, metric, ratio, []) for _ in range(repeats)]
            process = statistics.median(r["seconds"] + outside(r) for r in runs)
            for p in ps:
                alone, beside = [], []
                for _ in range(repeats):
                    alone.append(parallel_figures(simplify(
                        binary, mesh, metric, ratio, ["--parallel", p, "--threads", "1"])))
                    beside.append(parallel_figures(simplify(
                        binary, mesh, metric, ratio, ["--parallel", p, "--threads", threads])))
                med = lambda runs, key: statistics.median(r[key] for r in runs)
                slowest = med(alone, "slowest")
                serial = med(alone, "critical") - slowest
                out = med(alone, "outside")
                row = [os.path.basename(mesh), metric, p,
                       f"{med(alone, 'subsets_cpu'):.3f}", f"{med(beside, 'subsets_cpu'):.3f}",
                       f"{med(beside, 'subsets_cpu') / med(alone, 'subsets_cpu'):.3f}",
                       f"{slowest:.3f}", f"{med(alone, 'critical'):.3f}", f"{serial:.3f}",
                       f"{out:.3f}", f"{process:.3f}"]
                row += [f"{process / (serial + out + s * slowest):.2f}" for s in slowdowns]
                print("\t".join(row), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
