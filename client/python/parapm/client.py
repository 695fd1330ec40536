"""Client: a connection to a ParaPM coordinator and the calls that take more than one step.

Every RPC of MeshService is reachable through Client.stub (the generated stub); the methods
here add the token, chunking, resuming and errors a program needs. Failed calls raise
ParapmError with the gRPC status code and the server's message.
"""
from __future__ import annotations

import os
import time
from pathlib import Path
from typing import Callable, Iterator, Optional

import grpc

import parapm_pb2 as pb
import parapm_pb2_grpc as pb_grpc

DEFAULT_SERVER = "127.0.0.1:50051"  # where `parapm up` listens
UPLOAD_CHUNK_BYTES = 1 << 20  # the server takes chunks of at most 4 MiB
# The largest message either side accepts (proto/rpc_security.h: kMaxMessageBytes).
MAX_MESSAGE_BYTES = 1 << 30
# Codes after which a watch resumes from the last event seen.
RESUMABLE = {grpc.StatusCode.UNAVAILABLE, grpc.StatusCode.DEADLINE_EXCEEDED,
             grpc.StatusCode.RESOURCE_EXHAUSTED}
METRICS = {"quadric": pb.METRIC_QUADRIC, "energy": pb.METRIC_ENERGY}


class ParapmError(Exception):
    """A failed call: `code` is the grpc.StatusCode, `details` the server's message."""

    def __init__(self, what: str, code: grpc.StatusCode, details: str):
        super().__init__(f"{what}: {code.name}: {details}")
        self.code = code
        self.details = details


def _load_token(token: Optional[str], token_file: Optional[str]) -> str:
    """The token: given, else read from token_file, else PARAPM_TOKEN, else none ("")."""
    if token is not None:
        return token
    if token_file:
        text = Path(token_file).read_text().strip()
        if not text:
            raise ValueError(f"{token_file}: the token file is empty")
        return text
    return os.environ.get("PARAPM_TOKEN", "").strip()


