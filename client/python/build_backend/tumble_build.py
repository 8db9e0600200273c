"""The build backend of `pip install ./client/python` (PEP 517), with no dependencies of its own,
so that pip downloads nothing.

It builds the CMake target tumble_python (the package with its protobuf stubs and, where
pybind11 is installed, the engine's module tumble._engine) for the interpreter running pip, and
packs what CMake assembled in BUILD/python/tumble into a wheel. BUILD is the build folder given
by `--config-settings build-dir=PATH` (or $TUMBLE_BUILD_DIR), built incrementally; without one, a
temporary folder configured for the package alone (a few minutes on 2 cores)."""

import base64
import hashlib
import os
import shutil
import subprocess
import sys
import sysconfig
import tempfile
import zipfile
from pathlib import Path

SOURCE = Path(__file__).resolve().parents[3]
NAME, VERSION = "tumble", "0.1.0"
SUMMARY = ("Tumble: a rigid-body physics engine in this process (tumble.World) or a server's "
           "world over gRPC (tumble.connect)")


def get_requires_for_build_wheel(config_settings=None):
    return []


def get_requires_for_build_sdist(config_settings=None):
    return []


def prepare_metadata_for_build_wheel(metadata_directory, config_settings=None):
    """The metadata alone, so that pip does not build the wheel twice to learn it."""
    dist_info = Path(metadata_directory) / f"{NAME}-{VERSION}.dist-info"
    dist_info.mkdir(parents=True, exist_ok=True)
    (dist_info / "METADATA").write_text(_metadata())
    return dist_info.name


def build_wheel(wheel_directory, config_settings=None, metadata_directory=None):
    build, temporary = _build_folder(config_settings or {})
    try:
        return _pack(build / "python" / "tumble", wheel_directory)
    finally:
        if temporary:
            shutil.rmtree(build, ignore_errors=True)


def _pack(package, wheel_directory):
    engine = list(package.glob("_engine*.so"))
    if engine and not engine[0].name.endswith(sysconfig.get_config_var("EXT_SUFFIX")):
        raise RuntimeError(f"{engine[0]} was built for another Python than {sys.executable}; "
                           "build-dir must be configured with -DTUMBLE_PYTHON=" + sys.executable)
    tag = _platform_tag() if engine else "py3-none-any"
    wheel = Path(wheel_directory) / f"{NAME}-{VERSION}-{tag}.whl"
    dist_info = f"{NAME}-{VERSION}.dist-info"
    files = {}
    for path in sorted(package.rglob("*")):
        if path.is_file() and "__pycache__" not in path.parts:
            files[f"tumble/{path.relative_to(package).as_posix()}"] = path.read_bytes()
    files[f"{dist_info}/METADATA"] = _metadata().encode()
    files[f"{dist_info}/WHEEL"] = (
        "Wheel-Version: 1.0\nGenerator: tumble_build\n"
        f"Root-Is-Purelib: {'false' if engine else 'true'}\nTag: {tag}\n").encode()
    files[f"{dist_info}/top_level.txt"] = b"tumble\n"
    record = [f"{name},sha256={_digest(data)},{len(data)}" for name, data in files.items()]
    record.append(f"{dist_info}/RECORD,,")
    files[f"{dist_info}/RECORD"] = ("\n".join(record) + "\n").encode()
    with zipfile.ZipFile(wheel, "w", zipfile.ZIP_DEFLATED) as archive:
        for name, data in files.items():
            info = zipfile.ZipInfo(name, date_time=(2026, 1, 1, 0, 0, 0))
            info.external_attr = (0o755 if name.endswith(".so") else 0o644) << 16
            archive.writestr(info, data, zipfile.ZIP_DEFLATED)
    return wheel.name


def _build_folder(settings):
    given = settings.get("build-dir") or os.environ.get("TUMBLE_BUILD_DIR")
    if given:
        build = Path(given).resolve()
        if not (build / "CMakeCache.txt").is_file():
            raise RuntimeError(f"build-dir: {build} is not a configured CMake build folder")
        temporary = False
    else:
        temporary = True
        build = Path(tempfile.mkdtemp(prefix="tumble-wheel-"))
        _run(["cmake", "-S", SOURCE, "-B", build, "-DCMAKE_BUILD_TYPE=Release",
              f"-DTUMBLE_PYTHON={sys.executable}", "-DTUMBLE_BUILD_TESTS=OFF",
              "-DTUMBLE_BUILD_BENCH=OFF", "-DTUMBLE_BUILD_VIEWER=OFF", "-DTUMBLE_BUILD_DDS=OFF"])
    _run(["cmake", "--build", build, "--target", "tumble_python", "-j", str(os.cpu_count() or 1)])
    return build, temporary


def _run(command):
    # pip runs this backend with PYTHONPATH pointing at its isolated environment, whose
    # sitecustomize hides the interpreter's own site-packages; CMake's checks of grpc, protobuf and
    # numpy (and pybind11's of the interpreter) must see the environment the package will run in.
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONNOUSERSITE")}
    done = subprocess.run([str(part) for part in command], stdout=subprocess.PIPE,
                          stderr=subprocess.STDOUT, text=True, env=env)
    if done.returncode != 0:
        raise RuntimeError(f"{' '.join(map(str, command))} failed:\n{done.stdout[-4000:]}")


def _platform_tag():
    interpreter = f"cp{sys.version_info[0]}{sys.version_info[1]}"
    platform = sysconfig.get_platform().replace("-", "_").replace(".", "_")
    return f"{interpreter}-{interpreter}-{platform}"


def _metadata():
    return (f"Metadata-Version: 2.1\nName: {NAME}\nVersion: {VERSION}\nSummary: {SUMMARY}\n"
            "Requires-Python: >=3.9\nRequires-Dist: grpcio\nRequires-Dist: protobuf\n"
            "Requires-Dist: numpy\n")


def _digest(data):
    return base64.urlsafe_b64encode(hashlib.sha256(data).digest()).rstrip(b"=").decode()
