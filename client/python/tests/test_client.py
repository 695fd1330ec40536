"""The Python client against real daemons on loopback, started from the build's bin/.

AgainstARealCoordinator: a coordinator with a token and one parapm-worker. A committed mesh is
uploaded (progress reported), built with the energy metric in two subsets on the worker and
watched (every event once, in order; progress callbacks), downloaded (the bytes of the C++
client's `parapm get`, and lossless: `parapm check`), cut into levels (the bytes `parapm lod`
writes from the same .pm), streamed (the .pm's bytes up to its last split; a cut stops at
`parapm lod`'s level), and built again by the example script (the same PM). Errors carry
their gRPC codes: a wrong or missing token, unknown ids, bad options, a file that is no mesh.

UnfinishedJobsOverTls: a coordinator serving TLS (tests/data/tls) with no worker, closing
streams after 1 s: a 43k-face job waits for a worker forever. Its PM is FAILED_PRECONDITION; a
watch closed by the server resumes after its last event until the job is cancelled; a client
without the certificate's root, or without TLS, gets UNAVAILABLE.

Run by ctest (PythonClient.AgainstARealCoordinator) with PYTHONPATH=BUILD/python and
PARAPM_BIN_DIR=BUILD/bin; by hand from anywhere:
    PYTHONPATH=build/python PARAPM_BIN_DIR=build/bin python3 -m unittest -v test_client
"""
from __future__ import annotations

import ctypes
import hashlib
import json
import os
import signal
import subprocess
import sys
import tempfile
import threading
import time
import unittest
from pathlib import Path
from typing import Optional

import grpc

from parapm import Client, ParapmError, pb

ROOT = Path(__file__).resolve().parents[3]
BIN = Path(os.environ.get("PARAPM_BIN_DIR") or ROOT / "build" / "bin")
DATA = ROOT / "tests" / "data"
EXAMPLE = ROOT / "client" / "python" / "examples" / "submit_and_get_level.py"
MESH = DATA / "cad-cycloidal-43k.ply"  # 43368 faces
TOKEN = "python-client-test-token"
PR_SET_PDEATHSIG = 1
START_TIMEOUT_S = 20


def die_with_parent() -> None:
    """In a child before exec: killed when the test program dies, whatever kills it."""
    ctypes.CDLL(None, use_errno=True).prctl(PR_SET_PDEATHSIG, signal.SIGKILL)


def tail(path: Path, lines: int = 40) -> str:
    """The last lines of a log file ("" when absent)."""
    if not path.exists():
        return ""
    return "\n".join(path.read_text(errors="replace").splitlines()[-lines:])


class Service:
    """A coordinator (and workers) under `folder`: its data, token file, port file and logs.
    Every process is killed by stop() and, through PR_SET_PDEATHSIG, with the test program."""

    def __init__(self, folder: Path, coordinator_flags: list[str]):
        self.folder = folder
        self.token_file = folder / "token"
        self.token_file.write_text(TOKEN + "\n")
        self.processes: list[tuple[subprocess.Popen, Path]] = []
        self.port = self._start_coordinator(coordinator_flags)

    def _spawn(self, name: str, argv: list[str]) -> subprocess.Popen:
        log = self.folder / f"{name}.log"
        with log.open("wb") as out:
            process = subprocess.Popen(argv, stdin=subprocess.DEVNULL, stdout=out,
                                       stderr=subprocess.STDOUT, preexec_fn=die_with_parent)
        self.processes.append((process, log))
        return process

    def _start_coordinator(self, flags: list[str]) -> int:
        """Starts it on 127.0.0.1, port 0; returns the port it wrote to its port file."""
        port_file = self.folder / "port"
        process = self._spawn("coordinator", [
            str(BIN / "parapm-coordinator"), "--listen", "127.0.0.1:0", "--port-file",
            str(port_file), "--data", str(self.folder / "data"), "--token-file",
            str(self.token_file), *flags])
        end = time.monotonic() + START_TIMEOUT_S
        while not port_file.exists():
            if process.poll() is not None or time.monotonic() > end:
                self.stop()
                raise RuntimeError("the coordinator is not serving:\n" + self.logs())
            time.sleep(0.02)
        return int(port_file.read_text())

    def start_worker(self, name: str, threads: int) -> None:
        """Starts a parapm-worker and waits until the coordinator logs its registration."""
        self._spawn(f"worker-{name}", [
            str(BIN / "parapm-worker"), "--coordinator", f"127.0.0.1:{self.port}", "--listen",
            "127.0.0.1:0", "--threads", str(threads), "--name", name, "--token-file",
            str(self.token_file)])
        end = time.monotonic() + START_TIMEOUT_S
        while " registered: " not in (self.folder / "coordinator.log").read_text():
            if time.monotonic() > end:
                raise RuntimeError(f"worker {name} did not register:\n" + self.logs())
            time.sleep(0.02)

    def logs(self) -> str:
        """Every process's last log lines, for failure messages."""
        return "\n".join(f"----- {log.name}\n{tail(log)}" for _, log in self.processes)

    def stop(self) -> None:
        for process, _ in self.processes:
            if process.poll() is None:
                process.kill()
            process.wait()


