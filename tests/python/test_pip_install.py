"""`pip install ./client/python` into a virtual environment, as a user does (docs/PYTHON.md):
nothing downloaded (--no-index), Debian's grpcio, protobuf and numpy seen through
--system-site-packages; then the README's example and the in-process engine run from it."""

import os
import subprocess
import sys

from test_python_readme import readme_example

SOURCE = os.environ["TUMBLE_SOURCE_DIR"]


def installed_python(tmp_path):
    venv = tmp_path / "venv"
    subprocess.run([sys.executable, "-m", "venv", "--system-site-packages", venv], check=True,
                   timeout=120)
    pip = subprocess.run(
        [venv / "bin" / "pip", "install", "--no-index", "--config-settings",
         f"build-dir={os.environ['TUMBLE_BUILD_DIR']}", os.path.join(SOURCE, "client", "python")],
        capture_output=True, text=True, timeout=600, env=_outside_the_tree())
    assert pip.returncode == 0, pip.stdout + pip.stderr
    return venv / "bin" / "python"


def _outside_the_tree(**extra):
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    return {**env, "PYTHONDONTWRITEBYTECODE": "1", **extra}


def run(python, code, cwd, **env):
    done = subprocess.run([python, "-c", code], capture_output=True, text=True, timeout=120,
                          cwd=cwd, env=_outside_the_tree(**env))
    assert done.returncode == 0, done.stderr
    return done.stdout


def test_pip_installs_the_client_and_the_engine_and_the_readme_example_runs(server, tmp_path):
    python = installed_python(tmp_path)
    where = run(python, "import tumble; print(tumble.__file__)", tmp_path)
    assert where.startswith(str(tmp_path / "venv")), where
    example = readme_example().replace("127.0.0.1:50051", server.address)
    lines = run(python, example, tmp_path).splitlines()
    assert len(lines) == 60
    # TUMBLE_SERVER names the server when connect() is given no address.
    assert run(python, "import tumble; print(tumble.connect().address)", tmp_path,
               TUMBLE_SERVER=server.address).strip() == server.address
    local = ("import tumble; w = tumble.World(); w.spawn_ground(); "
             "b = w.spawn_sphere(0.5, position=(0, 0, 2)); w.step(120); "
             "print(round(float(w.states([b]).positions[0, 2]), 3))")
    assert run(python, local, tmp_path).strip() == "0.5"
