"""Uploads a mesh to a ParaPM coordinator, builds its Progressive Mesh there with a progress
line, downloads the PM and writes one level of it.

    PYTHONPATH=build/python python3 client/python/examples/submit_and_get_level.py \
        bunny.ply --faces 5000 --pm bunny.pm --level bunny-5k.ply
"""
import argparse
import sys

from parapm import Client, ParapmError, pb


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("mesh", help="mesh file (.obj .ply .off .stl, optionally .gz)")
    parser.add_argument("--server", help="coordinator host:port (default: PARAPM_SERVER, "
                        "else 127.0.0.1:50051, where `parapm up` listens)")
    parser.add_argument("--token-file", help="bearer token (default: PARAPM_TOKEN)")
    parser.add_argument("--metric", choices=["quadric", "energy"], default="quadric")
    parser.add_argument("--ratio", type=float, default=0.02, help="base mesh size, of the input faces")
    parser.add_argument("--faces", type=int, default=5000, help="faces of the level to write")
    parser.add_argument("--pm", default="out.pm", help="where to write the PM")
    parser.add_argument("--level", default="out-level.ply", help="where to write the level (.ply or .obj)")
    args = parser.parse_args()

    try:
        with Client(args.server, token_file=args.token_file) as client:
            mesh = client.upload(args.mesh)
            print(f"uploaded {args.mesh}: mesh {mesh.mesh_id}, {mesh.faces} faces")
            job = client.submit(mesh.mesh_id, metric=args.metric, target_ratio=args.ratio)

            def progress(done: int, total: int) -> None:
                print(f"\r{job.job_id}: {done}/{total} collapses", end="", file=sys.stderr, flush=True)

            job = client.wait(job.job_id, progress)
            print(file=sys.stderr)
            if job.state != pb.DONE:
                print(f"{job.job_id}: {job.failure_reason}", file=sys.stderr)
                return 1
            size = client.download(job.job_id, args.pm)
            print(f"{job.job_id}: base mesh {job.base_faces} faces + {job.vsplits} vsplits, {size} bytes in {args.pm}")
            fmt = "obj" if args.level.endswith(".obj") else "ply"
            client.get_level(job.job_id, args.level, max_faces=args.faces, format=fmt)
            print(f"level of at most {args.faces} faces in {args.level}")
    except ParapmError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
