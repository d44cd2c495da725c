#!/usr/bin/python3
"""The Blender add-on (client/blender), installed from its zip into Debian's Blender and driven
headless against a real server.

    blender_addon_test.py SERVER_BINARY CLI_BINARY REPO OUT_DIR

Starts motiondb-server with a token file and TLS (a self-signed certificate for 127.0.0.1 made
with openssl) on free loopback ports (gRPC and HTTPS), ingests two of assimp-testmodels' CMU takes with the CLI and builds a space on them, writes the first 480
frames of the first take as the BVH take Blender loads, builds the zip with
scripts/blender-addon.sh, then runs `blender -b --factory-startup` on addon_in_blender.py, which
installs the zip and checks the add-on (its docstring says what). OUT_DIR receives the rendered
picture, blender_addon.png. Exits 77 (ctest's skip) with a message when blender, openssl or the
takes are missing.
"""
import os
import pathlib
import shutil
import signal
import socket
import ssl
import subprocess
import sys
import tempfile
import urllib.request

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent.parent / "python"))
from server_fixtures import logged_port  # noqa: E402

TAKES = [pathlib.Path("/usr/share/assimp/models/BVH/01_01.bvh"),
         pathlib.Path("/usr/share/assimp/models/BVH/01_03.bvh")]
TOKEN = "blender-test-token"


def skip(why):
    print(f"SKIPPED: {why} (scripts/install-deps.sh installs it)")
    return 77


def main():
    server_binary, cli, repo, out_dir = sys.argv[1:5]
    repo, out_dir = pathlib.Path(repo), pathlib.Path(out_dir)
    blender = shutil.which("blender")
    if blender is None:
        return skip("blender is not installed")
    if shutil.which("openssl") is None:
        return skip("openssl is not installed (it makes the server's certificate)")
    missing = [str(take) for take in TAKES if not take.is_file()]
    if missing:
        return skip(f"{', '.join(missing)} missing (package assimp-testmodels)")
    out_dir.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="motiondb_blender_") as work:
        work = pathlib.Path(work)
        token_file = work / "token"
        token_file.write_text(TOKEN + "\n")
        cert, key = work / "cert.pem", work / "key.pem"
        # As tests/python/package_test.py makes its certificate: for the name the client dials.
        subprocess.run(
            ["openssl", "req", "-x509", "-newkey", "rsa:2048", "-nodes", "-days", "1",
             "-subj", "/CN=localhost", "-addext", "subjectAltName=DNS:localhost,IP:127.0.0.1",
             "-keyout", str(key), "-out", str(cert)], check=True, capture_output=True)
        log = work / "server.log"
        with open(log, "w") as log_file:
            server = subprocess.Popen(
                [server_binary, "--db", str(work / "test.sqlite"), "--listen", "127.0.0.1:0",
                 "--http", "127.0.0.1:0", "--auth-token-file", str(token_file),
                 "--tls-cert", str(cert), "--tls-key", str(key)],
                stdout=subprocess.DEVNULL, stderr=log_file)
        # A socket bound and never listening: a server address that refuses every connection,
        # held for the whole test so that no other process can take its port.
        dead = socket.socket()
        dead.bind(("127.0.0.1", 0))
        try:
            port = logged_port(log, server)
            url = f"https://127.0.0.1:{logged_port(log, server, face='http port')}"
            command = [cli, "--server", f"127.0.0.1:{port}", "--token-file", str(token_file),
                       "--tls-ca", str(cert)]
            subprocess.run(command + ["ingest", "--tag", "cmu"] + [str(t) for t in TAKES],
                           check=True)
            subprocess.run(command + ["space", "create", "body", "--skeleton", "1", "--rate",
                                      "30"], check=True, stdout=subprocess.DEVNULL)
            take = work / "take_01_01.bvh"
            request = urllib.request.Request(f"{url}/v1/clips/1/bvh?from=0&to=479",
                                             headers={"Authorization": f"Bearer {TOKEN}"})
            with urllib.request.urlopen(request, timeout=60,
                                        context=ssl.create_default_context(cafile=cert)) as answer:
                take.write_bytes(answer.read())
            addon_zip = work / "motiondb_blender.zip"
            subprocess.run([str(repo / "scripts" / "blender-addon.sh"), str(addon_zip)],
                           check=True)
            # The add-on installs into a user scripts folder of the test's own, not the home's.
            env = dict(os.environ, BLENDER_USER_SCRIPTS=str(work / "blender-scripts"),
                       BLENDER_USER_CONFIG=str(work / "blender-config"))
            script = pathlib.Path(__file__).resolve().parent / "addon_in_blender.py"
            result = subprocess.run(
                [blender, "-b", "--factory-startup", "--python-exit-code", "1", "--python",
                 str(script), "--", str(addon_zip), url, str(token_file), str(cert), str(take),
                 f"http://127.0.0.1:{dead.getsockname()[1]}", str(out_dir / "blender_addon.png")],
                env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                timeout=300)
            # Blender's own chatter (EGL, importer timings) is left out; the checks' lines stay.
            print("\n".join(line for line in result.stdout.splitlines()
                            if not line.startswith(("EGL", "\t"))))
            passed = result.returncode == 0 and "ADDON CHECKS PASSED" in result.stdout
            if not passed:
                print(f"FAILED: blender exited with {result.returncode}")
        finally:
            dead.close()
            server.send_signal(signal.SIGTERM)
            code = server.wait(timeout=60)
        if code != 0:
            print(f"FAILED: motiondb-server exited with {code}:\n{log.read_text()[-3000:]}")
        return 0 if passed and code == 0 else 1


if __name__ == "__main__":
    sys.exit(main())
