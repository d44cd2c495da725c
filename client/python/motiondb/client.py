"""The motiondb client: one gRPC channel and a method per task, over the generated stubs."""
from __future__ import annotations

import functools
import os
import pathlib
from typing import Any, Dict, Iterable, Iterator, List, Optional, Sequence, Tuple, Union

import grpc

from motiondb.v1 import clip_service_pb2, clip_service_pb2_grpc
from motiondb.v1 import common_pb2
from motiondb.v1 import job_service_pb2, job_service_pb2_grpc
from motiondb.v1 import label_service_pb2, label_service_pb2_grpc
from motiondb.v1 import search_service_pb2, search_service_pb2_grpc
from motiondb.v1 import server_service_pb2, server_service_pb2_grpc
from motiondb.v1 import space_service_pb2, space_service_pb2_grpc

try:  # curves as numpy arrays when numpy is there
    import numpy
except ImportError:  # pragma: no cover - depends on the system
    numpy = None

# The messages the methods return, re-exported for type hints.
Clip = clip_service_pb2.Clip
Space = space_service_pb2.Space
SearchResult = search_service_pb2.SearchResult
Label = label_service_pb2.Label
Job = job_service_pb2.Job
Skeleton = clip_service_pb2.Skeleton
SkeletonDetail = clip_service_pb2.SkeletonDetail

ClipRef = Union[int, str]  # a clip's id, or its name
PathOrBytes = Union[str, os.PathLike, bytes]

_STREAM_ABOVE = 8 << 20  # files larger than this are uploaded in chunks (IngestClipStream)
_CHUNK = 1 << 20
_FINAL_JOB_STATES = frozenset({job_service_pb2.JOB_STATE_SUCCEEDED, job_service_pb2.JOB_STATE_FAILED,
                               job_service_pb2.JOB_STATE_CANCELLED,
                               job_service_pb2.JOB_STATE_INTERRUPTED})
_ORIGINS = {None: label_service_pb2.LABEL_ORIGIN_UNSPECIFIED,
            "manual": label_service_pb2.LABEL_ORIGIN_MANUAL,
            "propagated": label_service_pb2.LABEL_ORIGIN_PROPAGATED}


class Error(Exception):
    """A call the server (or the channel) failed.

    code is the gRPC status code's name ("NOT_FOUND", "INVALID_ARGUMENT", ...), message the
    server's text (which names the bad field or item), status the grpc.StatusCode itself.
    """

    def __init__(self, code: str, message: str, status: Optional[grpc.StatusCode] = None):
        super().__init__(f"{code}: {message}")
        self.code = code
        self.message = message
        self.status = status

    @classmethod
    def from_rpc(cls, error: grpc.RpcError) -> "Error":
        status = error.code() if hasattr(error, "code") else None
        details = error.details() if hasattr(error, "details") else str(error)
        return cls(status.name if status is not None else "UNKNOWN", details or "", status)


def _rpc(method):
    """Turns a grpc.RpcError raised by the wrapped method into an Error."""

    @functools.wraps(method)
    def wrapped(*args, **kwargs):
        try:
            return method(*args, **kwargs)
        except grpc.RpcError as error:
            raise Error.from_rpc(error) from None

    return wrapped


def job_state_name(job: Job) -> str:
    """A job's state in lower case without the prefix: "queued", "running", "succeeded", ..."""
    return job_service_pb2.JobState.Name(job.state).removeprefix("JOB_STATE_").lower()


def job_finished(job: Job) -> bool:
    """Whether the job has ended (succeeded, failed, cancelled or interrupted)."""
    return job.state in _FINAL_JOB_STATES


def _read(source: PathOrBytes) -> Tuple[bytes, Optional[str]]:
    """The bytes of a BVH file given as a path or as its contents, and its file name if any."""
    if isinstance(source, (bytes, bytearray, memoryview)):
        return bytes(source), None
    path = pathlib.Path(source)
    return path.read_bytes(), path.name


