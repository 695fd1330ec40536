"""Client: a connection to a ParaPM coordinator and the calls that take more than one step.

Every RPC of MeshService is reachable through Client.stub (the generated stub, with
metadata=client.metadata() for the token); the methods here add the token, chunking, resuming
and errors a program needs. A failed call raises ParapmError with the gRPC status code and the
server's message.
"""
from __future__ import annotations

import logging
import os
import time
from pathlib import Path
from typing import Callable, Iterable, Iterator, Optional, Union

import grpc

try:
    import parapm_pb2 as pb
    import parapm_pb2_grpc as pb_grpc
except ImportError as e:  # the build writes them: they are not in the source tree
    raise ImportError(
        "parapm: the generated modules parapm_pb2 / parapm_pb2_grpc are not importable; build "
        "the target parapm_python (scripts/bootstrap.sh builds everything) and put BUILD/python "
        f"on PYTHONPATH ({e})") from e

PathLike = Union[str, "os.PathLike[str]"]
ProgressCallback = Callable[[int, int], None]

log = logging.getLogger("parapm")

DEFAULT_SERVER = "127.0.0.1:50051"  # where `parapm up` listens
# The coordinator takes upload chunks of at most 4 MiB (parapm.proto); 1 MiB as the C++ client.
UPLOAD_CHUNK_BYTES = 1 << 20
# The largest message either side accepts (proto/rpc_security.h: kMaxMessageBytes): a
# StreamPM batch of many vsplits can exceed gRPC's default of 4 MiB.
MAX_MESSAGE_BYTES = 1 << 30
# The C++ client's channel (rpc_security.cpp, make_channel): a dead peer is noticed by
# keepalive pings; the coordinator accepts them (rpc_server.cpp).
CHANNEL_OPTIONS = [
    ("grpc.max_receive_message_length", MAX_MESSAGE_BYTES),
    ("grpc.max_send_message_length", MAX_MESSAGE_BYTES),
    ("grpc.keepalive_time_ms", 10000),
    ("grpc.keepalive_timeout_ms", 5000),
    ("grpc.keepalive_permit_without_calls", 1),
]
# A watch that ends with one of these (the coordinator restarted, closed a watch open for its
# longest time, or had no room for another stream) resumes after the last event seen.
RESUMABLE = frozenset({grpc.StatusCode.UNAVAILABLE, grpc.StatusCode.DEADLINE_EXCEEDED,
                       grpc.StatusCode.RESOURCE_EXHAUSTED})
WATCH_RETRIES = 60  # resumes in a row without an event, one second apart
METRICS = {"quadric": pb.METRIC_QUADRIC, "energy": pb.METRIC_ENERGY}
LEVEL_FORMATS = ("obj", "ply")


class ParapmError(Exception):
    """A failed call: `code` is its grpc.StatusCode, `details` the server's message, `what`
    the call and its subject (e.g. "download job-..."). str(): "WHAT: CODE: DETAILS"."""

    def __init__(self, what: str, code: grpc.StatusCode, details: str, server: str = ""):
        text = f"{what}: {code.name}: {details}"
        if code == grpc.StatusCode.UNAVAILABLE and server:
            text += f" (is a coordinator running at {server}? 'parapm up' starts one)"
        super().__init__(text)
        self.what = what
        self.code = code
        self.details = details


def load_token(token: Optional[str] = None, token_file: Optional[PathLike] = None) -> str:
    """The bearer token: `token` when given, else token_file's text (surrounding whitespace
    dropped; an empty file is an error), else PARAPM_TOKEN, else "" (no token: a loopback
    coordinator started without one)."""
    if token is not None:
        return token
    if token_file:
        text = Path(token_file).read_text().strip()
        if not text:
            raise ValueError(f"{token_file}: the token file is empty")
        return text
    return os.environ.get("PARAPM_TOKEN", "").strip()


def job_options(options: Optional[pb.JobOptions] = None, *, metric: Optional[str] = None,
                target_ratio: Optional[float] = None, target_faces: Optional[int] = None,
                parallelism: Optional[int] = None, seed: Optional[int] = None) -> pb.JobOptions:
    """A copy of `options` (default: empty, the coordinator's defaults) with the keywords
    given set: metric "quadric" or "energy", target_ratio or target_faces (one: they are a
    oneof), parallelism (subsets p), seed."""
    out = pb.JobOptions()
    if options is not None:
        out.CopyFrom(options)
    if metric is not None:
        if metric not in METRICS:
            raise ValueError(f"metric {metric!r}: 'quadric' or 'energy'")
        out.metric = METRICS[metric]
    if target_ratio is not None and target_faces is not None:
        raise ValueError("give target_ratio or target_faces, not both")
    if target_ratio is not None:
        out.target_ratio = target_ratio
    if target_faces is not None:
        out.target_faces = target_faces
    if parallelism is not None:
        out.parallelism = parallelism
    if seed is not None:
        out.seed = seed
    return out


def level_format(path: PathLike, format: Optional[str]) -> str:
    """`format` when given, else the file's extension: "obj" or "ply"."""
    chosen = format or Path(path).suffix.lower().lstrip(".")
    if chosen not in LEVEL_FORMATS:
        raise ValueError(f"{path}: a level is written as .obj or .ply (or give format=)")
    return chosen


