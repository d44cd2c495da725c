// Debian's Chromium driven headless by Playwright (playwright-core from web/node_modules; no
// browser is ever downloaded), in a fresh profile, recording every console error and page
// error so that a test can insist there were none.
import { mkdtempSync, rmSync } from "node:fs";
import { createRequire } from "node:module";
import { tmpdir } from "node:os";
import { dirname, join } from "node:path";
import { fileURLToPath } from "node:url";

export const CHROMIUM = "/usr/bin/chromium";
const WEB = join(dirname(fileURLToPath(import.meta.url)), "..", "..", "web");
const { chromium } = createRequire(join(WEB, "package.json"))("playwright-core");

const ARGS = [
  "--headless",
  "--no-sandbox",
  "--disable-gpu",
  "--disable-quic",
  "--no-first-run",
  "--disable-background-networking",
  "--disable-component-update",
  "--disable-sync",
];

export class Browser {
  /** `args`: Chromium's command-line switches beyond ARGS. */
  static async launch(viewport = { width: 1400, height: 860 }, args = []) {
    const profile = mkdtempSync(join(tmpdir(), "motiondb_chromium_"));
    const context = await chromium.launchPersistentContext(profile, {
      executablePath: CHROMIUM,
      args: [...ARGS, ...args],
      headless: true,
      viewport,
    });
    return new Browser(context, profile);
  }

  constructor(context, profile) {
    this.context = context;
    this.profile = profile;
    /** Console errors and uncaught page errors, as text. */
    this.errors = [];
  }

  /** A new tab that reports its errors into `errors`. */
  async page() {
    const page = await this.context.newPage();
    page.on("console", (message) => {
      if (message.type() === "error") {
        const where = message.location().url;
        this.errors.push(`console: ${message.text()}${where ? ` (${where})` : ""}`);
      }
    });
    page.on("pageerror", (error) => this.errors.push(`page: ${error.message}`));
    return page;
  }

  async close() {
    await this.context.close();
    rmSync(this.profile, { recursive: true, force: true });
  }
}