class Client:
    """A connection to a motiondb server. Make one with motiondb.connect().

    Every method raises motiondb.Error when the call fails. timeout (seconds) bounds each unary
    call; streams (watch) are not bounded. Usable as a context manager (closes the channel).
    """

    def __init__(self, channel: grpc.Channel, token: Optional[str] = None,
                 timeout: Optional[float] = 300.0):
        self._channel = channel
        self._metadata = [("authorization", f"Bearer {token}")] if token else []
        self.timeout = timeout
        self._clips = clip_service_pb2_grpc.ClipServiceStub(channel)
        self._spaces = space_service_pb2_grpc.SpaceServiceStub(channel)
        self._search = search_service_pb2_grpc.SearchServiceStub(channel)
        self._labels = label_service_pb2_grpc.LabelServiceStub(channel)
        self._jobs = job_service_pb2_grpc.JobServiceStub(channel)
        self._server = server_service_pb2_grpc.ServerServiceStub(channel)

    # -- the connection -------------------------------------------------------------------------
    def close(self) -> None:
        """Closes the channel."""
        self._channel.close()

    def __enter__(self) -> "Client":
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def _call(self, method, request):
        return method(request, metadata=self._metadata, timeout=self.timeout)

    @_rpc
    def server_info(self) -> server_service_pb2.ServerInfo:
        """The server's version, uptime and counts (GetServerInfo)."""
        return self._call(self._server.GetServerInfo, server_service_pb2.GetServerInfoRequest())

    # -- clips ----------------------------------------------------------------------------------
    @_rpc
    def ingest(self, source: PathOrBytes, name: Optional[str] = None, tags: Iterable[str] = (),
               on_conflict: Optional[str] = None,
               file_name: Optional[str] = None) -> clip_service_pb2.IngestClipResponse:
        """Stores a motion file (BVH, FBX, .glb or .gltf), given as a path or as its bytes;
        returns the IngestClipResponse (.clip the clip as stored, .result, .warnings; for an FBX
        or glTF file of several takes .more_takes the second and later, each a clip NAME/TAKE;
        .file the file's format, unit and up axis).

        name defaults to the file name without folders and extension (bytes need name or
        file_name).
        on_conflict: None (skip an identical clip of the name, refuse another), "error", "skip"
        or "replace". Files over 8 MB go up in chunks (IngestClipStream).
        """
        data, path_name = _read(source)
        file_name = file_name or path_name or (f"{name.replace('/', '_')}.bvh" if name else None)
        if not file_name:
            raise ValueError("ingest of bytes needs name= or file_name=")
        conflict = clip_service_pb2.OnConflict.Value(
            f"ON_CONFLICT_{(on_conflict or 'unspecified').upper()}")
        if len(data) <= _STREAM_ABOVE:
            return self._call(self._clips.IngestClip, clip_service_pb2.IngestClipRequest(
                file_name=file_name, name=name or "", bvh=data, tags=list(tags),
                on_conflict=conflict))

        def chunks():
            yield clip_service_pb2.IngestClipStreamRequest(
                file_name=file_name, name=name or "", tags=list(tags), on_conflict=conflict,
                chunk=data[:_CHUNK])
            for offset in range(_CHUNK, len(data), _CHUNK):
                yield clip_service_pb2.IngestClipStreamRequest(chunk=data[offset:offset + _CHUNK])

        return self._clips.IngestClipStream(chunks(), metadata=self._metadata,
                                            timeout=self.timeout)

    def clips(self, tag: Optional[str] = None, name_contains: Optional[str] = None,
              sort: Optional[str] = None, page_size: int = 100) -> Iterator[List[Clip]]:
        """The library's clips, a page (a list of Clip) at a time: `for page in client.clips():`.
        Filters: a tag, a text the name holds; sort "id" (default), "name" or "created"."""
        token = ""
        while True:
            response = self._list_clips(clip_service_pb2.ListClipsRequest(
                page_size=page_size, page_token=token, tag=tag or "",
                name_contains=name_contains or "", sort=sort or ""))
            yield list(response.clips)
            token = response.next_page_token
            if not token:
                return

    @_rpc
    def _list_clips(self, request):
        return self._call(self._clips.ListClips, request)

    @_rpc
    def clip(self, clip: ClipRef) -> Clip:
        """One clip, by id or name (with its joint names)."""
        return self._call(self._clips.GetClip,
                          clip_service_pb2.GetClipRequest(clip_id=self.clip_id(clip)))

    @_rpc
    def delete_clip(self, clip: ClipRef) -> None:
        """Deletes a clip, its projections and its labels."""
        self._call(self._clips.DeleteClip,
                   clip_service_pb2.DeleteClipRequest(clip_id=self.clip_id(clip)))

    @_rpc
    def export(self, clip: ClipRef, path: Union[str, os.PathLike], first: Optional[int] = None,
               last: Optional[int] = None,
               format: Optional[str] = None) -> clip_service_pb2.ExportClipResponse:
        """Writes a clip, or its frames first..last (a hit), as a file at path
        (ExportClipStream: written as its pieces arrive, into path + ".tmp" renamed into place
        once whole). format: "bvh", "gltf" or "glb"; None: by path's extension (.gltf, .glb),
        else BVH. Returns the first message without its bytes: file_name (the server's
        suggestion), first_frame, last_frame."""
        target = pathlib.Path(path)
        if format is None:
            suffix = target.suffix.lower()
            format = suffix[1:] if suffix in (".gltf", ".glb") else "bvh"
        request = clip_service_pb2.ExportClipRequest(clip=self._range(clip, first, last),
                                                     format=format)
        partial = target.with_name(target.name + ".tmp")
        header = None
        try:
            with open(partial, "wb") as out:
                for piece in self._clips.ExportClipStream(request, metadata=self._metadata,
                                                          timeout=self.timeout):
                    if header is None:
                        header = clip_service_pb2.ExportClipResponse(
                            file_name=piece.file_name, first_frame=piece.first_frame,
                            last_frame=piece.last_frame)
                    out.write(piece.bvh)
            os.replace(partial, target)
        finally:
            partial.unlink(missing_ok=True)
        return header

    # -- skeletons -----------------------------------------------------------------------------
    @_rpc
    def skeletons(self) -> List[Skeleton]:
        """Every skeleton (the joint hierarchy clips and spaces share), in id order."""
        return list(self._call(self._clips.ListSkeletons,
                               clip_service_pb2.ListSkeletonsRequest()).skeletons)

    @_rpc
    def skeleton(self, skeleton_id: int) -> SkeletonDetail:
        """A skeleton's joints and its humanoid map: .humanoid_map.slots (each .slot, .joint_name,
        .overridden), .missing_slots (empty when .complete) and .mirror_pairs."""
        return self._call(self._clips.GetSkeleton,
                          clip_service_pb2.GetSkeletonRequest(skeleton_id=skeleton_id))

    @_rpc
    def map_skeleton(self, skeleton_id: int, slots: Optional[Dict[str, str]] = None,
                     clear: Iterable[str] = ()) -> SkeletonDetail:
        """Gives slots of a skeleton's humanoid map their joints by hand ({"LeftHand": "hand_l"}),
        or hands slots back to the automatic map (clear), stored; returns the skeleton as
        skeleton() does. A bad slot or joint raises Error (INVALID_ARGUMENT) and changes
        nothing."""
        request = clip_service_pb2.MapSkeletonRequest(skeleton_id=skeleton_id, clear=list(clear))
        for slot, joint in (slots or {}).items():
            request.set.add(slot=slot, joint=joint)
        return self._call(self._clips.MapSkeleton, request)

    def clip_id(self, clip: ClipRef) -> int:
        """A clip's id: an int is one already; a str is looked up as the clip's exact name
        (Error NOT_FOUND when no clip has it)."""
        if isinstance(clip, int):
            return clip
        for page in self.clips(name_contains=clip, page_size=1000):
            for found in page:
                if found.name == clip:
                    return found.clip_id
        raise Error("NOT_FOUND", f"no clip named {clip!r}", grpc.StatusCode.NOT_FOUND)

    # -- spaces ---------------------------------------------------------------------------------
    @_rpc
    def create_space(self, name: str, skeleton_id: Optional[int] = None,
                     training: Iterable[Union[ClipRef, Tuple[ClipRef, int, int]]] = (),
                     skeleton_ids: Iterable[int] = (), **params: Any) -> Space:
        """Builds a space (CreateSpace). training: clips, or (clip, first, last) ranges; empty
        trains on every clip of the skeleton. skeleton_ids, instead of skeleton_id: a space over
        several skeletons (canonical bone directions), holding the clips of each. params: the
        other CreateSpaceRequest fields (sample_rate, weight_preset, keep_heading, ...)."""
        ranges = [self._range(*(item if isinstance(item, tuple) else (item,))) for item in training]
        request = space_service_pb2.CreateSpaceRequest(name=name, training=ranges,
                                                       skeleton_ids=list(skeleton_ids), **params)
        if skeleton_id is not None:
            request.skeleton_id = skeleton_id
        return self._call(self._spaces.CreateSpace, request)

    @_rpc
    def space(self, name: str) -> Space:
        """A space with its build report and index (GetSpace)."""
        return self._call(self._spaces.GetSpace, space_service_pb2.GetSpaceRequest(name=name))

    def spaces(self) -> List[Space]:
        """Every space."""
        result, token = [], ""
        while True:
            response = self._list_spaces(token)
            result.extend(response.spaces)
            token = response.next_page_token
            if not token:
                return result

    @_rpc
    def _list_spaces(self, token):
        return self._call(self._spaces.ListSpaces,
                          space_service_pb2.ListSpacesRequest(page_token=token))

    @_rpc
    def delete_space(self, name: str) -> None:
        """Deletes a space."""
        self._call(self._spaces.DeleteSpace, space_service_pb2.DeleteSpaceRequest(name=name))

    @_rpc
    def curve(self, space: str, clip: ClipRef, first: Optional[int] = None,
              last: Optional[int] = None, dims: int = 3):
        """A clip's (range's) motion curve: its first dims coordinates in the space, one row per
        sample at the space's rate. A numpy float32 array of shape (frames, dims) when numpy is
        importable, else a list of lists of floats."""
        response = self._call(self._spaces.GetCurve, space_service_pb2.GetCurveRequest(
            space=space, clip=self._range(clip, first, last), dims=dims))
        return decode_curve(response.coordinates, response.frames, response.dims)

    # -- search ---------------------------------------------------------------------------------
    @_rpc
    def search(self, space: str, clip: Optional[ClipRef] = None, first: Optional[int] = None,
               last: Optional[int] = None, bvh: Optional[PathOrBytes] = None,
               **params: Any) -> List[SearchResult]:
        """Finds the ranges that move like the query, best first: a stored clip (id or name) or a
        range of it (first, last: frames at its rate, inclusive), or a BVH file (path or bytes,
        first/last a range of it). params: SearchRequest's fields (max_results, exact,
        neighbours, tags, clip_ids, exclude_query, mirror, ...). Each result has clip_id,
        clip_name, start_s, end_s, start_frame, end_frame and score (lower is closer); with
        mirror=True the query's left/right mirror is searched too, and each result's mirrored
        says whether the mirror found it."""
        request = self._search_request(params)
        request.space = space
        if (clip is None) == (bvh is None):
            raise ValueError("search needs one of clip= and bvh=")
        if clip is not None:
            request.clip.CopyFrom(self._range(clip, first, last))
        else:
            request.bvh.bvh = _read(bvh)[0]
            if first is not None:
                request.bvh.first_frame = first
            if last is not None:
                request.bvh.last_frame = last
        return list(self._call(self._search.Search, request).results)

    @staticmethod
    def _search_request(params: Dict[str, Any]) -> search_service_pb2.SearchRequest:
        try:
            return search_service_pb2.SearchRequest(**params)
        except (ValueError, TypeError) as error:
            raise ValueError(f"bad search parameter: {error}") from None

    # -- labels ---------------------------------------------------------------------------------
    @_rpc
    def add_labels(self, labels: Iterable[Union[Dict[str, Any], Sequence[Any]]]) -> List[Label]:
        """Adds manual labels in one batch (all or none); returns them as stored.

        Each label is a dict with keys clip (id or name; or clip_id / clip_name), descriptor,
        value (default 1), and a range in frames (first, last; inclusive, at the clip's rate) or
        seconds (start_s, end_s); no range: the whole clip. Or a tuple (clip, first, last,
        descriptor[, value]) in frames.
        """
        items = []
        for label in labels:
            if not isinstance(label, dict):
                fields = list(label)
                if len(fields) not in (4, 5):
                    raise ValueError(f"a label tuple is (clip, first, last, descriptor[, value]),"
                                     f" not {label!r}")
                label = dict(zip(("clip", "first", "last", "descriptor", "value"), fields))
            items.append(self._new_label(label))
        response = self._call(self._labels.AddLabels,
                              label_service_pb2.AddLabelsRequest(labels=items))
        return list(response.labels)

    @staticmethod
    def _new_label(label: Dict[str, Any]) -> label_service_pb2.NewLabel:
        known = {"clip", "clip_id", "clip_name", "first", "last", "first_frame", "last_frame",
                 "start_s", "end_s", "descriptor", "value"}
        unknown = set(label) - known
        if unknown:
            raise ValueError(f"unknown label keys {sorted(unknown)}")
        item = label_service_pb2.NewLabel(descriptor_name=label.get("descriptor", ""))
        clip = label.get("clip")
        if isinstance(clip, int):
            item.clip_id = clip
        elif clip is not None:
            item.clip_name = str(clip)
        if label.get("clip_id") is not None:
            item.clip_id = int(label["clip_id"])
        if label.get("clip_name") is not None:
            item.clip_name = label["clip_name"]
        for key, field in (("first", "first_frame"), ("last", "last_frame"),
                           ("first_frame", "first_frame"), ("last_frame", "last_frame")):
            if label.get(key) is not None:
                setattr(item, field, int(label[key]))
        for key in ("start_s", "end_s", "value"):
            if label.get(key) is not None:
                setattr(item, key, float(label[key]))
        return item

    def list_labels(self, clip: Optional[ClipRef] = None, descriptor: Optional[str] = None,
                    origin: Optional[str] = None, min_value: Optional[float] = None,
                    page_size: int = 1000) -> Iterator[Label]:
        """Labels in id order, page after page, filtered by clip, descriptor, origin ("manual" or
        "propagated") and min_value."""
        request = label_service_pb2.ListLabelsRequest(
            page_size=page_size, clip_id=self.clip_id(clip) if clip is not None else 0,
            descriptor_name=descriptor or "", origin=_origin(origin))
        if min_value is not None:
            request.min_value = min_value
        return self._pages(self._labels.ListLabels, request)

    def find_labels(self, descriptor: str, min_value: float = 0.0, tags: Iterable[str] = (),
                    page_size: int = 1000) -> Iterator[Label]:
        """The ranges carrying a descriptor at min_value or more, strongest first (manual and
        propagated), each with clip_name, first_frame/last_frame and start_s/end_s."""
        return self._pages(self._labels.FindLabels, label_service_pb2.FindLabelsRequest(
            descriptor_name=descriptor, min_value=min_value, tags=list(tags), page_size=page_size))

    def _pages(self, method, request) -> Iterator[Any]:
        while True:
            try:
                response = self._call(method, request)
            except grpc.RpcError as error:
                raise Error.from_rpc(error) from None
            yield from response.labels
            if not response.next_page_token:
                return
            request.page_token = response.next_page_token

    def clip_labels(self, clip: ClipRef, page_size: int = 1000) -> List[Label]:
        """A clip's label timeline: all its labels by first frame (every page read)."""
        return list(self._pages(self._labels.GetClipLabels, label_service_pb2.GetClipLabelsRequest(
            clip_id=self.clip_id(clip), page_size=page_size)))

    @_rpc
    def delete_labels(self, ids: Iterable[int] = (), clip: Optional[ClipRef] = None,
                      descriptor: Optional[str] = None, origin: Optional[str] = None) -> int:
        """Deletes labels by id, or those a filter (clip, descriptor, origin) takes; deleting a
        manual label deletes the labels propagated from it. Returns how many were deleted."""
        return self._call(self._labels.DeleteLabels, label_service_pb2.DeleteLabelsRequest(
            label_ids=list(ids), clip_id=self.clip_id(clip) if clip is not None else 0,
            descriptor_name=descriptor or "", origin=_origin(origin))).deleted

    # -- jobs -----------------------------------------------------------------------------------
    @_rpc
    def start_propagation(self, space: str, descriptors: Iterable[str] = (),
                          tags: Iterable[str] = (), rival_share: Optional[float] = None,
                          **search_params: Any) -> Job:
        """Queues a propagation job in a space: each manual label of the descriptors (empty:
        every descriptor of a manual label) runs as a search, whose results get the descriptor.
        search_params: each query's SearchRequest parameters (max_results, exact, ...); tags:
        only clips carrying one of them are searched; rival_share (0 < R <= 1): a range is
        written only where every overlapping range of another descriptor has less than R times
        its value (None: every descriptor's). Returns the job (queued)."""
        return self._call(self._jobs.StartPropagation, job_service_pb2.StartPropagationRequest(
            space=space, descriptor_names=list(descriptors), tags=list(tags),
            rival_share=rival_share, search=self._search_request(search_params)))

    @_rpc
    def job(self, job_id: str) -> Job:
        """A job now (GetJob)."""
        return self._call(self._jobs.GetJob, job_service_pb2.GetJobRequest(job_id=job_id))

    def jobs(self) -> Iterator[Job]:
        """Every job, newest first."""
        request = job_service_pb2.ListJobsRequest()
        while True:
            try:
                response = self._call(self._jobs.ListJobs, request)
            except grpc.RpcError as error:
                raise Error.from_rpc(error) from None
            yield from response.jobs
            if not response.next_page_token:
                return
            request.page_token = response.next_page_token

    def watch(self, job_id: str) -> Iterator[Job]:
        """The job now, then again at each change of its progress, counts or state, until it
        ends: the last Job yielded has a final state (see job_finished()). Closing the iterator
        early cancels the stream."""
        stream = self._jobs.WatchJob(job_service_pb2.WatchJobRequest(job_id=job_id),
                                     metadata=self._metadata)
        try:
            for job in stream:
                yield job
                if job.state in _FINAL_JOB_STATES:
                    return
        except grpc.RpcError as error:
            raise Error.from_rpc(error) from None
        finally:
            stream.cancel()

    @_rpc
    def cancel(self, job_id: str) -> Job:
        """Cancels a queued or running job; returns it as it ended. Error FAILED_PRECONDITION
        for a job that has ended already."""
        return self._call(self._jobs.CancelJob, job_service_pb2.CancelJobRequest(job_id=job_id))

    # -- helpers --------------------------------------------------------------------------------
    def _range(self, clip: ClipRef, first: Optional[int] = None,
               last: Optional[int] = None) -> common_pb2.ClipRange:
        result = common_pb2.ClipRange(clip_id=self.clip_id(clip))
        if first is not None:
            result.first_frame = first
        if last is not None:
            result.last_frame = last
        return result


