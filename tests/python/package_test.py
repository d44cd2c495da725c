#!/usr/bin/python3
"""The motiondb Python package (client/python), installed offline and run against the server.

Installs client/python with `pip install --no-index --no-deps --target DIR` (the stubs generated
from proto/ on the way; nothing written into the source tree),
imports motiondb from DIR only, starts the real motiondb-server on a free loopback port with a
temporary database, and drives it through the package: ingest, a space, search, labels, a
propagation job watched to its end, curves; then runs examples/propagate_markup.py end to end;
and connects with a token, and over TLS.
usage: package_test.py SERVER_BINARY REPO_ROOT
"""
import csv
import os
import pathlib
import shutil
import signal
import subprocess
import sys
import tempfile
import unittest

from server_fixtures import arm_raise_bvh, logged_port

SERVER = REPO = None
motiondb = None  # imported from the installed copy in setUpModule
WORK = None
SITE = None


def setUpModule():
    global motiondb, WORK, SITE
    WORK = tempfile.TemporaryDirectory()
    source = REPO / "client" / "python"
    before = sorted(str(p) for p in source.rglob("*") if "__pycache__" not in p.parts)
    SITE = pathlib.Path(WORK.name) / "site"
    env = dict(os.environ, MOTIONDB_PROTO_DIR=str(REPO / "proto"))
    env.pop("PYTHONPATH", None)
    install = subprocess.run(
        [sys.executable, "-m", "pip", "install", "--no-index", "--no-deps", "--no-cache-dir",
         "--disable-pip-version-check", "--target", str(SITE), str(source)],
        env=env, capture_output=True, text=True, timeout=300)
    if install.returncode != 0:
        raise RuntimeError(f"pip install failed:\n{install.stdout}\n{install.stderr}")
    after = sorted(str(p) for p in source.rglob("*") if "__pycache__" not in p.parts)
    assert after == before, f"the install wrote into the source tree: {set(after) - set(before)}"
    # Import from the installed copy only: no stubs or sources from the tree on the path.
    sys.path.insert(0, str(SITE))
    import motiondb as installed
    import motiondb.v1.clip_service_pb2
    motiondb = installed
    assert pathlib.Path(motiondb.__file__).is_relative_to(SITE), motiondb.__file__
    assert pathlib.Path(motiondb.v1.clip_service_pb2.__file__).is_relative_to(SITE)


def tearDownModule():
    WORK.cleanup()


