#!/usr/bin/python3
"""Calls at a thread limit: refused or queued. Starts SERVER --threads N on a fresh database with
Debian's assimp-testmodels clips and a space, then runs CLIENTS threads searching for SECONDS,
and prints how many calls succeeded, how many were refused (RESOURCE_EXHAUSTED), and the
latency percentiles of the successful ones.

    PYTHONPATH=build/python bench/thread_limit_bench.py SERVER [--threads 4] [--clients 16]
"""
import argparse, concurrent.futures, glob, os, socket, subprocess, sys, tempfile, threading, time

import grpc
from motiondb.v1 import clip_service_pb2, clip_service_pb2_grpc, common_pb2
from motiondb.v1 import search_service_pb2, search_service_pb2_grpc
from motiondb.v1 import space_service_pb2, space_service_pb2_grpc


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("server")
    parser.add_argument("--threads", type=int, default=4)
    parser.add_argument("--clients", type=int, default=16)
    parser.add_argument("--seconds", type=float, default=10)
    args = parser.parse_args()
    work = tempfile.mkdtemp()
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    server = subprocess.Popen([args.server, "--db", f"{work}/db.sqlite", "--listen",
                               f"127.0.0.1:{port}", "--http", "off", "--threads", str(args.threads),
                               "--quiet"],
                              stderr=subprocess.DEVNULL)
    try:
        channel = grpc.insecure_channel(f"127.0.0.1:{port}")
        grpc.channel_ready_future(channel).result(timeout=30)
        clips = clip_service_pb2_grpc.ClipServiceStub(channel)
        files = sorted(glob.glob("/usr/share/assimp/models/BVH/0*.bvh"))
        ids = [clips.IngestClip(clip_service_pb2.IngestClipRequest(
            file_name=os.path.basename(f), bvh=open(f, "rb").read())).clip.clip_id for f in files]
        space_service_pb2_grpc.SpaceServiceStub(channel).CreateSpace(
            space_service_pb2.CreateSpaceRequest(name="bench", training=[common_pb2.ClipRange(clip_id=ids[0])]))
        search = search_service_pb2_grpc.SearchServiceStub(channel)
        results, lock, stop = [], threading.Lock(), time.monotonic() + args.seconds

        def client(k):
            own = search_service_pb2_grpc.SearchServiceStub(grpc.insecure_channel(f"127.0.0.1:{port}"))
            while time.monotonic() < stop:
                start = time.monotonic()
                request = search_service_pb2.SearchRequest(
                    space="bench", clip=common_pb2.ClipRange(clip_id=ids[k % len(ids)], first_frame=100, last_frame=220))
                try:
                    own.Search(request, timeout=30)
                    code = "OK"
                except grpc.RpcError as error:
                    code = error.code().name
                with lock:
                    results.append((code, time.monotonic() - start))

        with concurrent.futures.ThreadPoolExecutor(args.clients) as pool:
            list(pool.map(client, range(args.clients)))
        ok = sorted(t for c, t in results if c == "OK")
        codes = {}
        for c, _ in results:
            codes[c] = codes.get(c, 0) + 1
        pct = lambda p: 1000 * ok[min(len(ok) - 1, int(p * len(ok)))] if ok else float("nan")
        print(f"{args.server} --threads {args.threads}, {args.clients} clients, {args.seconds:.0f} s: "
              f"{codes}; OK p50 {pct(0.5):.1f} ms, p99 {pct(0.99):.1f} ms")
    finally:
        server.terminate()
        server.wait()


if __name__ == "__main__":
    main()
