#!/usr/bin/python3
"""A motiondb client in Python, with Debian's python3-grpcio and stubs generated from proto/.

Generate the stubs (the build does this into build/python), then run:

    PYTHONPATH=build/python /usr/bin/python3 client/python/motiondb_example.py \
        --server 127.0.0.1:50051 walk.bvh run.bvh

It uploads the files, builds a space named "example" if there is none, searches with the
first file as the query and prints the ranked time ranges.
"""
import argparse
import os
import pathlib
import sys

import grpc

from motiondb.v1 import clip_service_pb2, clip_service_pb2_grpc
from motiondb.v1 import common_pb2
from motiondb.v1 import search_service_pb2, search_service_pb2_grpc
from motiondb.v1 import server_service_pb2, server_service_pb2_grpc
from motiondb.v1 import space_service_pb2, space_service_pb2_grpc


def connect(address, token=None):
    """A channel to the server; with a token every call carries it as a bearer token."""
    channel = grpc.insecure_channel(address)
    metadata = [("authorization", f"Bearer {token}")] if token else []
    return channel, metadata


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--server", default=os.environ.get("MOTIONDB_SERVER", "127.0.0.1:50051"))
    parser.add_argument("--token", default=None)
    parser.add_argument("--space", default="example")
    parser.add_argument("files", nargs="+", type=pathlib.Path)
    args = parser.parse_args()

    channel, metadata = connect(args.server, args.token)
    clips = clip_service_pb2_grpc.ClipServiceStub(channel)
    spaces = space_service_pb2_grpc.SpaceServiceStub(channel)
    search = search_service_pb2_grpc.SearchServiceStub(channel)
    server = server_service_pb2_grpc.ServerServiceStub(channel)

    info = server.GetServerInfo(server_service_pb2.GetServerInfoRequest(), metadata=metadata)
    print(f"motiondb-server {info.version}: {info.counts.clips} clips")

    ids = []
    for path in args.files:
        try:
            reply = clips.IngestClip(
                clip_service_pb2.IngestClipRequest(file_name=path.name, bvh=path.read_bytes()),
                metadata=metadata)
        except grpc.RpcError as error:  # e.g. INVALID_ARGUMENT naming the bad line
            print(f"{path}: {error.code().name}: {error.details()}", file=sys.stderr)
            continue
        ids.append(reply.clip.clip_id)
        # Run again on the same files, the example stores nothing twice: an unchanged file is
        # skipped (on_conflict unset), and a changed one under a stored name is refused.
        skipped = reply.result == clip_service_pb2.INGEST_RESULT_SKIPPED
        print(f"{path} -> clip {reply.clip.clip_id}, {reply.clip.frame_count} frames"
              + (" (stored before; skipped)" if skipped else ""))
        for warning in reply.warnings:  # e.g. identical content to another clip
            print(f"  warning: {warning}")
    if not ids:
        return 1

    try:
        spaces.GetSpace(space_service_pb2.GetSpaceRequest(name=args.space), metadata=metadata)
    except grpc.RpcError as error:
        if error.code() != grpc.StatusCode.NOT_FOUND:
            raise
        first = clips.GetClip(clip_service_pb2.GetClipRequest(clip_id=ids[0]), metadata=metadata)
        space = spaces.CreateSpace(
            space_service_pb2.CreateSpaceRequest(name=args.space, skeleton_id=first.skeleton_id),
            metadata=metadata)
        print(f"built space {space.name}: {space.report.dims} dims")

    response = search.Search(
        search_service_pb2.SearchRequest(space=args.space,
                                         clip=common_pb2.ClipRange(clip_id=ids[0]),
                                         max_results=10),
        metadata=metadata)
    for rank, result in enumerate(response.results, 1):
        print(f"{rank:3d}  {result.clip_name:40s} {result.start_s:8.3f}-{result.end_s:8.3f} s"
              f"  frames {result.start_frame}-{result.end_frame}  score {result.score:.4f}")
    print(f"{len(response.results)} results in {response.timings.request_ms:.2f} ms")
    return 0


if __name__ == "__main__":
    sys.exit(main())
