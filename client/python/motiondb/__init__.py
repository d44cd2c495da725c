"""Python client of the motiondb motion-search server.

    import motiondb
    client = motiondb.connect("127.0.0.1:50051")           # token=..., tls_ca="ca.pem"
    clip = client.ingest("walk.bvh", tags=["walk"]).clip
    client.create_space("body")
    for result in client.search("body", clip=clip.clip_id, max_results=5):
        print(result.clip_name, result.start_s, result.end_s, result.score)
    client.add_labels([(clip.clip_id, 10, 40, "step", 1.0)])
    print(client.skeleton(clip.skeleton_id).humanoid_map.missing_slots)  # [] when mapped
    job = client.start_propagation("body", ["step"], max_results=5)
    for update in client.watch(job.job_id):
        print(update.done, "/", update.total)
    for label in client.find_labels("step", min_value=0.5):
        print(label.clip_name, label.start_s, label.end_s, label.value)

Failed calls raise motiondb.Error (.code the gRPC status name, .message the server's text).
The returned objects are the API's messages (proto/motiondb/v1), whose generated modules are
motiondb.v1.*_pb2.
"""
# The stubs (motiondb.v1) come with the installed package; from a checkout, the package's source
# folder and the build's build/python (generated stubs only) both on PYTHONPATH make one package.
__path__ = __import__("pkgutil").extend_path(__path__, __name__)

from motiondb.client import (Clip, Client, Error, Job, Label, SearchResult, Skeleton,
                             SkeletonDetail, Space, connect, decode_curve, job_finished,
                             job_state_name)

__all__ = ["Clip", "Client", "Error", "Job", "Label", "SearchResult", "Skeleton",
           "SkeletonDetail", "Space", "connect", "decode_curve", "job_finished",
           "job_state_name"]
__version__ = "0.1.0"