def _origin(origin: Optional[str]) -> int:
    if isinstance(origin, int):
        return origin
    try:
        return _ORIGINS[origin.lower() if origin else None]
    except KeyError:
        raise ValueError(f"origin is 'manual' or 'propagated', not {origin!r}") from None


def decode_curve(data: bytes, frames: int, dims: int):
    """frames x dims little-endian float32 (row-major) as a numpy array, or lists without numpy."""
    if numpy is not None:
        return numpy.frombuffer(data, dtype="<f4").reshape(frames, dims)
    import array
    import sys
    values = array.array("f", data)
    if sys.byteorder != "little":
        values.byteswap()
    return [list(values[row * dims:(row + 1) * dims]) for row in range(frames)]


def connect(address: str, token: Optional[str] = None,
            tls_ca: Optional[PathOrBytes] = None, tls: bool = False,
            timeout: Optional[float] = 300.0, ready_timeout: Optional[float] = 30.0) -> Client:
    """A Client of the server at address ("host:port").

    token: sent as "authorization: Bearer TOKEN" on every call (the server's --auth-token-file).
    tls_ca: the CA certificate (a PEM file's path or its bytes) to trust for a TLS server; or
    tls=True to use the system's roots. timeout: seconds per unary call (None: unbounded).
    ready_timeout: wait this long for the connection (None: do not wait); Error UNAVAILABLE
    when it is not up by then.
    """
    options = [("grpc.max_receive_message_length", -1), ("grpc.max_send_message_length", -1)]
    if tls_ca is not None or tls:
        roots = _read(tls_ca)[0] if tls_ca is not None else None
        channel = grpc.secure_channel(address, grpc.ssl_channel_credentials(roots), options)
    else:
        channel = grpc.insecure_channel(address, options)
    if ready_timeout is not None:
        try:
            grpc.channel_ready_future(channel).result(timeout=ready_timeout)
        except grpc.FutureTimeoutError:
            channel.close()
            raise Error("UNAVAILABLE", f"no server answered at {address} within "
                        f"{ready_timeout:g} s", grpc.StatusCode.UNAVAILABLE) from None
    return Client(channel, token=token, timeout=timeout)
