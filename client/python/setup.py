"""Builds the geodex package: the geodex.v1 modules are generated from the repository's
proto/geodex/v1/geodex.proto with protoc and grpc_python_plugin (Debian: protobuf-compiler,
protobuf-compiler-grpc), and google.rpc's error details are kept as a descriptor set for
geodex.errors. GEODEX_PROTO_DIR overrides where the protos are (default ../../proto)."""
import os
import re
import shutil
import subprocess
import tempfile

from setuptools import setup
from setuptools.command.build_py import build_py

HERE = os.path.dirname(os.path.abspath(__file__))


def _project_version():
    """The one version: CMakeLists.txt's project(geodex VERSION x.y.z), next to the protos."""
    proto_dir = os.environ.get("GEODEX_PROTO_DIR", os.path.join(HERE, "..", "..", "proto"))
    cmake = os.path.join(proto_dir, "..", "CMakeLists.txt")
    try:
        with open(cmake, encoding="utf-8") as f:
            found = re.search(r"project\(geodex VERSION ([0-9.]+)", f.read())
    except OSError:
        found = None
    if not found:
        raise SystemExit("geodex: no project version in " + cmake + " (set GEODEX_PROTO_DIR)")
    return found.group(1)


VERSION = _project_version()


class BuildWithStubs(build_py):
    def run(self):
        super().run()
        proto_dir = os.environ.get("GEODEX_PROTO_DIR", os.path.join(HERE, "..", "..", "proto"))
        plugin = shutil.which("grpc_python_plugin")
        protoc = shutil.which("protoc")
        if not (plugin and protoc and os.path.isdir(proto_dir)):
            raise SystemExit("geodex: building needs protoc, grpc_python_plugin and the protos in "
                             + proto_dir + " (set GEODEX_PROTO_DIR)")
        subprocess.check_call([
            protoc, "--proto_path=" + proto_dir, "--python_out=" + self.build_lib,
            "--grpc_python_out=" + self.build_lib, "--plugin=protoc-gen-grpc_python=" + plugin,
            "geodex/v1/geodex.proto"])
        open(os.path.join(self.build_lib, "geodex", "v1", "__init__.py"), "a").close()
        with open(os.path.join(self.build_lib, "geodex", "_version.py"), "w") as f:
            f.write('__version__ = "%s"  # generated from CMakeLists.txt\'s project version\n' % VERSION)
        subprocess.check_call([
            protoc, "--proto_path=" + proto_dir, "--include_imports",
            "--descriptor_set_out=" + os.path.join(self.build_lib, "geodex", "_rpc_details.desc"),
            "google/rpc/status.proto", "google/rpc/error_details.proto"])


# Build products (build/, geodex.egg-info) go to a directory of their own, never into the source
# tree: `pip install ./client/python` leaves the checkout as it was.
_OUT = tempfile.mkdtemp(prefix="geodex-build-")
setup(version=VERSION, cmdclass={"build_py": BuildWithStubs},
      options={"build": {"build_base": os.path.join(_OUT, "build")},
               "egg_info": {"egg_base": _OUT}})