def raise_then_rest_bvh(frames=150, lift=1.0):
    """An arm raise in the first half, then still: a clip where only a range raises."""
    half = arm_raise_bvh(frames // 2, lift).rsplit("Frame Time: 0.0333333\n", 1)[1].splitlines()
    rest = ["0 90 0 0 0 0 0 0 0 0 0 0"] * (frames - len(half))
    header = arm_raise_bvh(2).split("MOTION\n")[0]
    return (header + f"MOTION\nFrames: {len(half) + len(rest)}\nFrame Time: 0.0333333\n"
            + "\n".join(half + rest) + "\n")


class PackageTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.dir = tempfile.TemporaryDirectory()
        log = os.path.join(cls.dir.name, "server.log")
        cls.log = open(log, "w")
        cls.server = subprocess.Popen(
            [SERVER, "--db", os.path.join(cls.dir.name, "test.sqlite"), "--listen", "127.0.0.1:0", "--http", "off"],
            stdout=subprocess.DEVNULL, stderr=cls.log)
        cls.address = f"127.0.0.1:{logged_port(log, cls.server)}"
        cls.client = motiondb.connect(cls.address)

    @classmethod
    def tearDownClass(cls):
        cls.client.close()
        cls.server.send_signal(signal.SIGTERM)
        code = cls.server.wait(timeout=30)
        cls.log.close()
        cls.dir.cleanup()
        assert code == 0, f"motiondb-server exited with {code} after SIGTERM"

    def test_1_ingest_space_search(self):
        client = self.client
        ids = [client.ingest(arm_raise_bvh(80 + 5 * i, 0.8 + 0.1 * i).encode(),
                             name=f"raise_{i}", tags=["raise"]).clip.clip_id for i in range(4)]
        ids.append(client.ingest(arm_raise_bvh(80, 0.0).encode(), name="still",
                                 tags=["still"]).clip.clip_id)
        with tempfile.TemporaryDirectory() as folder:  # a path, named after the file
            path = pathlib.Path(folder) / "long_take.bvh"
            path.write_text(raise_then_rest_bvh())
            ids.append(client.ingest(path, tags=["take"]).clip.clip_id)
        self.assertEqual(client.clip("long_take").clip_id, ids[-1])
        cmu = pathlib.Path("/usr/share/assimp/models/BVH/01_01.bvh")
        if cmu.exists():  # another skeleton beside the space's
            self.assertEqual(client.ingest(cmu).clip.name, "01_01")
        fbx = pathlib.Path("/usr/share/assimp/models/FBX/animation_with_skeleton.fbx")
        if fbx.exists():  # an FBX file, read by the server's importer: a clip a take
            ingested = client.ingest(fbx, tags=["fbx"])
            self.assertEqual(ingested.clip.name, "animation_with_skeleton")
            self.assertEqual(ingested.clip.frame_count, 21)
            self.assertEqual((ingested.file.format, ingested.file.up_axis), ("fbx", "Y"))
            self.assertEqual(len(ingested.more_takes), 0)
            with tempfile.TemporaryDirectory() as folder:  # and out again as glTF
                glb = pathlib.Path(folder) / "hit.glb"
                header = client.export(ingested.clip.clip_id, glb, first=2, last=9)
                self.assertEqual(header.file_name, "animation_with_skeleton_2-9.glb")
                self.assertEqual(glb.read_bytes()[:4], b"glTF")
        pages = list(client.clips(tag="raise", page_size=3))
        self.assertEqual([[c.name for c in page] for page in pages],
                         [["raise_0", "raise_1", "raise_2"], ["raise_3"]])

        skeleton = client.clip(ids[0]).skeleton_id
        space = client.create_space("arms", skeleton_id=skeleton)
        self.assertGreater(space.report.dims, 0)
        self.assertEqual([s.name for s in client.spaces()], ["arms"])

        results = client.search("arms", clip="raise_1", max_results=10, exclude_query=False)
        self.assertGreater(len(results), 0)
        self.assertEqual((results[0].clip_id, results[0].clip_name), (ids[1], "raise_1"))
        self.assertLessEqual(results[0].start_s, results[0].end_s)
        self.assertGreaterEqual(results[0].score, 0.0)
        ranged = client.search("arms", clip=ids[0], first=0, last=59, max_results=5)
        self.assertNotIn(ids[4], [r.clip_id for r in ranged[:3]])
        by_file = client.search("arms", bvh=arm_raise_bvh(85, 0.9).encode(), max_results=3)
        self.assertEqual(len(by_file), 3)
        # mirror=: the arm of Hips, Shoulder, Elbow has no side to mirror to, and says so.
        with self.assertRaises(motiondb.Error) as raised:
            client.search("arms", clip="raise_1", mirror=True)
        self.assertEqual(raised.exception.code, "FAILED_PRECONDITION")
        self.assertIn("cannot be mirrored", raised.exception.message)

    def test_1c_a_space_over_several_skeletons(self):
        client = self.client
        arm = client.clip("raise_0").skeleton_id  # Hips, Shoulder, Elbow: no legs, no hands
        cmu_file = pathlib.Path("/usr/share/assimp/models/BVH/01_01.bvh")
        skeletons = [arm] + ([client.clip("01_01").skeleton_id] if cmu_file.exists() else [])
        with self.assertRaises(motiondb.Error) as raised:
            client.create_space("rigs", skeleton_ids=skeletons)
        self.assertEqual(raised.exception.code, "FAILED_PRECONDITION")
        self.assertIn(f"skeleton {arm}", raised.exception.message)
        self.assertIn("LeftUpperLeg", raised.exception.message)
        if not cmu_file.exists():
            return
        space = client.create_space("rigs", skeleton_ids=skeletons[1:])
        self.assertEqual((list(space.skeleton_ids), space.representation),
                         (skeletons[1:], "canonical-bones"))
        self.assertIn("LeftUpperLeg", [w.joint for w in space.report.joint_weights])
        results = client.search("rigs", clip="01_01", first=200, last=440, max_results=3)
        self.assertGreater(len(results), 0)
        client.delete_space("rigs")

    def test_1b_skeletons_and_their_humanoid_maps(self):
        client = self.client
        skeleton = client.clip("raise_0").skeleton_id  # Hips, Shoulder, Elbow
        self.assertIn(skeleton, [s.skeleton_id for s in client.skeletons()])
        shown = client.skeleton(skeleton)
        self.assertEqual([j.name for j in shown.joints], ["Hips", "Shoulder", "Elbow"])
        self.assertFalse(shown.humanoid_map.complete)  # said, not an error
        self.assertIn("LeftUpperArm", shown.humanoid_map.missing_slots)
        mapped = client.map_skeleton(skeleton, {"LeftUpperArm": "Shoulder", "leftlowerarm": "Elbow"})
        self.assertEqual({s.slot: (s.joint_name, s.overridden) for s in mapped.humanoid_map.slots},
                         {"Hips": ("Hips", False), "LeftUpperArm": ("Shoulder", True),
                          "LeftLowerArm": ("Elbow", True)})
        with self.assertRaises(motiondb.Error) as raised:
            client.map_skeleton(skeleton, {"LeftHand": "no_such_joint"})
        self.assertEqual(raised.exception.code, "INVALID_ARGUMENT")
        self.assertIn("no_such_joint", raised.exception.message)
        self.assertEqual(client.skeleton(skeleton).humanoid_map, mapped.humanoid_map)
        cleared = client.map_skeleton(skeleton, clear=["LeftUpperArm", "LeftLowerArm"])
        self.assertEqual(cleared.humanoid_map, shown.humanoid_map)
        if pathlib.Path("/usr/share/assimp/models/BVH/01_01.bvh").exists():
            cmu = client.skeleton(client.clip("01_01").skeleton_id).humanoid_map
            self.assertTrue(cmu.complete)
            self.assertIn(("LeftUpperLeg", "LeftUpLeg"), [(s.slot, s.joint_name) for s in cmu.slots])

    def test_2_errors(self):
        with self.assertRaises(motiondb.Error) as raised:
            self.client.search("no-such-space", clip=1)
        self.assertEqual(raised.exception.code, "NOT_FOUND")
        with self.assertRaises(motiondb.Error) as raised:
            self.client.ingest(b"HIERARCHY\nROOT a\n{\nOFFSET 0 0\n", name="bad")
        self.assertEqual(raised.exception.code, "INVALID_ARGUMENT")
        self.assertIn("line", raised.exception.message)
        with self.assertRaises(motiondb.Error) as raised:
            self.client.add_labels([{"clip": "raise_0", "first": 0, "last": 10,
                                     "descriptor": "x", "value": 1.5}])
        self.assertEqual(raised.exception.code, "INVALID_ARGUMENT")
        self.assertIn("labels[0]", raised.exception.message)
        with self.assertRaises(motiondb.Error) as raised:
            self.client.job("job-999")
        self.assertEqual(raised.exception.code, "NOT_FOUND")

    def test_3_labels_propagation(self):
        client = self.client
        added = client.add_labels([
            ("raise_0", 0, 79, "raise-arm", 1.0),
            {"clip": "still", "start_s": 0.0, "end_s": 1.0, "descriptor": "stand", "value": 0.8},
        ])
        self.assertEqual([label.descriptor_name for label in added], ["raise-arm", "stand"])
        self.assertEqual((added[0].first_frame, added[0].last_frame), (0, 79))
        self.assertEqual(added[1].first_frame, 0)
        manual = list(client.list_labels(origin="manual"))
        self.assertEqual(len(manual), 2)
        self.assertEqual([l.label_id for l in client.list_labels(descriptor="stand")],
                         [added[1].label_id])

        job = client.start_propagation("arms", ["raise-arm"], max_results=5)
        self.assertTrue(job.job_id.startswith("job-"))
        updates = list(client.watch(job.job_id))
        self.assertGreaterEqual(len(updates), 1)
        final = updates[-1]
        self.assertTrue(motiondb.job_finished(final))
        self.assertEqual(motiondb.job_state_name(final), "succeeded", final.error)
        self.assertEqual((final.done, final.total), (1, 1))
        self.assertGreater(final.labels_written, 0)
        self.assertEqual(client.job(job.job_id).state, final.state)
        self.assertIn(job.job_id, [j.job_id for j in client.jobs()])
        with self.assertRaises(motiondb.Error) as raised:
            client.cancel(job.job_id)
        self.assertEqual(raised.exception.code, "FAILED_PRECONDITION")
        with self.assertRaises(motiondb.Error) as raised:
            client.start_propagation("arms", ["raise-arm"], rival_share=2)
        self.assertEqual(raised.exception.code, "INVALID_ARGUMENT")
        self.assertIn("rival_share", str(raised.exception))

        found = list(client.find_labels("raise-arm", min_value=0.0))
        self.assertGreater(len(found), 1)
        self.assertEqual([l.value for l in found], sorted((l.value for l in found), reverse=True))
        propagated = [l for l in found if l.job_id == job.job_id]
        self.assertEqual(len(propagated), final.labels_written)
        raised_clips = {"raise_1", "raise_2", "raise_3", "long_take"}
        self.assertTrue(raised_clips & {l.clip_name for l in propagated}, propagated)
        self.assertTrue(all(l.start_s <= l.end_s for l in propagated))
        timeline = client.clip_labels("raise_0")
        self.assertIn(added[0].label_id, [l.label_id for l in timeline])

        self.assertEqual(client.delete_labels(descriptor="stand"), 1)
        self.assertEqual(list(client.find_labels("stand")), [])

    def test_4_curve(self):
        curve = self.client.curve("arms", "raise_0", first=0, last=29, dims=2)
        try:
            import numpy
        except ImportError:
            print("python3-numpy is not installed: checked the curve as a list of lists only",
                  file=sys.stderr)
            self.assertIsInstance(curve, list)
            self.assertEqual(len(curve[0]), 2)
            self.assertGreater(len(curve), 20)
            self.assertTrue(all(isinstance(v, float) for row in curve for v in row))
            return
        self.assertIsInstance(curve, numpy.ndarray)
        self.assertEqual(curve.dtype, numpy.float32)
        self.assertEqual(curve.shape[1], 2)
        self.assertGreater(curve.shape[0], 20)

    def test_5_example_propagates_markup(self):
        with tempfile.TemporaryDirectory() as folder:
            labels, output = pathlib.Path(folder) / "labels.csv", pathlib.Path(folder) / "out.csv"
            labels.write_text("clip,start,end,descriptor,value\n"
                              "raise_2,0,89,lift,0.9\n"
                              "long_take,0,74,lift,1\n")
            run = subprocess.run(
                [sys.executable, str(REPO / "client" / "python" / "examples" / "propagate_markup.py"),
                 "--server", self.address, "--space", "example-space", "--max-results", "4",
                 str(labels), "-o", str(output)],
                env=dict(os.environ, PYTHONPATH=str(SITE)), capture_output=True, text=True,
                timeout=300)
            self.assertEqual(run.returncode, 0, run.stdout + run.stderr)
            self.assertIn("added 2 manual labels: lift", run.stdout)
            self.assertIn("built space example-space", run.stdout)
            self.assertRegex(run.stdout, r"job-[0-9]+ succeeded: 2/2 labels")
            with open(output, newline="") as file:
                rows = list(csv.DictReader(file))
            self.assertRegex(run.stdout, rf"wrote {len(rows)} propagated labels")
            self.assertGreater(len(rows), 0)
            self.assertEqual({r["descriptor"] for r in rows}, {"lift"})
            for row in rows:
                self.assertLessEqual(int(row["start"]), int(row["end"]))
                self.assertTrue(0.0 <= float(row["value"]) <= 1.0)
            # The output is what `motiondb labels import` (and the example) reads back.
            self.assertEqual(list(rows[0]), ["clip", "start", "end", "descriptor", "value"])


class TokenTest(unittest.TestCase):
    def test_token_is_sent_on_every_call(self):
        with tempfile.TemporaryDirectory() as folder:
            token_file = pathlib.Path(folder) / "token"
            token_file.write_text("py-secret-token\n")
            log_path = os.path.join(folder, "server.log")
            with open(log_path, "w") as log:
                server = subprocess.Popen(
                    [SERVER, "--db", os.path.join(folder, "t.sqlite"), "--listen", "127.0.0.1:0", "--http", "off",
                     "--auth-token-file", str(token_file)], stdout=subprocess.DEVNULL, stderr=log)
                try:
                    address = f"127.0.0.1:{logged_port(log_path, server)}"
                    with motiondb.connect(address) as anonymous:
                        with self.assertRaises(motiondb.Error) as raised:
                            anonymous.server_info()
                        self.assertEqual(raised.exception.code, "UNAUTHENTICATED")
                    with motiondb.connect(address, token="py-secret-token") as client:
                        self.assertTrue(client.server_info().auth_required)
                        self.assertEqual(list(client.clips()), [[]])
                        self.assertEqual(list(client.find_labels("anything")), [])
                finally:
                    server.send_signal(signal.SIGTERM)
                    self.assertEqual(server.wait(timeout=30), 0)


class AnswerLimitTest(unittest.TestCase):
    """A server whose answers are at most 1 MiB (--max-answer-mb 1): export() streams a take whose
    BVH is past the limit, and clip_labels() reads every page of a timeline past it."""

    def test_export_streams_past_the_limit_and_timelines_come_in_pages(self):
        import grpc
        from motiondb.v1 import clip_service_pb2, clip_service_pb2_grpc, common_pb2
        with tempfile.TemporaryDirectory() as folder:
            log_path = os.path.join(folder, "server.log")
            with open(log_path, "w") as log:
                server = subprocess.Popen(
                    [SERVER, "--db", os.path.join(folder, "t.sqlite"), "--listen", "127.0.0.1:0",
                     "--http", "off", "--max-answer-mb", "1"],
                    stdout=subprocess.DEVNULL, stderr=log)
                try:
                    address = f"127.0.0.1:{logged_port(log_path, server)}"
                    with motiondb.connect(address) as client:
                        frames = 40000  # about 5 MB of BVH, its bound 10 MB
                        clip_id = client.ingest(arm_raise_bvh(frames).encode(),
                                                name="long").clip.clip_id
                        stub = clip_service_pb2_grpc.ClipServiceStub(
                            grpc.insecure_channel(address))
                        with self.assertRaises(grpc.RpcError) as raised:
                            stub.ExportClip(clip_service_pb2.ExportClipRequest(
                                clip=common_pb2.ClipRange(clip_id=clip_id)), timeout=30)
                        self.assertEqual(raised.exception.code(),
                                         grpc.StatusCode.RESOURCE_EXHAUSTED)
                        self.assertIn("--max-answer-mb", raised.exception.details())

                        path = pathlib.Path(folder) / "long.bvh"
                        first = client.export("long", path)
                        self.assertEqual((first.file_name, first.first_frame, first.last_frame),
                                         ("long.bvh", 0, frames - 1))
                        self.assertFalse(first.bvh)
                        self.assertFalse(path.with_name("long.bvh.tmp").exists())
                        text = path.read_text()
                        self.assertGreater(len(text), 1 << 20)
                        self.assertIn(f"Frames: {frames}\n", text)
                        self.assertEqual(len(text.split("MOTION\n")[1].splitlines()), 2 + frames)
                        # A range: the unary export's text, written by the stream.
                        ranged = pathlib.Path(folder) / "range.bvh"
                        client.export(clip_id, ranged, first=100, last=199)
                        unary = stub.ExportClip(clip_service_pb2.ExportClipRequest(
                            clip=common_pb2.ClipRange(clip_id=clip_id, first_frame=100,
                                                      last_frame=199)), timeout=30)
                        self.assertEqual(ranged.read_bytes(), unary.bvh)
                        # A failed export leaves no file.
                        with self.assertRaises(motiondb.Error) as failed:
                            client.export(clip_id, pathlib.Path(folder) / "bad.bvh", last=frames)
                        self.assertEqual(failed.exception.code, "INVALID_ARGUMENT")
                        self.assertEqual(sorted(p.name for p in pathlib.Path(folder).iterdir()
                                                if p.suffix in (".bvh", ".tmp")),
                                         ["long.bvh", "range.bvh"])

                        for start in range(0, 1500, 500):  # a batch's answer is bounded too
                            client.add_labels([("long", f, f + 5, "step")
                                               for f in range(start, start + 500)])
                        timeline = client.clip_labels("long")
                        self.assertEqual([label.first_frame for label in timeline],
                                         list(range(1500)))
                finally:
                    server.send_signal(signal.SIGTERM)
                    self.assertEqual(server.wait(timeout=30), 0)


class TlsTest(unittest.TestCase):
    def test_connects_with_the_servers_certificate(self):
        if shutil.which("openssl") is None:
            self.skipTest("openssl is not installed; the TLS test needs it to make a certificate")
        with tempfile.TemporaryDirectory() as folder:
            cert, key = pathlib.Path(folder) / "cert.pem", pathlib.Path(folder) / "key.pem"
            # As the C++ server tests make theirs (tests/test_data.cc): self-signed, for
            # localhost and 127.0.0.1, so that the client checks the name it dials.
            subprocess.run(
                ["openssl", "req", "-x509", "-newkey", "rsa:2048", "-nodes", "-days", "1",
                 "-subj", "/CN=localhost", "-addext", "subjectAltName=DNS:localhost,IP:127.0.0.1",
                 "-keyout", str(key), "-out", str(cert)], check=True, capture_output=True)
            log_path = os.path.join(folder, "server.log")
            with open(log_path, "w") as log:
                server = subprocess.Popen(
                    [SERVER, "--db", os.path.join(folder, "t.sqlite"), "--listen", "127.0.0.1:0",
                     "--http", "off", "--tls-cert", str(cert), "--tls-key", str(key)],
                    stdout=subprocess.DEVNULL, stderr=log)
                try:
                    address = f"127.0.0.1:{logged_port(log_path, server)}"
                    with motiondb.connect(address, tls_ca=cert) as client:  # a path
                        self.assertTrue(client.server_info().tls)
                        self.assertEqual(list(client.clips()), [[]])
                    with motiondb.connect(address, tls_ca=cert.read_bytes()) as client:  # bytes
                        self.assertTrue(client.server_info().tls)
                    # Without TLS, or trusting only the system's roots, no connection comes up.
                    for options in ({}, {"tls": True}):
                        with self.assertRaises(motiondb.Error) as raised:
                            motiondb.connect(address, ready_timeout=2, **options)
                        self.assertEqual(raised.exception.code, "UNAVAILABLE", options)
                finally:
                    server.send_signal(signal.SIGTERM)
                    self.assertEqual(server.wait(timeout=30), 0)


if __name__ == "__main__":
    SERVER, REPO = sys.argv[1], pathlib.Path(sys.argv[2]).resolve()
    unittest.main(argv=sys.argv[:1], verbosity=2)
