// Follows a job to its end by polling GET /v1/jobs/{id} (WatchJob is a gRPC stream, which a
// page cannot open), reporting every state it sees.
import { api } from "../api/routes";
import type { Job } from "../api/types";

const POLL_MS = 250;

export function isLive(job: Job): boolean {
  return job.state === "JOB_STATE_QUEUED" || job.state === "JOB_STATE_RUNNING";
}

export async function watchJob(first: Job, onUpdate: (job: Job) => void): Promise<Job> {
  let job = first;
  onUpdate(job);
  while (isLive(job)) {
    await new Promise((resolve) => window.setTimeout(resolve, POLL_MS));
    job = await api.job(job.job_id);
    onUpdate(job);
  }
  return job;
}
