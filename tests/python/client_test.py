#!/usr/bin/python3
"""The server, driven by a client written against generated Python stubs (python3-grpcio).

Starts the real motiondb-server on a free loopback port with a temporary database.
usage: client_test.py SERVER_BINARY EXAMPLE_SCRIPT   (PYTHONPATH must hold the stubs)
"""
import os
import pathlib
import signal
import subprocess
import sys
import tempfile
import unittest

import grpc

from motiondb.v1 import clip_service_pb2, clip_service_pb2_grpc
from motiondb.v1 import common_pb2
from motiondb.v1 import search_service_pb2, search_service_pb2_grpc
from motiondb.v1 import server_service_pb2, server_service_pb2_grpc
from motiondb.v1 import space_service_pb2, space_service_pb2_grpc
from server_fixtures import arm_raise_bvh, logged_port

SERVER = EXAMPLE = None


class ServerTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.dir = tempfile.TemporaryDirectory()
        log = os.path.join(cls.dir.name, "server.log")
        # Port 0: the server picks a free port itself and logs it, so no other process can take
        # it between choosing and binding.
        cls.server = subprocess.Popen(
            [SERVER, "--db", os.path.join(cls.dir.name, "test.sqlite"), "--listen", "127.0.0.1:0", "--http", "off"],
            stdout=subprocess.DEVNULL, stderr=open(log, "w"))
        cls.port = logged_port(log, cls.server)
        cls.address = f"127.0.0.1:{cls.port}"
        cls.channel = grpc.insecure_channel(cls.address)
        grpc.channel_ready_future(cls.channel).result(timeout=30)
        cls.clips = clip_service_pb2_grpc.ClipServiceStub(cls.channel)
        cls.spaces = space_service_pb2_grpc.SpaceServiceStub(cls.channel)
        cls.search = search_service_pb2_grpc.SearchServiceStub(cls.channel)
        cls.info = server_service_pb2_grpc.ServerServiceStub(cls.channel)

    @classmethod
    def tearDownClass(cls):
        cls.channel.close()
        cls.server.send_signal(signal.SIGTERM)
        code = cls.server.wait(timeout=30)
        cls.dir.cleanup()
        assert code == 0, f"motiondb-server exited with {code} after SIGTERM"

    def ingest(self, name, text, tags=()):
        return self.clips.IngestClip(clip_service_pb2.IngestClipRequest(
            file_name=name, bvh=text.encode(), tags=list(tags)), timeout=30)

    def test_1_ingest_space_and_search(self):
        ids = [self.ingest(f"raise_{i}.bvh", arm_raise_bvh(80 + 5 * i, 0.8 + 0.1 * i), ["raise"])
               .clip.clip_id for i in range(4)]
        ids.append(self.ingest("still.bvh", arm_raise_bvh(80, 0.0), ["still"]).clip.clip_id)
        listed = self.clips.ListClips(clip_service_pb2.ListClipsRequest(tag="raise"), timeout=10)
        self.assertEqual([c.name for c in listed.clips], [f"raise_{i}" for i in range(4)])
        clip = self.clips.GetClip(clip_service_pb2.GetClipRequest(clip_id=ids[0]), timeout=10)
        self.assertEqual(clip.frame_count, 80)
        self.assertAlmostEqual(clip.fps, 30.0, places=3)

        space = self.spaces.CreateSpace(space_service_pb2.CreateSpaceRequest(
            name="arms", skeleton_id=clip.skeleton_id), timeout=60)
        self.assertGreater(space.report.dims, 0)
        self.assertAlmostEqual(sum(space.report.explained_variance), 1.0, places=6)

        response = self.search.Search(search_service_pb2.SearchRequest(
            space="arms", clip=common_pb2.ClipRange(clip_id=ids[1]), max_results=10,
            exclude_query=False), timeout=30)  # kept: the check is that it finds itself
        self.assertGreater(len(response.results), 0)
        self.assertEqual(response.results[0].clip_id, ids[1], "a clip finds itself first")
        self.assertNotIn(ids[-1], [r.clip_id for r in response.results[:4]])
        self.assertGreaterEqual(response.timings.total_ms, 0)

        exported = self.clips.ExportClip(clip_service_pb2.ExportClipRequest(
            clip=common_pb2.ClipRange(clip_id=ids[0], first_frame=10, last_frame=19)), timeout=10)
        self.assertIn(b"Frames: 10", exported.bvh)

    def test_2_errors_have_real_codes(self):
        def code(call):
            with self.assertRaises(grpc.RpcError) as raised:
                call()
            return raised.exception.code(), raised.exception.details()

        status, details = code(lambda: self.ingest("bad.bvh", "HIERARCHY\nROOT a\n{\nOFFSET 0 0\n"))
        self.assertEqual(status, grpc.StatusCode.INVALID_ARGUMENT)
        self.assertIn("line", details)
        status, _ = code(lambda: self.clips.GetClip(
            clip_service_pb2.GetClipRequest(clip_id=999999), timeout=10))
        self.assertEqual(status, grpc.StatusCode.NOT_FOUND)
        status, _ = code(lambda: self.search.Search(search_service_pb2.SearchRequest(
            space="no-such-space", clip=common_pb2.ClipRange(clip_id=1)), timeout=10))
        self.assertEqual(status, grpc.StatusCode.NOT_FOUND)

    def test_3_example_script_runs(self):
        with tempfile.TemporaryDirectory() as work:
            files = []
            for i in range(2):
                path = pathlib.Path(work) / f"example_{i}.bvh"
                path.write_text(arm_raise_bvh(70 + 10 * i))
                files.append(str(path))
            run = subprocess.run([sys.executable, EXAMPLE, "--server", self.address,
                                  "--space", "arms", *files],
                                 capture_output=True, text=True, timeout=120)
            self.assertEqual(run.returncode, 0, run.stderr)
            self.assertIn("results in", run.stdout)

    def test_4_server_info(self):
        info = self.info.GetServerInfo(server_service_pb2.GetServerInfoRequest(), timeout=10)
        self.assertTrue(info.version)
        self.assertGreaterEqual(info.counts.clips, 5)

    def test_5_names_conflicts_and_updates(self):
        def upload(bvh, on_conflict=clip_service_pb2.ON_CONFLICT_UNSPECIFIED):
            return self.clips.IngestClip(clip_service_pb2.IngestClipRequest(
                file_name="take_001.bvh", name="py_session/take_001", bvh=bvh.encode(),
                on_conflict=on_conflict), timeout=30)

        take, retake = arm_raise_bvh(60, 0.5), arm_raise_bvh(60, 0.6)
        first = upload(take)
        self.assertEqual(first.result, clip_service_pb2.INGEST_RESULT_STORED)
        self.assertEqual(first.clip.name, "py_session/take_001")
        self.assertEqual(len(first.clip.content_hash), 64)
        again = upload(take)  # the same file again: skipped by default
        self.assertEqual(again.result, clip_service_pb2.INGEST_RESULT_SKIPPED)
        self.assertEqual(again.clip.clip_id, first.clip.clip_id)
        with self.assertRaises(grpc.RpcError) as raised:
            upload(retake)  # other content under the name: refused by default
        self.assertEqual(raised.exception.code(), grpc.StatusCode.ALREADY_EXISTS)
        self.assertIn("on_conflict", raised.exception.details())
        replaced = upload(retake, clip_service_pb2.ON_CONFLICT_REPLACE)
        self.assertEqual(replaced.result, clip_service_pb2.INGEST_RESULT_REPLACED)
        self.assertEqual(replaced.replaced_clip_id, first.clip.clip_id)

        updated = self.clips.UpdateClip(clip_service_pb2.UpdateClipRequest(
            clip_id=replaced.clip.clip_id, name="py_session/take_001_best", add_tags=["best"]),
            timeout=10)
        self.assertEqual(updated.name, "py_session/take_001_best")
        self.assertEqual(list(updated.tags), ["best"])
        exported = self.clips.ExportClip(clip_service_pb2.ExportClipRequest(
            clip=common_pb2.ClipRange(clip_id=updated.clip_id)), timeout=10)
        self.assertEqual(exported.file_name, "py_session_take_001_best.bvh")


if __name__ == "__main__":
    SERVER, EXAMPLE = sys.argv[1], sys.argv[2]
    unittest.main(argv=sys.argv[:1], verbosity=2)
