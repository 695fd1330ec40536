"""ParaPM's Python client: a thin layer over the service's gRPC API (proto/parapm.proto).

    from parapm import Client
    client = Client("127.0.0.1:50051")                    # token: PARAPM_TOKEN, if any
    mesh = client.upload("bunny.ply")
    job = client.submit(mesh.mesh_id, target_ratio=0.02, metric="energy")
    job = client.wait(job.job_id, progress=lambda done, total: print(done, total))
    client.download(job.job_id, "bunny.pm")
    client.get_level(job.job_id, "bunny-5k.ply", max_faces=5000)

The generated modules (parapm_pb2, parapm_pb2_grpc) come from the build (see README.md here).
"""
from parapm.client import Client, ParapmError, pb

__all__ = ["Client", "ParapmError", "pb"]
