"""ParaPM's Python client: a thin layer over the service's gRPC API (proto/parapm.proto,
docs/API.md).

    from parapm import Client, pb
    with Client("127.0.0.1:50051") as client:           # token: PARAPM_TOKEN, if any
        mesh = client.upload("bunny.ply")
        job = client.submit(mesh.mesh_id, target_ratio=0.02, metric="energy")
        job = client.wait(job.job_id, progress=lambda done, total: print(done, total))
        if job.state == pb.DONE:
            client.download(job.job_id, "bunny.pm")
            client.get_level(job.job_id, "bunny-5k.ply", max_faces=5000)

`pb` is the generated module of the messages (parapm_pb2); the build writes it, with the
service stub parapm_pb2_grpc, into BUILD/python beside a copy of this package, so
PYTHONPATH=BUILD/python imports both (client/python/README.md).
"""
from parapm.client import Client, ParapmError, job_options, load_token, pb

__all__ = ["Client", "ParapmError", "job_options", "load_token", "pb"]
