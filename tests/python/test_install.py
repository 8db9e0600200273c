"""An installed Tumble, found the way a user's own project finds it: `cmake --install` into a
temporary prefix, then the programs of tests/install built with find_package(Tumble) and with
pkg-config, and run."""

import glob
import os
import shlex
import subprocess

from conftest import Server

SOURCE = os.path.join(os.environ["TUMBLE_SOURCE_DIR"], "tests", "install")


def run(command, env=None):
    done = subprocess.run([str(part) for part in command], capture_output=True, text=True,
                          timeout=240, env={**os.environ, **(env or {})})
    assert done.returncode == 0, f"{shlex.join(map(str, command))}\n{done.stdout}{done.stderr}"
    return done.stdout


def install(prefix):
    run(["cmake", "--install", os.environ["TUMBLE_BUILD_DIR"], "--prefix", prefix])
    [pc_dir] = {os.path.dirname(path) for path in glob.glob(f"{prefix}/**/tumble.pc", recursive=True)}
    return pc_dir


def built_with_cmake(prefix, build, components):
    run(["cmake", "-S", SOURCE, "-B", build, f"-DCMAKE_PREFIX_PATH={prefix}",
         f"-DTUMBLE_COMPONENTS={';'.join(components)}", "-DCMAKE_BUILD_TYPE=Release"])
    run(["cmake", "--build", build])
    return build


def built_with_pkg_config(pc_dir, package, source, program):
    env = {"PKG_CONFIG_PATH": pc_dir}
    flags = run(["pkg-config", "--cflags", "--libs", package], env=env).split()
    run(["g++", "-O1", os.path.join(SOURCE, source), "-o", program, *flags])
    return program


def test_the_engine_builds_against_an_install_from_cmake_and_pkg_config(tmp_path):
    prefix = tmp_path / "prefix"
    pc_dir = install(prefix)
    assert (prefix / "include/tumble/physics/world.h").is_file()
    for program in ("tumble", "tumble-server", "tumble-run"):
        assert os.access(prefix / "bin" / program, os.X_OK), program
    assert (prefix / "share/tumble/shaders/phong.frag").is_file()
    assert "-std=c++20" in run(["pkg-config", "--cflags", "tumble"], env={"PKG_CONFIG_PATH": pc_dir})

    build = built_with_cmake(prefix, tmp_path / "cmake", ["physics"])
    assert "box at z = 0.50" in run([build / "engine_user"])
    program = built_with_pkg_config(pc_dir, "tumble", "engine_user.cc", tmp_path / "engine_pc")
    assert "box at z = 0.50" in run([program])


def test_the_client_builds_against_an_install_and_talks_to_a_server(tmp_path):
    prefix = tmp_path / "prefix"
    pc_dir = install(prefix)
    assert (prefix / "include/tumble/client.h").is_file()
    assert (prefix / "include/tumble/v1/world.grpc.pb.h").is_file()
    build = built_with_cmake(prefix, tmp_path / "cmake", ["physics", "client"])
    program = built_with_pkg_config(pc_dir, "tumble-client", "client_user.cc", tmp_path / "client_pc")
    server = Server()
    try:
        for user in (build / "client_user", program):
            said = run([user, server.address])
            assert "at z = 3.00 m" in said and "/nonexistent.mcap: cannot open" in said
    finally:
        code, rest = server.stop()
    assert code == 0, rest
    # The client links none of the engine: its pkg-config file does not ask for it.
    libs = run(["pkg-config", "--libs", "tumble-client"], env={"PKG_CONFIG_PATH": pc_dir})
    assert "-ltumble_physics" not in libs and "-lqhull_r" not in libs
