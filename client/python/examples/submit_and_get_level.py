"""Uploads a mesh to a ParaPM coordinator, builds its Progressive Mesh there with a progress
bar, downloads the PM and writes the level of at most N faces (cut by the coordinator).

    PYTHONPATH=build/python python3 client/python/examples/submit_and_get_level.py \\
        bunny.ply --faces 5000 --pm bunny.pm --level bunny-5k.ply

Exit status: 0 done; 1 the job failed or was cancelled; 2 a call failed (the message says
which, with its gRPC status code).
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

BAR_WIDTH = 30


def parse_args(argv: list[str]) -> argparse.Namespace:
    """The command line; --help works without the generated modules."""
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("mesh", help="mesh file (.obj .ply .off .stl, optionally .gz)")
    parser.add_argument("--server", help="coordinator host:port (default: PARAPM_SERVER, "
                        "else 127.0.0.1:50051, where `parapm up` listens)")
    parser.add_argument("--token-file", help="file holding the bearer token (default: "
                        "PARAPM_TOKEN; none for a loopback coordinator without one)")
    parser.add_argument("--tls", action="store_true", help="connect over TLS")
    parser.add_argument("--tls-ca", help="PEM roots that sign the server's certificate "
                        "(implies --tls; default: the system's)")
    parser.add_argument("--metric", choices=["quadric", "energy"], default="quadric")
    parser.add_argument("--ratio", type=float, default=0.02,
                        help="base mesh size, as a fraction of the input's faces (default 0.02)")
    parser.add_argument("--parallelism", type=int,
                        help="subsets p (default: the coordinator's)")
    parser.add_argument("--faces", type=int, default=5000,
                        help="faces of the level to write, at most (default 5000)")
    parser.add_argument("--pm", help="where to write the PM (default: MESH's name .pm)")
    parser.add_argument("--level", help="where to write the level, .ply or .obj "
                        "(default: MESH's name -FACES.ply)")
    return parser.parse_args(argv)


def progress_bar(label: str, done: int, total: int) -> str:
    """One line: LABEL [#####.....]  NN% done/total."""
    fraction = min(done / total, 1.0) if total else 0.0
    filled = int(round(fraction * BAR_WIDTH))
    bar = "#" * filled + "." * (BAR_WIDTH - filled)
    return f"{label} [{bar}] {100 * fraction:3.0f}% {done}/{total} faces removed"


def run(args: argparse.Namespace) -> int:
    """Upload, submit, wait, download, level; the exit status."""
    from parapm import Client, pb  # the build's generated modules: PYTHONPATH=BUILD/python

    mesh_path = Path(args.mesh)
    pm_path = Path(args.pm or mesh_path.name.split(".")[0] + ".pm")
    level_path = Path(args.level or f"{mesh_path.name.split('.')[0]}-{args.faces}.ply")
    with Client(args.server, token_file=args.token_file, tls=args.tls,
                tls_ca=args.tls_ca) as client:
        mesh = client.upload(mesh_path)
        print(f"uploaded {mesh_path}: mesh {mesh.mesh_id}, {mesh.vertices} vertices, "
              f"{mesh.faces} faces{'; ' + mesh.repairs if mesh.repairs else ''}")
        job = client.submit(mesh.mesh_id, metric=args.metric, target_ratio=args.ratio,
                            parallelism=args.parallelism)

        def show(done: int, total: int) -> None:
            print("\r" + progress_bar(job.job_id, done, total), end="", file=sys.stderr,
                  flush=True)

        job = client.wait(job.job_id, show)
        print(file=sys.stderr)
        if job.state != pb.DONE:
            print(f"{job.job_id}: {pb.JobState.Name(job.state).lower()}"
                  f"{': ' + job.failure_reason if job.failure_reason else ''}", file=sys.stderr)
            return 1
        size = client.download(job.job_id, pm_path)
        print(f"{job.job_id}: base mesh {job.base_faces} faces + {job.vsplits} vsplits in "
              f"{job.seconds:.2f} s; {pm_path} ({size} bytes)")
        client.get_level(job.job_id, level_path, max_faces=args.faces)
        print(f"{level_path}: the level of at most {args.faces} faces")
    return 0


def main(argv: list[str]) -> int:
    args = parse_args(argv)
    try:
        from parapm import ParapmError
    except ImportError as e:  # the package or its generated modules are not on PYTHONPATH
        print(f"error: {e} (PYTHONPATH=BUILD/python: client/python/README.md)", file=sys.stderr)
        return 2
    try:
        return run(args)
    except (ParapmError, OSError, ValueError) as e:
        print(f"error: {e}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