def upload_chunks(path: Path, progress: Optional[ProgressCallback] = None,
                  chunk_bytes: int = UPLOAD_CHUNK_BYTES) -> Iterator[pb.UploadChunk]:
    """The UploadChunk messages of a file: the first names it (its extension tells the
    format) and every one carries at most chunk_bytes; an empty file gives one empty chunk (the
    coordinator then says the upload is empty). progress(sent, total) after each."""
    total = path.stat().st_size
    sent = 0
    with path.open("rb") as f:
        data = f.read(chunk_bytes)
        yield pb.UploadChunk(file_name=path.name, data=data)
        while True:
            sent += len(data)
            if progress:
                progress(sent, total)
            data = f.read(chunk_bytes)
            if not data:
                return
            yield pb.UploadChunk(data=data)


class Client:
    """A connection to a coordinator.

    server: host:port (default: PARAPM_SERVER, else 127.0.0.1:50051). token / token_file: the
    bearer token sent as "authorization: Bearer TOKEN" on every call (default: PARAPM_TOKEN;
    none for a loopback coordinator started without one). tls: connect over TLS, verifying the
    server against tls_ca (a PEM file) or root_certificates (PEM bytes), else the system's
    roots; either of those implies tls. Use it as a context manager, or close() it.
    """

    def __init__(self, server: Optional[str] = None, *, token: Optional[str] = None,
                 token_file: Optional[PathLike] = None, tls: bool = False,
                 tls_ca: Optional[PathLike] = None, root_certificates: Optional[bytes] = None):
        self.server = server or os.environ.get("PARAPM_SERVER") or DEFAULT_SERVER
        self._token = load_token(token, token_file)
        if tls_ca is not None:
            root_certificates = Path(tls_ca).read_bytes()
        if tls or root_certificates is not None:
            credentials = grpc.ssl_channel_credentials(root_certificates=root_certificates)
            self._channel = grpc.secure_channel(self.server, credentials, CHANNEL_OPTIONS)
        else:
            self._channel = grpc.insecure_channel(self.server, CHANNEL_OPTIONS)
        self.stub = pb_grpc.MeshServiceStub(self._channel)

    def close(self) -> None:
        self._channel.close()

    def __enter__(self) -> "Client":
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def metadata(self) -> list[tuple[str, str]]:
        """The call metadata carrying the token (none without one)."""
        return [("authorization", f"Bearer {self._token}")] if self._token else []

    def _error(self, what: str, e: grpc.RpcError) -> ParapmError:
        return ParapmError(what, e.code(), e.details() or "", self.server)

    def _call(self, what: str, method: Callable, request: object,
              timeout: Optional[float] = 60) -> object:
        """A unary (or client-streaming) call with the token; `timeout` seconds, None: none."""
        try:
            return method(request, metadata=self.metadata(), timeout=timeout)
        except grpc.RpcError as e:
            raise self._error(what, e) from None

    # ---- meshes and jobs ------------------------------------------------------------------

    def upload(self, path: PathLike, progress: Optional[ProgressCallback] = None
               ) -> pb.UploadReply:
        """Uploads a mesh file (.obj .ply .off .stl, optionally .gz) in 1 MiB chunks,
        progress(sent, total) after each. Returns the stored mesh: its mesh_id (the same bytes
        give the same id), counts after repair, and what the repair did."""
        path = Path(path)
        path.stat()  # a missing file fails here, before the call
        return self._call(f"upload {path}", self.stub.Upload, upload_chunks(path, progress),
                          timeout=None)

    def submit(self, mesh_id: str, options: Optional[pb.JobOptions] = None, *,
               metric: Optional[str] = None, target_ratio: Optional[float] = None,
               target_faces: Optional[int] = None, parallelism: Optional[int] = None,
               seed: Optional[int] = None) -> pb.Job:
        """Queues a job of an uploaded mesh: `options` as a JobOptions, and/or the common ones
        as keywords (job_options()); the coordinator's defaults for the rest. Returns the job
        (state QUEUED, its options with the parallelism pinned)."""
        request = pb.SubmitRequest(mesh_id=mesh_id, options=job_options(
            options, metric=metric, target_ratio=target_ratio, target_faces=target_faces,
            parallelism=parallelism, seed=seed))
        return self._call(f"submit {mesh_id}", self.stub.Submit, request)

    def job(self, job_id: str) -> pb.Job:
        """The job now: state, counts, progress, failure reason."""
        return self._call(f"get job {job_id}", self.stub.GetJob, pb.JobRef(job_id=job_id))

    def jobs(self, limit: int = 100) -> list[pb.Job]:
        """The newest jobs first, at most `limit`."""
        reply = self._call("list jobs", self.stub.ListJobs, pb.ListJobsRequest(limit=limit))
        return list(reply.jobs)

    def cancel(self, job_id: str) -> pb.Job:
        """Cancels a job (queued: at once; running: at its next check; ended: unchanged)."""
        return self._call(f"cancel {job_id}", self.stub.CancelJob, pb.JobRef(job_id=job_id))

    def delete_job(self, job_id: str) -> pb.DeleteReply:
        """Deletes an ended job, its events and its PM."""
        return self._call(f"delete {job_id}", self.stub.DeleteJob, pb.JobRef(job_id=job_id))

    def delete_mesh(self, mesh_id: str) -> pb.DeleteReply:
        """Deletes a mesh and its jobs (all of them ended)."""
        return self._call(f"delete {mesh_id}", self.stub.DeleteMesh, pb.MeshRef(mesh_id=mesh_id))

    def watch(self, job_id: str, on_event: Optional[Callable[[pb.JobEvent], None]] = None,
              after_seq: int = 0) -> pb.Job:
        """Follows the job's events after `after_seq` to its last (finished, failed or
        cancelled), calling on_event for each. A watch that breaks (UNAVAILABLE,
        DEADLINE_EXCEEDED, RESOURCE_EXHAUSTED) is resumed a second later after the last event
        seen, logged as a warning on the "parapm" logger; after 60 breaks in a row without an
        event it raises. Returns the job as it ended."""
        after, breaks = after_seq, 0
        while True:
            try:
                for event in self.stub.Watch(pb.WatchRequest(job_id=job_id, after_seq=after),
                                             metadata=self.metadata()):
                    after, breaks = event.seq, 0
                    if on_event:
                        on_event(event)
                return self.job(job_id)
            except grpc.RpcError as e:
                if e.code() not in RESUMABLE or breaks >= WATCH_RETRIES:
                    raise self._error(f"watch {job_id}", e) from None
                breaks += 1
                log.warning("watch %s: %s: %s; resuming after event %d", job_id,
                            e.code().name, e.details(), after)
                time.sleep(1)

    def wait(self, job_id: str, progress: Optional[ProgressCallback] = None) -> pb.Job:
        """watch() with a progress callback: progress(done, total) for each progress event
        (faces removed so far of those to remove, about once a second while it runs). Returns
        the job as it ended (DONE, FAILED with its failure_reason, or CANCELLED)."""
        def on_event(event: pb.JobEvent) -> None:
            if progress and event.WhichOneof("event") == "progress":
                progress(event.progress.done, event.progress.total)
        return self.watch(job_id, on_event)

    # ---- results --------------------------------------------------------------------------

    def _receive(self, what: str, chunks: Iterable[pb.Chunk], out: PathLike) -> int:
        """Writes a stream of Chunk messages to `out` through OUT.part, renamed at the end: a
        failed call leaves no file. Returns the bytes written."""
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
            raise self._error(what, e) from None
        except BaseException:
            part.unlink(missing_ok=True)
            raise
        part.replace(out)
        return written

    def download(self, job_id: str, out: PathLike) -> int:
        """Writes the done job's .pm to `out`; returns its size."""
        chunks = self.stub.Download(pb.JobRef(job_id=job_id), metadata=self.metadata())
        return self._receive(f"download {job_id}", chunks, out)

    def get_level(self, job_id: str, out: PathLike, *, max_faces: Optional[int] = None,
                  max_error: Optional[float] = None, format: Optional[str] = None) -> int:
        """Writes one level of the done job's PM to `out`, cut by the coordinator (GetLevel):
        the largest with at most max_faces faces, or the smallest whose error bound is at most
        max_error (give one). format "obj" or "ply"; default: out's extension. Returns the
        bytes written."""
        if (max_faces is None) == (max_error is None):
            raise ValueError("give max_faces or max_error")
        request = pb.LevelRequest(job_id=job_id, format=level_format(out, format))
        if max_faces is not None:
            request.max_faces = max_faces
        else:
            request.max_error = max_error
        chunks = self.stub.GetLevel(request, metadata=self.metadata())
        return self._receive(f"level {job_id}", chunks, out)

    def stream(self, job_id: str, *, from_vsplit: int = 0, max_faces: Optional[int] = None,
               max_error: Optional[float] = None, batch_vsplits: int = 0
               ) -> Iterator[pb.PmStreamMessage]:
        """The done job's PM as it streams (StreamPM): the .pm header and base mesh first
        (header_and_base, when from_vsplit is 0), then batches of vertex split records
        (vsplit_batch; first_vsplit, count) from from_vsplit up to the level of max_faces or
        max_error (else all). Their bytes concatenated are the .pm file up to that split
        record (docs/PM-FORMAT.md, "Streaming"; the file's last section, for full resolution
        only, is not streamed). Leaving the loop early cancels the call."""
        if max_faces is not None and max_error is not None:
            raise ValueError("give max_faces or max_error, not both")
        request = pb.StreamRequest(job_id=job_id, from_vsplit=from_vsplit,
                                   batch_vsplits=batch_vsplits)
        if max_faces is not None:
            request.max_faces = max_faces
        if max_error is not None:
            request.max_error = max_error
        call = self.stub.StreamPM(request, metadata=self.metadata())
        try:
            yield from call
        except grpc.RpcError as e:
            raise self._error(f"stream {job_id}", e) from None
        finally:
            call.cancel()  # nothing once the stream ended
