"""The Python client against a real coordinator on loopback: a coordinator started from the
build (parapm-coordinator, running subsets itself) with a token; a committed mesh uploaded,
built, watched with progress, downloaded (the same bytes as the C++ client's `parapm get`,
and lossless: `parapm check`), a level (the same bytes as `parapm level`), a stream (its
bytes the .pm file's first bytes); the example script end to end; a wrong token and an
unknown job are errors with their codes.

Run by ctest (PythonClient.AgainstARealCoordinator) with PARAPM_BIN_DIR set to the build's bin/.
"""
import os
import subprocess
import sys
import tempfile
import time
import unittest
from pathlib import Path

import grpc

from parapm import Client, ParapmError, pb

BIN = Path(os.environ.get("PARAPM_BIN_DIR", Path(__file__).resolve().parents[3] / "build" / "bin"))
ROOT = Path(__file__).resolve().parents[3]
MESH = ROOT / "tests" / "data" / "cad-cycloidal-43k.ply"
TOKEN = "python-client-token"


class AgainstARealCoordinator(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.dir = tempfile.TemporaryDirectory(prefix="parapm-python-")
        d = Path(cls.dir.name)
        (d / "token").write_text(TOKEN + "\n")
        cls.log = open(d / "coordinator.log", "w")
        cls.coordinator = subprocess.Popen(
            [str(BIN / "parapm-coordinator"), "--listen", "127.0.0.1:0", "--port-file", str(d / "port"),
             "--data", str(d / "data"), "--local-threads", "2", "--token-file", str(d / "token")],
            stdout=cls.log, stderr=subprocess.STDOUT)
        for _ in range(200):
            if (d / "port").exists() and (d / "port").read_text().strip():
                break
            time.sleep(0.05)
        cls.server = f"127.0.0.1:{(d / 'port').read_text().strip()}"
        cls.client = Client(cls.server, token=TOKEN)

    @classmethod
    def tearDownClass(cls):
        cls.client.close()
        cls.coordinator.terminate()
        cls.coordinator.wait(timeout=30)
        cls.log.close()
        cls.dir.cleanup()

    def cli(self, *args) -> subprocess.CompletedProcess:
        env = dict(os.environ, PARAPM_TOKEN=TOKEN)
        return subprocess.run([str(BIN / "parapm"), "--log-level", "warn", *args, "--server", self.server],
                              env=env, capture_output=True, text=True)

    def built_job(self) -> pb.Job:
        if not hasattr(type(self), "_job"):
            sent = []
            mesh = self.client.upload(MESH, progress=lambda done, total: sent.append((done, total)))
            self.assertEqual(mesh.faces, 43368)
            self.assertEqual(sent[-1], (MESH.stat().st_size, MESH.stat().st_size))
            # The energy metric in two subsets: a build of a few seconds, long enough for
            # progress events (one a second).
            job = self.client.submit(mesh.mesh_id, metric="energy", target_ratio=0.05, parallelism=2)
            self.assertIn(job.state, (pb.QUEUED, pb.RUNNING, pb.DONE))
            events, progress = [], []
            done = self.client.watch(job.job_id, events.append)
            self.assertEqual(done.state, pb.DONE, done.failure_reason)
            self.assertEqual(events[-1].WhichOneof("event"), "finished")
            self.assertEqual([e.seq for e in events], list(range(1, len(events) + 1)))
            # wait() on an ended job: its events again, progress(done, total) for each progress.
            self.client.wait(job.job_id, lambda d, t: progress.append((d, t)))
            seen = [(e.progress.done, e.progress.total) for e in events if e.WhichOneof("event") == "progress"]
            self.assertTrue(seen, "the build reported no progress")
            self.assertEqual(progress, seen)
            self.assertLessEqual(progress[-1][0], progress[-1][1])
            type(self)._job = done
        return type(self)._job

    def test_the_pm_is_the_cpp_clients_and_lossless(self):
        job = self.built_job()
        with tempfile.TemporaryDirectory() as d:
            ours, theirs = Path(d) / "py.pm", Path(d) / "cpp.pm"
            self.assertEqual(self.client.download(job.job_id, ours), ours.stat().st_size)
            got = self.cli("get", job.job_id, "-o", str(theirs))
            self.assertEqual(got.returncode, 0, got.stderr)
            self.assertEqual(ours.read_bytes(), theirs.read_bytes())
            check = subprocess.run([str(BIN / "parapm"), "--log-level", "warn", "check", str(ours),
                                    "--against", str(MESH)], capture_output=True, text=True)
            self.assertEqual(check.returncode, 0, check.stdout + check.stderr)

    def test_a_level_is_parapm_levels(self):
        job = self.built_job()
        with tempfile.TemporaryDirectory() as d:
            ours, theirs = Path(d) / "py.ply", Path(d) / "cpp.ply"
            self.client.get_level(job.job_id, ours, max_faces=5000, format="ply")
            got = self.cli("level", job.job_id, "--faces", "5000", "-o", str(theirs))
            self.assertEqual(got.returncode, 0, got.stderr)
            self.assertEqual(ours.read_bytes(), theirs.read_bytes())

    def test_the_stream_is_the_files_first_bytes(self):
        job = self.built_job()
        with tempfile.TemporaryDirectory() as d:
            pm = Path(d) / "x.pm"
            self.client.download(job.job_id, pm)
            parts = list(self.client.stream(job.job_id, batch_vsplits=1000))
            self.assertEqual(parts[0].WhichOneof("part"), "header_and_base")
            self.assertEqual(sum(p.count for p in parts[1:]), job.vsplits)
            data = b"".join(p.header_and_base or p.vsplit_batch for p in parts)
            self.assertEqual(data, pm.read_bytes()[:len(data)])
            # Up to a face count: fewer records.
            cut = list(self.client.stream(job.job_id, max_faces=job.base_faces + 100))
            self.assertLess(sum(p.count for p in cut[1:]), job.vsplits)

    def test_the_example_script_end_to_end(self):
        with tempfile.TemporaryDirectory() as d:
            script = ROOT / "client" / "python" / "examples" / "submit_and_get_level.py"
            env = dict(os.environ, PARAPM_TOKEN=TOKEN)
            run = subprocess.run([sys.executable, str(script), str(MESH), "--server", self.server,
                                  "--faces", "3000", "--pm", str(Path(d) / "e.pm"), "--level",
                                  str(Path(d) / "e.obj")], env=env, capture_output=True, text=True)
            self.assertEqual(run.returncode, 0, run.stdout + run.stderr)
            self.assertIn("vsplits", run.stdout)
            self.assertTrue((Path(d) / "e.obj").stat().st_size > 0)
            helped = subprocess.run([sys.executable, str(script), "--help"], capture_output=True, text=True)
            self.assertEqual(helped.returncode, 0)
            self.assertIn("--faces", helped.stdout)

    def test_a_wrong_token_and_an_unknown_job_are_errors_with_their_codes(self):
        with Client(self.server, token="not-it") as wrong:
            with self.assertRaises(ParapmError) as refused:
                wrong.jobs()
            self.assertEqual(refused.exception.code, grpc.StatusCode.UNAUTHENTICATED)
        with self.assertRaises(ParapmError) as unknown:
            self.client.job("job-0000000000000000")
        self.assertEqual(unknown.exception.code, grpc.StatusCode.NOT_FOUND)
        with tempfile.TemporaryDirectory() as d:
            with self.assertRaises(ParapmError) as missing:
                self.client.download("job-0000000000000000", Path(d) / "x.pm")
            self.assertEqual(missing.exception.code, grpc.StatusCode.NOT_FOUND)
            self.assertFalse((Path(d) / "x.pm").exists())
            self.assertFalse((Path(d) / "x.pm.part").exists())


if __name__ == "__main__":
    unittest.main()
