// The web page's latency (issue 14): page ready with 1,000 clips in the library, and a search
// from the page to rendered hits at the demo library, each beside a baseline measured in the
// same run (the page on the 3-clip demo library; the same search as a bare POST /v1/search).
// Not a test: the numbers go to bench/RESULTS.md's table and a dated note in bench/notes/.
//
//   node bench/web_page_bench.mjs BUILD_DIR [--loads 10] [--searches 30]
//
// BUILD_DIR holds server/motiondb-server and client/motiondb; web/dist must be built
// (scripts/build-web.sh). Debian's Chromium headless; servers on free loopback ports.
import { mkdtempSync, rmSync } from "node:fs";
import { tmpdir } from "node:os";
import { join } from "node:path";
import { Browser } from "../testing/web/browser.mjs";
import { ASSIMP_BVH, cliOffline, loadCopies, loadDemoLibrary } from "../testing/web/library.mjs";
import { ServerProcess } from "../testing/web/server.mjs";

const args = process.argv.slice(2);
const option = (name, fallback) => {
  const i = args.indexOf(name);
  return i >= 0 ? Number(args[i + 1]) : fallback;
};
const build = args[0];
if (!build)
  throw new Error("usage: node bench/web_page_bench.mjs BUILD_DIR [--loads N] [--searches N]");
const SERVER = join(build, "server", "motiondb-server");
const CLI = join(build, "client", "motiondb");
const LOADS = option("--loads", 10);
const SEARCHES = option("--searches", 30);

function summary(name, values) {
  const sorted = [...values].sort((a, b) => a - b);
  const at = (q) => sorted[Math.min(sorted.length - 1, Math.floor(q * sorted.length))];
  const text = `${name}: median ${at(0.5).toFixed(1)} ms, p90 ${at(0.9).toFixed(1)} ms, max ${sorted[sorted.length - 1].toFixed(1)} ms (n=${values.length})`;
  console.log(text);
  return text;
}

/** Milliseconds from navigation start to the page's `motiondb-ready` mark, cold and warm. */
async function pageReady(server, expectedCount) {
  const cold = [];
  const warm = [];
  for (let i = 0; i < LOADS; i++) {
    const browser = await Browser.launch();
    const page = await browser.page();
    for (const into of [cold, warm]) {
      if (into === cold) await page.goto(server.baseUrl + "/");
      else await page.reload();
      await page.waitForSelector("body[data-ready=true]");
      into.push(
        await page.evaluate(() => performance.getEntriesByName("motiondb-ready")[0].startTime),
      );
    }
    const count = await page.textContent("[data-testid=clip-count]");
    if (!count.endsWith(`of ${expectedCount}`)) throw new Error(`the page shows "${count}"`);
    if (browser.errors.length) throw new Error(browser.errors.join("\n"));
    await browser.close();
  }
  return { cold, warm };
}

/** Click on Search to the hits in the DOM and painted, measured in the page. */
async function pageSearches(server, clipId) {
  const browser = await Browser.launch();
  const page = await browser.page();
  await page.goto(`${server.baseUrl}/?space=demo&clip=${clipId}&from=40&to=124`);
  await page.waitForSelector("[data-testid=hit]", { timeout: 60_000 });
  const times = [];
  for (let i = 0; i < SEARCHES; i++) {
    times.push(
      await page.evaluate(async () => {
        const hits = document.querySelector("[data-testid=hits]");
        hits.replaceChildren();
        const rendered = new Promise((resolve) =>
          new MutationObserver((_, observer) => {
            if (hits.children.length) {
              observer.disconnect();
              resolve();
            }
          }).observe(hits, { childList: true }),
        );
        const start = performance.now();
        document.querySelector("[data-testid=search]").click();
        await rendered;
        await new Promise((resolve) => requestAnimationFrame(() => setTimeout(resolve)));
        return performance.now() - start;
      }),
    );
  }
  if (browser.errors.length) throw new Error(browser.errors.join("\n"));
  await browser.close();
  return times;
}

/** The same search as the page's, as a bare HTTP call from node (no page). */
async function bareSearches(server, clipId) {
  const body = JSON.stringify({
    space: "demo",
    clip: { clip_id: clipId, first_frame: 40, last_frame: 124 },
    max_results: 20,
    return_path: true,
  });
  const times = [];
  for (let i = 0; i < SEARCHES; i++) {
    const start = performance.now();
    const response = await fetch(`${server.baseUrl}/v1/search`, {
      method: "POST",
      body,
      headers: { "Content-Type": "application/json" },
    });
    await response.json();
    times.push(performance.now() - start);
  }
  return times;
}

const work = mkdtempSync(join(tmpdir(), "motiondb_web_bench_"));
const lines = [];
try {
  const demo = await ServerProcess.start(SERVER, ["--quiet"]);
  const clips = loadDemoLibrary(CLI, demo);
  const demoReady = await pageReady(demo, 3);
  lines.push(summary("page ready, demo library (3 clips), cold", demoReady.cold));
  lines.push(summary("page ready, demo library (3 clips), warm", demoReady.warm));
  lines.push(
    summary("search, bare POST /v1/search", await bareSearches(demo, clips["01_01"].clip_id)),
  );
  lines.push(
    summary(
      "search from the page to rendered hits",
      await pageSearches(demo, clips["01_01"].clip_id),
    ),
  );
  await demo.stop();

  const big = await ServerProcess.start(SERVER, ["--quiet"]);
  const short = join(work, "short.bvh");
  cliOffline(CLI, "convert", join(ASSIMP_BVH, "01_01.bvh"), short, "--from", "0", "--to", "119");
  await loadCopies(big, short, 1000, "bench");
  const bigReady = await pageReady(big, 1000);
  lines.push(summary("page ready, 1,000 clips, cold", bigReady.cold));
  lines.push(summary("page ready, 1,000 clips, warm", bigReady.warm));
  await big.stop();
} finally {
  rmSync(work, { recursive: true, force: true });
}
console.log("\n" + lines.join("\n"));