def run(*argv: object, env: Optional[dict] = None) -> subprocess.CompletedProcess:
    """Runs a program to its end (2 minutes at most), its output captured as text."""
    return subprocess.run([str(a) for a in argv], capture_output=True, text=True, timeout=120,
                          env=env)


def parapm(*args: object) -> subprocess.CompletedProcess:
    """The C++ CLI, build/bin/parapm."""
    return run(BIN / "parapm", "--log-level", "warn", *args)


def events_named(events: list[pb.JobEvent], name: str) -> list[pb.JobEvent]:
    return [e for e in events if e.WhichOneof("event") == name]


class AgainstARealCoordinator(unittest.TestCase):
    """One job built on a real worker; every test reads it."""

    @classmethod
    def setUpClass(cls) -> None:
        cls.tmp = tempfile.TemporaryDirectory(prefix="parapm-python-")
        cls.dir = Path(cls.tmp.name)
        cls.service = Service(cls.dir, ["--local-threads", "0"])
        try:
            cls.service.start_worker("py-worker", threads=2)
            cls.server = f"127.0.0.1:{cls.service.port}"
            cls.client = Client(cls.server, token_file=cls.service.token_file)
            cls.build_the_job()
        except BaseException:
            print(cls.service.logs(), file=sys.stderr)
            cls.tearDownClass()
            raise

    @classmethod
    def build_the_job(cls) -> None:
        """Upload, submit, watch and download the class's job."""
        cls.sent: list[tuple[int, int]] = []
        cls.mesh = cls.client.upload(MESH, progress=lambda done, total: cls.sent.append(
            (done, total)))
        # The energy metric in two subsets: rounds on the worker, a build of a few seconds.
        cls.submitted = cls.client.submit(cls.mesh.mesh_id, metric="energy", target_ratio=0.05,
                                          parallelism=2)
        cls.events: list[pb.JobEvent] = []
        cls.job = cls.client.watch(cls.submitted.job_id, cls.events.append)
        cls.pm = cls.dir / "job.pm"
        cls.client.download(cls.job.job_id, cls.pm)

    @classmethod
    def tearDownClass(cls) -> None:
        if hasattr(cls, "client"):
            cls.client.close()
        cls.service.stop()
        cls.tmp.cleanup()

    def cli(self, *args: object) -> subprocess.CompletedProcess:
        """A service command of the C++ CLI against this coordinator."""
        return parapm(*args, "--server", self.server, "--token-file", self.service.token_file)

    def lod(self, out: Path, *cut: object) -> dict:
        """`parapm lod` of the job's .pm into `out`; its --json report."""
        done = parapm("lod", self.pm, "-o", out, "--json", *cut)
        self.assertEqual(done.returncode, 0, done.stderr)
        return json.loads(done.stdout)

    def test_the_upload_reports_the_mesh_and_its_progress(self) -> None:
        size = MESH.stat().st_size
        self.assertEqual(self.mesh.faces, 43368)
        self.assertEqual(self.mesh.bytes, size)
        self.assertEqual(self.mesh.content_sha256, hashlib.sha256(MESH.read_bytes()).hexdigest())
        self.assertEqual(self.sent[-1], (size, size))
        self.assertTrue(all(b - a <= 1 << 20 for (a, _), (b, _) in
                            zip([(0, 0)] + self.sent, self.sent)), self.sent)
        # The same bytes again: the same mesh.
        self.assertEqual(self.client.upload(MESH).mesh_id, self.mesh.mesh_id)

    def test_the_watch_sees_every_event_once_in_order(self) -> None:
        self.assertEqual(self.job.state, pb.DONE, self.job.failure_reason)
        self.assertEqual(self.submitted.options.parallelism, 2)
        self.assertEqual([e.seq for e in self.events], list(range(1, len(self.events) + 1)))
        self.assertEqual(self.events[0].WhichOneof("event"), "queued")
        self.assertEqual(self.events[-1].WhichOneof("event"), "finished")
        self.assertEqual(self.events[-1].finished.vsplits, self.job.vsplits)
        # The subsets ran on the worker.
        started = events_named(self.events, "subset_started")
        self.assertTrue(started, [e.WhichOneof("event") for e in self.events])
        self.assertEqual({e.subset_started.worker for e in started}, {"py-worker"})

    def test_wait_calls_progress_with_the_progress_events(self) -> None:
        calls: list[tuple[int, int]] = []
        job = self.client.wait(self.job.job_id, lambda done, total: calls.append((done, total)))
        self.assertEqual(job.state, pb.DONE)
        seen = [(e.progress.done, e.progress.total)
                for e in events_named(self.events, "progress")]
        self.assertTrue(seen, "the build reported no progress")
        self.assertEqual(calls, seen)
        for done, total in seen:
            self.assertLessEqual(done, total)

    def test_the_pm_is_the_cpp_clients_and_lossless(self) -> None:
        data = self.pm.read_bytes()
        self.assertEqual(len(data), self.job.pm_bytes)
        self.assertEqual(hashlib.sha256(data).hexdigest(), self.job.pm_sha256)
        theirs = self.dir / "cpp.pm"
        got = self.cli("get", self.job.job_id, "-o", theirs)
        self.assertEqual(got.returncode, 0, got.stderr)
        self.assertEqual(data, theirs.read_bytes())
        check = parapm("check", self.pm, "--against", MESH)
        self.assertEqual(check.returncode, 0, check.stdout + check.stderr)

    def test_a_level_is_parapm_lods(self) -> None:
        for fmt in ("obj", "ply"):
            for cut, flags in (({"max_faces": 5000}, ["--faces", 5000]),
                               ({"max_faces": 1}, ["--faces", 1]),
                               ({"max_error": 1e-3}, ["--error", 1e-3])):
                with self.subTest(format=fmt, cut=cut):
                    ours, theirs = self.dir / f"py.{fmt}", self.dir / f"lod.{fmt}"
                    size = self.client.get_level(self.job.job_id, ours, **cut)
                    self.lod(theirs, *flags)
                    self.assertEqual(size, ours.stat().st_size)
                    self.assertEqual(ours.read_bytes(), theirs.read_bytes())
        # format= names it whatever the file's name.
        named = self.dir / "level.bin"
        self.client.get_level(self.job.job_id, named, max_faces=5000, format="obj")
        self.lod(self.dir / "lod-5000.obj", "--faces", 5000)
        self.assertEqual(named.read_bytes(), (self.dir / "lod-5000.obj").read_bytes())

    def test_the_stream_is_the_file(self) -> None:
        data = self.pm.read_bytes()
        parts = list(self.client.stream(self.job.job_id, batch_vsplits=1000))
        self.assertEqual(parts[0].WhichOneof("part"), "header_and_base")
        self.assertTrue(all(p.WhichOneof("part") == "vsplit_batch" for p in parts[1:]))
        self.assertEqual([p.first_vsplit for p in parts[1:]],
                         list(range(0, self.job.vsplits, 1000)))
        self.assertEqual({p.total_vsplits for p in parts}, {self.job.vsplits})
        # The file up to its last split record (what follows is for full resolution only:
        # vertex copies, input order, a checksum; docs/PM-FORMAT.md).
        streamed = b"".join(p.header_and_base + p.vsplit_batch for p in parts)
        self.assertEqual(streamed, data[:len(streamed)])
        # Up to a face count: the records of `parapm lod`'s level, then on from there.
        level = self.lod(self.dir / "cut.obj", "--faces", 5000)["level"]
        cut = list(self.client.stream(self.job.job_id, max_faces=5000))
        self.assertEqual(sum(p.count for p in cut), level)
        rest = list(self.client.stream(self.job.job_id, from_vsplit=level))
        self.assertNotEqual(rest[0].WhichOneof("part"), "header_and_base")
        self.assertEqual(b"".join(p.header_and_base + p.vsplit_batch for p in cut + rest),
                         streamed)

    def test_the_example_script_builds_the_same_pm(self) -> None:
        pm, level = self.dir / "example.pm", self.dir / "example.ply"
        done = run(sys.executable, EXAMPLE, MESH, "--server", self.server, "--token-file",
                   self.service.token_file, "--metric", "energy", "--ratio", 0.05,
                   "--parallelism", 2, "--faces", 3000, "--pm", pm, "--level", level)
        self.assertEqual(done.returncode, 0, done.stdout + done.stderr)
        self.assertIn("faces removed", done.stderr)
        self.assertEqual(pm.read_bytes(), self.pm.read_bytes())
        self.lod(self.dir / "lod-3000.ply", "--faces", 3000)
        self.assertEqual(level.read_bytes(), (self.dir / "lod-3000.ply").read_bytes())

    def test_the_example_script_helps_without_the_service(self) -> None:
        env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
        helped = run(sys.executable, EXAMPLE, "--help", env=env)
        self.assertEqual(helped.returncode, 0, helped.stderr)
        self.assertIn("--faces", helped.stdout)

    def assertFails(self, code: grpc.StatusCode, call, *args, **kwargs) -> ParapmError:
        """Runs the call, which must raise ParapmError with `code`; returns it."""
        with self.assertRaises(ParapmError) as raised:
            call(*args, **kwargs)
        self.assertEqual(raised.exception.code, code, str(raised.exception))
        return raised.exception

    def test_a_wrong_or_missing_token_is_unauthenticated(self) -> None:
        with Client(self.server, token="not-it") as wrong:
            error = self.assertFails(grpc.StatusCode.UNAUTHENTICATED, wrong.jobs)
            self.assertIn("the bearer token is wrong", error.details)
            self.assertFails(grpc.StatusCode.UNAUTHENTICATED, wrong.upload, MESH)
            self.assertFails(grpc.StatusCode.UNAUTHENTICATED,
                             lambda: list(wrong.stream(self.job.job_id)))
        with Client(self.server, token="") as none:
            error = self.assertFails(grpc.StatusCode.UNAUTHENTICATED, none.job, self.job.job_id)
            self.assertIn("needs a bearer token", error.details)

    def test_unknown_ids_are_not_found(self) -> None:
        unknown = "job-0000000000000000"
        error = self.assertFails(grpc.StatusCode.NOT_FOUND, self.client.job, unknown)
        self.assertEqual(str(error), f"get job {unknown}: NOT_FOUND: no job '{unknown}'")
        self.assertFails(grpc.StatusCode.NOT_FOUND, self.client.watch, unknown)
        out = self.dir / "missing.pm"
        self.assertFails(grpc.StatusCode.NOT_FOUND, self.client.download, unknown, out)
        self.assertFails(grpc.StatusCode.NOT_FOUND, self.client.get_level, unknown,
                         self.dir / "missing.obj", max_faces=10)
        self.assertFalse(out.exists())
        self.assertFalse(out.with_name(out.name + ".part").exists())
        self.assertFails(grpc.StatusCode.NOT_FOUND, self.client.submit, "mesh-0000000000000000")

    def test_bad_requests_are_invalid_arguments(self) -> None:
        error = self.assertFails(grpc.StatusCode.INVALID_ARGUMENT, self.client.submit,
                                 self.mesh.mesh_id, target_ratio=2.0)
        self.assertIn("target_ratio", error.details)
        self.assertFails(grpc.StatusCode.INVALID_ARGUMENT, self.client.submit, self.mesh.mesh_id,
                         parallelism=1000)
        not_a_mesh = self.dir / "not-a-mesh.obj"
        not_a_mesh.write_text("v 0 0 0\nf 1 2 3\n")
        error = self.assertFails(grpc.StatusCode.INVALID_ARGUMENT, self.client.upload, not_a_mesh)
        self.assertIn("not-a-mesh.obj", error.details)
        empty = self.dir / "empty.ply"
        empty.write_bytes(b"")
        self.assertFails(grpc.StatusCode.INVALID_ARGUMENT, self.client.upload, empty)
        self.assertFails(grpc.StatusCode.INVALID_ARGUMENT, lambda: list(
            self.client.stream(self.job.job_id, from_vsplit=self.job.vsplits + 1)))
        # Caught before any call.
        with self.assertRaises(ValueError):
            self.client.get_level(self.job.job_id, self.dir / "x.obj")
        with self.assertRaises(ValueError):
            self.client.get_level(self.job.job_id, self.dir / "x.stl", max_faces=10)
        with self.assertRaises(ValueError):
            self.client.submit(self.mesh.mesh_id, metric="fast")


