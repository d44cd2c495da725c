#!/usr/bin/python3
"""Runs every command block of README.md and docs/*.md as written, so that the docs cannot drift.

    readme_examples_test.py REPO BUILD_DIR
    readme_examples_test.py --list REPO    # which blocks would run, from which page, in order

The README's first command starts the server: this test runs scripts/start.sh itself (on free
loopback ports for gRPC and HTTP, a fresh database and log in a temporary folder), then each
```sh block of each page in order in one temporary working folder (with build/, client/,
scripts/ and proto/ linked to the real ones), against the one server, with the built `motiondb`
on PATH and MOTIONDB_SERVER naming the test's server; the default addresses (127.0.0.1:50051,
and 127.0.0.1:8080 for HTTP) are replaced by the test server's. The pages run in PAGE_ORDER
(README.md first, then the docs pages that build on its library, each on the state the pages
before it left: clips ingested, the space `body`, labels.csv), then any other docs/*.md page in
name order, so that no page's blocks go unrun; a failure names its page, line and first
command. A block preceded by `<!-- readme-test: skip: REASON -->` is not run; the reason must
say which other check runs it. `<!-- readme-test: requires: TOOL -->` runs the block when TOOL
is on PATH and says so when it is not; TOOL `npm-registry` means npm and a reachable npm
registry (a machine that reaches only Debian's archive has neither the page's packages nor
Buf's). Last, `scripts/start.sh --demo` must load its demo library into a fresh database, say
where its web page is, and serve it there; without the npm registry start.sh serves the JSON
API instead, as it documents, and says where. MOTIONDB_REQUIRE_NPM=1 (set by .ci/run) makes an
unreachable registry a failure rather than a reason not to run.
"""
import os
import pathlib
import re
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time

# A directive is one line, so that a page that names one in its text does not take the text up to
# the next block's directive for a directive.
BLOCK = re.compile(r"(?:<!--[ \t]*readme-test:[ \t]*(?P<directive>[^\n]*?)[ \t]*-->[ \t]*\n)?"
                   r"```sh\n(?P<body>.*?)```", re.S)
DEFAULT_ADDRESS = "127.0.0.1:50051"
DEFAULT_HTTP_ADDRESS = "127.0.0.1:8080"
# The order the pages run in: each page's blocks find what the pages before it made.
PAGE_ORDER = ("README.md", "docs/user-guide.md", "docs/api.md", "docs/operations.md",
              "docs/search-tuning.md")


def pages(repo):
    """README.md and every docs/*.md page: PAGE_ORDER's first, then the others by name."""
    found = ["README.md"] + sorted(str(p.relative_to(repo)) for p in (repo / "docs").glob("*.md"))
    ordered = [page for page in PAGE_ORDER if page in found]
    return ordered + [page for page in found if page not in ordered]


class Block:
    """One ```sh block: its page, its line there, its readme-test directive (or None), its body."""

    def __init__(self, page, text, match):
        self.page = page
        self.line = text.count("\n", 0, match.start("body")) + 1  # its first line
        self.directive = match.group("directive")
        self.body = match.group("body")

    def first_line(self):
        return self.body.strip().splitlines()[0]

    def where(self):
        return f"{self.page}:{self.line}: {self.first_line()}"


def blocks(repo):
    """Every ```sh block of every page, in the order they run."""
    found = []
    for page in pages(repo):
        text = (repo / page).read_text()
        found += [Block(page, text, match) for match in BLOCK.finditer(text)]
    return found


def list_blocks(repo):
    """Prints which blocks would run, from which page, in order (no server needed)."""
    for block in blocks(repo):
        if block.directive:
            print(f"{block.where()}    [{block.directive}]")
        else:
            print(block.where())


def free_port():
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return sock.getsockname()[1]


class StartedServer:
    """scripts/start.sh [--demo] running in the background until stop()."""

    def __init__(self, repo, build, work, demo):
        self.port = free_port()
        self.address = f"127.0.0.1:{self.port}"
        self.http_address = f"127.0.0.1:{free_port()}"
        env = dict(os.environ, BUILD_DIR=str(build), MOTIONDB_DB=str(work / "motiondb.sqlite"),
                   MOTIONDB_LOG=str(work / "motiondb-server.log"))
        command = [str(repo / "scripts" / "start.sh")] + (["--demo"] if demo else [])
        self.output = open(work / "start.out", "w+")
        self.process = subprocess.Popen(command + ["--listen", self.address,
                                                   "--http", self.http_address], cwd=work, env=env,
                                        stdout=self.output, stderr=subprocess.STDOUT,
                                        start_new_session=True)
        deadline = time.monotonic() + 900
        while "motiondb-server is running" not in self.text():
            if self.process.poll() is not None or time.monotonic() > deadline:
                raise SystemExit(f"start.sh did not serve:\n{self.text()}")
            time.sleep(0.2)

    def text(self):
        self.output.flush()
        self.output.seek(0)
        return self.output.read()

    def stop(self):
        os.killpg(self.process.pid, signal.SIGTERM)
        self.process.wait(timeout=60)


