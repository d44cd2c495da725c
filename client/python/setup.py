"""The motiondb Python client: `pip install ./client/python` (offline, on Debian's
python3-setuptools, python3-wheel, python3-grpcio and python3-protobuf).

The gRPC stubs (motiondb/v1/*_pb2*.py) are not kept in the source tree: the install generates
them from the repository's proto/ with protoc and grpc_python_plugin (Debian's protobuf-compiler
and protobuf-compiler-grpc, which building the server needs too) into the package it installs.
Environment:
  MOTIONDB_STUBS_DIR            a folder holding ready stubs as motiondb/v1/*.py (e.g. the
                                build's build/python): copied instead of generating
  MOTIONDB_PROTO_DIR            the folder holding motiondb/v1/*.proto (default ../../proto)
  MOTIONDB_PROTOC               protoc (default: protoc on PATH)
  MOTIONDB_GRPC_PYTHON_PLUGIN   grpc_python_plugin (default: on PATH)
"""
import atexit
import os
import pathlib
import shutil
import subprocess
import tempfile

from setuptools import setup
from setuptools.command.build_py import build_py

HERE = pathlib.Path(__file__).resolve().parent


def _tool(variable, name):
    path = os.environ.get(variable) or shutil.which(name)
    if not path:
        raise SystemExit(f"motiondb: {name} not found (install it, or set {variable}, or "
                         "MOTIONDB_STUBS_DIR to a folder of generated stubs)")
    return path


class BuildWithStubs(build_py):
    """build_py, then the motiondb.v1 stubs into the build folder's motiondb/v1/."""

    def run(self):
        super().run()
        target = pathlib.Path(self.build_lib) / "motiondb" / "v1"
        target.mkdir(parents=True, exist_ok=True)
        stubs = os.environ.get("MOTIONDB_STUBS_DIR")
        if stubs:
            source = pathlib.Path(stubs) / "motiondb" / "v1"
            files = sorted(source.glob("*_pb2*.py"))
            if not files:
                raise SystemExit(f"motiondb: no *_pb2*.py in {source}")
            for file in files:
                shutil.copy(file, target / file.name)
        else:
            proto_dir = pathlib.Path(os.environ.get("MOTIONDB_PROTO_DIR", HERE.parent.parent / "proto"))
            protos = sorted(str(p.relative_to(proto_dir))
                            for p in (proto_dir / "motiondb" / "v1").glob("*.proto"))
            if not protos:
                raise SystemExit(f"motiondb: no motiondb/v1/*.proto under {proto_dir} "
                                 "(set MOTIONDB_PROTO_DIR or MOTIONDB_STUBS_DIR)")
            subprocess.run([_tool("MOTIONDB_PROTOC", "protoc"), f"--proto_path={proto_dir}",
                            f"--python_out={self.build_lib}", f"--grpc_python_out={self.build_lib}",
                            "--plugin=protoc-gen-grpc_python="
                            + _tool("MOTIONDB_GRPC_PYTHON_PLUGIN", "grpc_python_plugin"), *protos],
                           check=True)
        (target / "__init__.py").write_text('"""Generated gRPC stubs of motiondb.v1."""\n')


# setuptools builds in the source folder by default (build/, motiondb.egg-info): build in a
# temporary folder instead, so that installing leaves the checkout as it was.
_BUILD = tempfile.mkdtemp(prefix="motiondb-python-build-")
atexit.register(shutil.rmtree, _BUILD, ignore_errors=True)

setup(
    name="motiondb",
    version="0.1.0",
    description="Python client of the motiondb motion-search server",
    packages=["motiondb"],
    package_data={"motiondb": ["py.typed"]},
    python_requires=">=3.9",
    # Debian's python3-grpcio and python3-protobuf; not declared as requirements, so that pip
    # never tries to fetch them (they are not pip-visible distributions on every system).
    cmdclass={"build_py": BuildWithStubs},
    options={"build": {"build_base": os.path.join(_BUILD, "build")},
             "egg_info": {"egg_base": _BUILD}},
)