class UnfinishedJobsOverTls(unittest.TestCase):
    """A coordinator over TLS with no worker: a job of 43k faces starts and waits for one."""

    CERT = DATA / "tls" / "cert.pem"  # for localhost and 127.0.0.1

    @classmethod
    def setUpClass(cls) -> None:
        cls.tmp = tempfile.TemporaryDirectory(prefix="parapm-python-tls-")
        cls.dir = Path(cls.tmp.name)
        cls.service = Service(cls.dir, [
            "--tls-cert", str(cls.CERT), "--tls-key", str(DATA / "tls" / "key.pem"),
            "--local-threads", "0", "--stream-total-s", "1"])
        cls.server = f"localhost:{cls.service.port}"
        cls.client = Client(cls.server, token=TOKEN, tls_ca=cls.CERT)
        try:
            cls.mesh = cls.client.upload(MESH)
        except BaseException:
            print(cls.service.logs(), file=sys.stderr)
            cls.tearDownClass()
            raise

    @classmethod
    def tearDownClass(cls) -> None:
        cls.client.close()
        cls.service.stop()
        cls.tmp.cleanup()

    def submit(self, seed: int) -> pb.Job:
        """A job of its own (each seed: a new job) that never ends by itself."""
        return self.client.submit(self.mesh.mesh_id, target_ratio=0.1, parallelism=2, seed=seed)

    def test_only_a_client_trusting_the_certificate_gets_in(self) -> None:
        job = self.submit(seed=1)
        self.assertIn(job.job_id, [j.job_id for j in self.client.jobs()])
        with Client(self.server, token=TOKEN) as plain:
            with self.assertRaises(ParapmError) as refused:
                plain.job(job.job_id)
            self.assertEqual(refused.exception.code, grpc.StatusCode.UNAVAILABLE)
        with Client(self.server, token=TOKEN, tls=True) as untrusting:  # the system's roots
            with self.assertRaises(ParapmError) as refused:
                untrusting.job(job.job_id)
            self.assertEqual(refused.exception.code, grpc.StatusCode.UNAVAILABLE)

    def test_an_unfinished_job_has_no_pm_yet(self) -> None:
        job = self.submit(seed=2)
        out = self.dir / "early.pm"
        for call, args in ((self.client.download, (out,)),
                           (self.client.get_level, (self.dir / "early.obj",)),
                           (self.client.delete_job, ())):
            kwargs = {"max_faces": 100} if call == self.client.get_level else {}
            with self.subTest(call=call.__name__):
                with self.assertRaises(ParapmError) as refused:
                    call(job.job_id, *args, **kwargs)
                self.assertEqual(refused.exception.code, grpc.StatusCode.FAILED_PRECONDITION)
        self.assertFalse(out.exists())
        with self.assertRaises(ParapmError) as refused:
            self.client.delete_mesh(self.mesh.mesh_id)
        self.assertEqual(refused.exception.code, grpc.StatusCode.FAILED_PRECONDITION)

    def test_a_watch_the_server_closes_resumes_after_its_last_event(self) -> None:
        job = self.submit(seed=3)
        events: list[pb.JobEvent] = []
        # The coordinator closes the watch after 1 s (DEADLINE_EXCEEDED); the client watches
        # again a second later from its last event, and sees the cancellation at 2.5 s.
        cancel = threading.Timer(2.5, self.client.cancel, [job.job_id])
        cancel.start()
        try:
            with self.assertLogs("parapm", "WARNING") as logged:
                ended = self.client.watch(job.job_id, events.append)
        finally:
            cancel.cancel()
        self.assertEqual(ended.state, pb.CANCELLED)
        self.assertEqual([e.seq for e in events], list(range(1, len(events) + 1)))
        self.assertEqual(events[-1].WhichOneof("event"), "cancelled")
        resumed = [line for line in logged.output if "DEADLINE_EXCEEDED" in line]
        self.assertTrue(resumed, logged.output)
        self.assertIn(f"resuming after event {events[-2].seq}", resumed[-1])


if __name__ == "__main__":
    unittest.main()