def npm_registry_reachable():
    """True when npm can reach its registry; fails the test under MOTIONDB_REQUIRE_NPM=1."""
    if shutil.which("npm") is not None:
        try:
            if subprocess.run(["npm", "ping"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                              timeout=60).returncode == 0:
                return True
        except subprocess.TimeoutExpired:
            pass
    if os.environ.get("MOTIONDB_REQUIRE_NPM") == "1":
        raise SystemExit("the npm registry is unreachable (npm ping) and MOTIONDB_REQUIRE_NPM=1")
    return False


def tool_available(tool):
    return npm_registry_reachable() if tool == "npm-registry" else shutil.which(tool) is not None


def run_block(body, env, work):
    print(f"$ {body.strip()}", flush=True)
    result = subprocess.run(["/bin/bash", "-euo", "pipefail", "-c", body], cwd=work, env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                            timeout=600)
    print(result.stdout[-3000:], flush=True)
    return result.returncode


def main():
    if len(sys.argv) == 3 and sys.argv[1] == "--list":
        list_blocks(pathlib.Path(sys.argv[2]).resolve())
        return 0
    repo, build = pathlib.Path(sys.argv[1]).resolve(), pathlib.Path(sys.argv[2]).resolve()
    every_block = blocks(repo)
    if not any(block.page == "README.md" for block in every_block):
        raise SystemExit("README.md has no ```sh blocks")
    work = pathlib.Path(tempfile.mkdtemp(prefix="motiondb_readme_"))
    try:
        for name in ("client", "scripts", "proto"):
            (work / name).symlink_to(repo / name)
        (work / "build").symlink_to(build)
        (work / "docker").mkdir()
        server = StartedServer(repo, build, work, demo=False)
        env = dict(os.environ, MOTIONDB_SERVER=server.address,
                   PATH=f"{build / 'client'}:{os.environ.get('PATH', '')}")
        failed, ran, skipped = [], 0, 0
        try:
            for block in every_block:
                directive, body = block.directive, block.body
                if directive and directive.startswith("requires:"):
                    tool = directive.split(":", 1)[1].strip()
                    if not tool_available(tool):
                        print(f"{block.page}: not run here ({tool} is not available):\n{body}")
                        skipped += 1
                        continue
                elif directive:
                    if not directive.startswith("skip:") or len(directive) < 12:
                        raise SystemExit(f"{block.page}: bad readme-test directive: {directive!r}")
                    print(f"{block.page}: not run here ({directive}):\n{body}")
                    skipped += 1
                    continue
                ran += 1
                print(f"--- {block.page}, line {block.line}", flush=True)
                body = body.replace(DEFAULT_ADDRESS, server.address)
                if run_block(body.replace(DEFAULT_HTTP_ADDRESS, server.http_address), env,
                             work) != 0:
                    failed.append(block.where())
        finally:
            server.stop()

        demo_work = work / "demo"
        demo_work.mkdir()
        demo = StartedServer(repo, build, demo_work, demo=True)
        try:
            demo_env = dict(env, MOTIONDB_SERVER=demo.address)
            ran += 1
            page = f"http://{demo.http_address}"
            # grep reads to the end (no -q): a reader that exits early can make the writer fail
            # on a closed pipe, which pipefail reports.
            checks = ("motiondb clips --tag demo | grep 01_01 >/dev/null\n"
                      "motiondb search --space demo --clip 1 --max 3\n")
            if "the web page was not built" in demo.text() and not npm_registry_reachable():
                print("the web page was not built (the npm registry is unreachable): "
                      "checking the JSON API start.sh serves instead")
                if f"JSON API: {page}" not in demo.text():
                    failed.append(f"scripts/start.sh --demo did not say: JSON API: {page}")
                checks += f"curl -sf {page}/v1/spaces | grep demo >/dev/null\n"
            else:
                if f"open {page}" not in demo.text():
                    failed.append(f"scripts/start.sh --demo did not say: open {page}")
                checks += f"curl -sf {page}/ | grep '<title>motiondb' >/dev/null\n"
            if run_block(checks, demo_env, work) != 0:
                failed.append("scripts/start.sh --demo")
        finally:
            demo.stop()
        print(f"README and docs blocks: {ran} run, {skipped} not run here, {len(failed)} failed")
        for where in failed:
            print(f"FAILED: {where}")
        return 1 if failed else 0
    finally:
        shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())
