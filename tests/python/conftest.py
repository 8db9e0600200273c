"""A real tumble-server per test, started by the test (the binary named by $TUMBLE_SERVER_BINARY,
which ctest sets), on a port the system picks."""

import os
import signal
import socket
import subprocess

import pytest

import tumble

EMPTY_SCENE = {"name": "empty", "bodies": []}


class Server:
    def __init__(self, *args, env=None):
        binary = os.environ["TUMBLE_SERVER_BINARY"]
        self.process = subprocess.Popen(
            [binary, "--listen", "127.0.0.1:0", "--paused", *args],
            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
            env={**os.environ, **(env or {})})
        line = self.process.stdout.readline()
        if "listening on " not in line:
            self.process.kill()
            raise RuntimeError(f"tumble-server did not start: {line}{self.process.stdout.read()}")
        self.address = line.split("listening on ")[1].split()[0]

    def stop(self):
        """SIGTERM; the server's exit code and its last words."""
        self.process.send_signal(signal.SIGTERM)
        try:
            rest, _ = self.process.communicate(timeout=20)
        except subprocess.TimeoutExpired:
            self.process.kill()
            rest, _ = self.process.communicate()
        return self.process.returncode, rest


@pytest.fixture
def server():
    running = Server()
    yield running
    code, rest = running.stop()
    assert code == 0, rest


@pytest.fixture
def world(server):
    with tumble.connect(server.address) as connected:
        yield connected


@pytest.fixture
def empty_world(world):
    """No bodies; a world that stands still unless told."""
    world.load_scene(EMPTY_SCENE)
    return world


def free_port():
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]
