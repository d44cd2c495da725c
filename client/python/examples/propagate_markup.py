#!/usr/bin/python3
"""The batch markup job end to end: labels from a CSV, propagated through a space, exported.

    propagate_markup.py --server 127.0.0.1:50051 --space body labels.csv -o propagated.csv

Reads manual labels from a CSV in the format `motiondb labels import` reads (header
clip,start,end,descriptor,value; optional unit column, frames or seconds; clip a clip's name,
or a clip_id column), adds them in one batch, starts a propagation job for their descriptors
in the space (built over the first label's skeleton when there is no space of that name),
prints its progress while watching it, and writes the labels the job propagated as CSV in the
same format (frames) to the output file. Needs the motiondb package (pip install ./client/python).
"""
import argparse
import csv
import os
import sys

import motiondb


def read_labels(path):
    """The CSV's rows as label dicts for Client.add_labels."""
    labels = []
    with open(path, newline="", encoding="utf-8-sig") as file:
        for line, row in enumerate(csv.DictReader(file), start=2):
            try:
                label = {"descriptor": row["descriptor"]}
                if row.get("value"):
                    label["value"] = float(row["value"])
                if row.get("clip_id"):
                    label["clip_id"] = int(row["clip_id"])
                if row.get("clip"):
                    label["clip_name"] = row["clip"]
                seconds = (row.get("unit") or "frames").strip() == "seconds"
                for column, frames_key, seconds_key in (("start", "first", "start_s"),
                                                        ("end", "last", "end_s")):
                    if row.get(column):
                        label[seconds_key if seconds else frames_key] = (
                            float(row[column]) if seconds else int(row[column]))
            except (KeyError, ValueError) as error:
                raise SystemExit(f"{path}: line {line}: {error}") from None
            labels.append(label)
    if not labels:
        raise SystemExit(f"{path}: no labels")
    return labels


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("labels", help="CSV: clip,start,end,descriptor,value")
    parser.add_argument("-o", "--output", required=True, help="CSV of the propagated labels")
    parser.add_argument("--server", default=os.environ.get("MOTIONDB_SERVER", "127.0.0.1:50051"))
    parser.add_argument("--token", default=None)
    parser.add_argument("--tls-ca", default=None, help="CA certificate of a TLS server")
    parser.add_argument("--space", required=True)
    parser.add_argument("--max-results", type=int, default=None, help="results per query")
    args = parser.parse_args()

    try:
        client = motiondb.connect(args.server, token=args.token, tls_ca=args.tls_ca)
        added = client.add_labels(read_labels(args.labels))
        descriptors = sorted({label.descriptor_name for label in added})
        print(f"added {len(added)} manual labels: {', '.join(descriptors)}")

        try:
            client.space(args.space)
        except motiondb.Error as error:
            if error.code != "NOT_FOUND":
                raise
            skeleton = client.clip(added[0].clip_id).skeleton_id
            space = client.create_space(args.space, skeleton_id=skeleton)
            print(f"built space {space.name}: {space.report.dims} dims")

        params = {} if args.max_results is None else {"max_results": args.max_results}
        job = client.start_propagation(args.space, descriptors, **params)
        print(f"started {job.job_id}")
        for job in client.watch(job.job_id):
            print(f"{job.job_id} {motiondb.job_state_name(job)}: {job.done}/{job.total} labels, "
                  f"{job.queries} queries, {job.labels_written} labels written", flush=True)
        if motiondb.job_state_name(job) != "succeeded":
            print(f"{job.job_id} {motiondb.job_state_name(job)}: {job.error}", file=sys.stderr)
            return 1

        written = 0
        with open(args.output, "w", newline="", encoding="utf-8") as file:
            out = csv.writer(file)
            out.writerow(["clip", "start", "end", "descriptor", "value"])
            for descriptor in descriptors:
                for label in client.list_labels(descriptor=descriptor, origin="propagated"):
                    if label.job_id == job.job_id:
                        out.writerow([label.clip_name, label.first_frame, label.last_frame,
                                      label.descriptor_name, f"{label.value:.6g}"])
                        written += 1
        print(f"wrote {written} propagated labels to {args.output}")
        return 0
    except motiondb.Error as error:
        print(f"error: {error.code}: {error.message}", file=sys.stderr)
        return 1


if __name__ == "__main__":
    sys.exit(main())