class Client:
    """A connection to a coordinator.

    server: host:port (default: PARAPM_SERVER, else 127.0.0.1:50051).
    token / token_file: the bearer token (default: PARAPM_TOKEN; none on a loopback
    coordinator). tls: connect over TLS, verifying the server against root_certificates
    (PEM bytes; None: the system's roots).
    """

    def __init__(self, server: Optional[str] = None, *, token: Optional[str] = None,
                 token_file: Optional[str] = None, tls: bool = False,
                 root_certificates: Optional[bytes] = None):
        self.server = server or os.environ.get("PARAPM_SERVER") or DEFAULT_SERVER
        self._token = _load_token(token, token_file)
        options = [("grpc.max_receive_message_length", MAX_MESSAGE_BYTES),
                   ("grpc.max_send_message_length", MAX_MESSAGE_BYTES)]
        if tls:
            credentials = grpc.ssl_channel_credentials(root_certificates=root_certificates)
            self._channel = grpc.secure_channel(self.server, credentials, options)
        else:
            self._channel = grpc.insecure_channel(self.server, options)
        self.stub = pb_grpc.MeshServiceStub(self._channel)

    def close(self) -> None:
        self._channel.close()

    def __enter__(self) -> "Client":
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def metadata(self) -> list[tuple[str, str]]:
        """The call metadata carrying the token (the server reads "authorization")."""
        return [("authorization", f"Bearer {self._token}")] if self._token else []

    def _call(self, what: str, method, request, timeout: Optional[float] = 60):
        try:
            return method(request, metadata=self.metadata(), timeout=timeout)
        except grpc.RpcError as e:
            raise ParapmError(what, e.code(), e.details()) from None

    # ---- meshes and jobs ----------------------------------------------------------------------

    def upload(self, path: str | os.PathLike,
               progress: Optional[Callable[[int, int], None]] = None) -> pb.UploadReply:
        """Uploads a mesh file (.obj .ply .off .stl, optionally .gz) in 1 MiB chunks;
        progress(sent, total) after each. Returns the stored mesh (its mesh_id, counts,
        and what the repair step did)."""
        path = Path(path)
        total = path.stat().st_size

        def chunks() -> Iterator[pb.UploadChunk]:
            sent = 0
            with path.open("rb") as f:
                first = True
                while True:
                    data = f.read(UPLOAD_CHUNK_BYTES)
                    if not data and not first:
                        return
                    yield pb.UploadChunk(file_name=path.name if first else "", data=data)
                    first = False
                    sent += len(data)
                    if progress:
                        progress(sent, total)
                    if not data:
                        return

        return self._call(f"upload {path}", self.stub.Upload, chunks(), timeout=None)

    def submit(self, mesh_id: str, options: Optional[pb.JobOptions] = None, *,
               metric: Optional[str] = None, target_ratio: Optional[float] = None,
               target_faces: Optional[int] = None, parallelism: Optional[int] = None,
               seed: Optional[int] = None) -> pb.Job:
        """Queues a job of an uploaded mesh: `options` as a JobOptions, or the common ones as
        keywords (metric "quadric" or "energy", target_ratio or target_faces, parallelism,
        seed); the coordinator's defaults for the rest."""
        options = pb.JobOptions() if options is None else options
        if metric is not None:
            if metric not in METRICS:
                raise ValueError(f"metric {metric!r}: quadric or energy")
            options.metric = METRICS[metric]
        if target_ratio is not None:
            options.target_ratio = target_ratio
        if target_faces is not None:
            options.target_faces = target_faces
        if parallelism is not None:
            options.parallelism = parallelism
        if seed is not None:
            options.seed = seed
        request = pb.SubmitRequest(mesh_id=mesh_id, options=options)
        return self._call(f"submit {mesh_id}", self.stub.Submit, request)

    def job(self, job_id: str) -> pb.Job:
        return self._call(f"get job {job_id}", self.stub.GetJob, pb.JobRef(job_id=job_id))

    def jobs(self, limit: int = 100) -> list[pb.Job]:
        reply = self._call("list jobs", self.stub.ListJobs, pb.ListJobsRequest(limit=limit))
        return list(reply.jobs)

    def cancel(self, job_id: str) -> pb.Job:
        return self._call(f"cancel {job_id}", self.stub.CancelJob, pb.JobRef(job_id=job_id))

    def delete_job(self, job_id: str) -> pb.DeleteReply:
        return self._call(f"delete {job_id}", self.stub.DeleteJob, pb.JobRef(job_id=job_id))

    def watch(self, job_id: str,
              on_event: Optional[Callable[[pb.JobEvent], None]] = None) -> pb.Job:
        """Follows the job's events to its end, calling on_event for each; a watch that breaks
        (the coordinator restarted, or closed a long watch) resumes after the last event seen.
        Returns the job as it ended."""
        after, attempts = 0, 0
        while True:
            try:
                for event in self.stub.Watch(pb.WatchRequest(job_id=job_id, after_seq=after),
                                             metadata=self.metadata()):
                    after, attempts = event.seq, 0
                    if on_event:
                        on_event(event)
                break
            except grpc.RpcError as e:
                if e.code() not in RESUMABLE or attempts >= 60:
                    raise ParapmError(f"watch {job_id}", e.code(), e.details()) from None
                attempts += 1
                time.sleep(1)
        return self.job(job_id)

    def wait(self, job_id: str,
             progress: Optional[Callable[[int, int], None]] = None) -> pb.Job:
        """watch() with a progress callback: progress(done, total) for each progress event
        (collapses done of the job's total)."""
        def on_event(event: pb.JobEvent) -> None:
            if progress and event.WhichOneof("event") == "progress":
                progress(event.progress.done, event.progress.total)
        return self.watch(job_id, on_event)

    # ---- results ------------------------------------------------------------------------------

    def _receive(self, what: str, chunks, out: str | os.PathLike) -> int:
        """Writes a stream of Chunk messages to `out` through a temporary file renamed at the
        end (never a partial file). Returns the bytes written."""
        out = Path(out)
        part = out.with_name(out.name + ".part")
        written = 0
        try:
            with part.open("wb") as f:
                for chunk in chunks:
                    f.write(chunk.data)
                    written += len(chunk.data)
        except grpc.RpcError as e:
            part.unlink(missing_ok=True)
            raise ParapmError(what, e.code(), e.details()) from None
        part.replace(out)
        return written

    def download(self, job_id: str, out: str | os.PathLike) -> int:
        """Writes the job's .pm to `out`; returns its size."""
        chunks = self.stub.Download(pb.JobRef(job_id=job_id), metadata=self.metadata())
        return self._receive(f"download {job_id}", chunks, out)

    def get_level(self, job_id: str, out: str | os.PathLike, *, max_faces: Optional[int] = None,
                  max_error: Optional[float] = None, format: str = "ply") -> int:
        """Writes one level of the job's PM to `out` (format "ply" or "obj"): the largest with
        at most max_faces faces, or the smallest whose error bound is at most max_error."""
        request = pb.LevelRequest(job_id=job_id, format=format)
        if (max_faces is None) == (max_error is None):
            raise ValueError("give max_faces or max_error")
        if max_faces is not None:
            request.max_faces = max_faces
        else:
            request.max_error = max_error
        chunks = self.stub.GetLevel(request, metadata=self.metadata())
        return self._receive(f"level {job_id}", chunks, out)

    def stream(self, job_id: str, *, from_vsplit: int = 0, max_faces: Optional[int] = None,
               max_error: Optional[float] = None,
               batch_vsplits: int = 0) -> Iterator[pb.PmStreamMessage]:
        """The job's PM as a stream (StreamPM): the .pm file's header and base mesh first,
        then batches of its vertex split records, as they are in the file, up to the limit
        (docs/PM-FORMAT.md, "Streaming"): their bytes concatenated are the file's first bytes."""
        request = pb.StreamRequest(job_id=job_id, from_vsplit=from_vsplit,
                                   batch_vsplits=batch_vsplits)
        if max_faces is not None:
            request.max_faces = max_faces
        if max_error is not None:
            request.max_error = max_error
        try:
            yield from self.stub.StreamPM(request, metadata=self.metadata())
        except grpc.RpcError as e:
            raise ParapmError(f"stream {job_id}", e.code(), e.details()) from None
