// Libraries for the browser tests and the page benchmark, loaded through the real interfaces:
// the motiondb CLI over gRPC (as scripts/start.sh --demo does) or POST /v1/clips.
import { execFileSync } from "node:child_process";
import { readFileSync } from "node:fs";
import { join } from "node:path";

/** Debian's assimp-testmodels: two CMU takes (one skeleton) and a boxing take (another). */
export const ASSIMP_BVH = "/usr/share/assimp/models/BVH";

export function cli(cliBin, server, ...args) {
  return execFileSync(cliBin, [...args, "--server", server.grpcAddress], {
    encoding: "utf8",
    stdio: ["ignore", "pipe", "pipe"],
  });
}

/** An offline command (no server): convert, inspect. */
export function cliOffline(cliBin, ...args) {
  return execFileSync(cliBin, args, {
    encoding: "utf8",
    stdio: ["ignore", "pipe", "pipe"],
  });
}

export function cliJson(cliBin, server, ...args) {
  return JSON.parse(cli(cliBin, server, ...args, "--json"));
}

/**
 * The demo library of scripts/start.sh --demo, with a tag per source so that filters have
 * something to tell apart: 01_01 and 01_03 tagged cmu, Boxing_Toes tagged boxing, all tagged
 * demo; a space `demo` on the CMU skeleton. Returns the clips by name.
 */
export function loadDemoLibrary(cliBin, server) {
  const cmu = ["01_01.bvh", "01_03.bvh"].map((f) => join(ASSIMP_BVH, f));
  cli(cliBin, server, "ingest", ...cmu, "--tag", "demo", "--tag", "cmu");
  cli(
    cliBin,
    server,
    "ingest",
    join(ASSIMP_BVH, "Boxing_Toes.bvh"),
    "--tag",
    "demo",
    "--tag",
    "boxing",
  );
  const clips = cliJson(cliBin, server, "clips").clips;
  const byName = Object.fromEntries(clips.map((c) => [c.name, c]));
  cli(cliBin, server, "space", "create", "demo", "--skeleton", String(byName["01_01"].skeleton_id));
  return byName;
}

/** `count` clips through POST /v1/clips: copies of one BVH file under numbered names. */
export async function loadCopies(server, bvhPath, count, tag) {
  const bvh = readFileSync(bvhPath).toString("base64");
  for (let i = 0; i < count; i++) {
    const name = `copy_${String(i).padStart(4, "0")}`;
    const response = await fetch(`${server.baseUrl}/v1/clips`, {
      method: "POST",
      headers: { "Content-Type": "application/json" },
      body: JSON.stringify({ file_name: `${name}.bvh`, bvh, tags: [tag] }),
    });
    if (!response.ok) throw new Error(`POST /v1/clips ${name}: ${await response.text()}`);
  }
}
