// A real motiondb-server for the browser tests and the page benchmark: a fresh database in a
// temporary folder, gRPC and HTTP on free loopback ports, stopped with SIGTERM.
import { spawn } from "node:child_process";
import { mkdtempSync, openSync, readFileSync, rmSync } from "node:fs";
import { createServer } from "node:net";
import { tmpdir } from "node:os";
import { dirname, join } from "node:path";
import { fileURLToPath } from "node:url";

/** The page the tests load: this checkout's build (run_browser_tests.sh builds it first). */
const WEB_DIST = join(dirname(fileURLToPath(import.meta.url)), "..", "..", "web", "dist");

/** A loopback port nothing listens on (bound and released; the server binds it next). */
export function freePort() {
  return new Promise((resolve, reject) => {
    const probe = createServer();
    probe.on("error", reject);
    probe.listen(0, "127.0.0.1", () => {
      const { port } = probe.address();
      probe.close(() => resolve(port));
    });
  });
}

export class ServerProcess {
  /** Starts `serverBin` and waits until /readyz answers 200. */
  static async start(serverBin, extraArgs = []) {
    const dir = mkdtempSync(join(tmpdir(), "motiondb_web_"));
    const grpc = `127.0.0.1:${await freePort()}`;
    const http = `127.0.0.1:${await freePort()}`;
    const log = join(dir, "server.log");
    const out = openSync(log, "w");
    const child = spawn(
      serverBin,
      [
        "--db",
        join(dir, "motiondb.sqlite"),
        "--listen",
        grpc,
        "--http",
        http,
        "--web-root",
        WEB_DIST,
        ...extraArgs,
      ],
      { stdio: ["ignore", out, out] },
    );
    const server = new ServerProcess(child, dir, grpc, `http://${http}`, log);
    await server.waitReady();
    return server;
  }

  constructor(child, dir, grpcAddress, baseUrl, logPath) {
    this.child = child;
    this.dir = dir;
    this.grpcAddress = grpcAddress;
    this.baseUrl = baseUrl;
    this.logPath = logPath;
    this.exited = new Promise((resolve) => child.on("exit", resolve));
  }

  async waitReady() {
    const deadline = Date.now() + 60_000;
    while (Date.now() < deadline) {
      if (this.child.exitCode !== null) break;
      try {
        if ((await fetch(`${this.baseUrl}/readyz`)).ok) return;
      } catch {
        // not listening yet
      }
      await new Promise((resolve) => setTimeout(resolve, 100));
    }
    throw new Error(`motiondb-server did not become ready:\n${this.log()}`);
  }

  log() {
    return readFileSync(this.logPath, "utf8").slice(-4000);
  }

  async stop() {
    if (this.child.exitCode === null) this.child.kill("SIGTERM");
    await this.exited;
    rmSync(this.dir, { recursive: true, force: true });
  }
}
