"""Refusals raise tumble.Error with the gRPC code and the server's message, and leave the world
as it was; an unreachable or unwelcoming server raises at connect."""

import subprocess
import time

import grpc
import pytest

import tumble
from conftest import Server, free_port


def state_of(world):
    """Everything a refusal must leave alone: ids, poses, the step."""
    return world.info().step, [(b.id, b.position.tolist(), b.orientation.tolist())
                               for b in world.bodies()]


def test_a_refused_batch_names_the_field_and_changes_nothing(world):
    before = state_of(world)
    specs = [tumble.BodySpec(tumble.Box((1, 1, 1)), pos=(0, 0, 5)),
             tumble.BodySpec(tumble.Sphere(0.5), mass=-1.0)]
    with pytest.raises(tumble.Error) as refused:
        world.spawn_many(specs)
    assert refused.value.code == grpc.StatusCode.INVALID_ARGUMENT
    assert "bodies[1].mass" in refused.value.message
    assert refused.value.call == "SpawnBodies"
    assert state_of(world) == before

    with pytest.raises(tumble.Error) as too_fast:
        world.spawn_box(size=(1, 1, 1), pos=(0, 0, 5), angular_velocity=(1e308, 0, 0))
    assert "bodies[0].angular_velocity" in too_fast.value.message
    assert "max_angular_speed" in str(too_fast.value)
    assert state_of(world) == before


def test_unknown_ids_are_not_found_and_nothing_is_removed(world):
    before = state_of(world)
    known = before[1][0][0]
    with pytest.raises(tumble.Error) as unknown:
        world.remove([known, 10**15])
    assert unknown.value.code == grpc.StatusCode.NOT_FOUND
    assert "ids[1]" in unknown.value.message
    with pytest.raises(tumble.Error) as push:
        world.apply_impulse(10**15, (1, 0, 0))
    assert push.value.code == grpc.StatusCode.NOT_FOUND
    with pytest.raises(tumble.Error):
        world.body(10**15)
    assert state_of(world) == before


def test_malformed_arguments_are_refused_before_sending(world):
    before = state_of(world)
    cases = [
        lambda: world.spawn_box(size=(1, 1), pos=(0, 0, 5)),
        lambda: world.spawn_sphere("big"),
        lambda: world.spawn(object()),
        lambda: world.spawn_hull([[0, 0], [1, 1]]),
        lambda: world.spawn_box(size=(1, 1, 1), color=(2, 0, 0)),
        lambda: world.settings(solver="fastest"),
        lambda: world.step(0),
        lambda: world.remove(["one"]),
        lambda: world.restore("not bytes"),
        lambda: world.load_scene(42),
        lambda: world.frames(count=-1),
    ]
    for case in cases:
        with pytest.raises(tumble.ArgumentError) as error:
            case()
        # Both our exception and Python's own: callers may catch either.
        assert isinstance(error.value, ValueError) and isinstance(error.value, tumble.Error)
        assert error.value.code == grpc.StatusCode.INVALID_ARGUMENT
    assert state_of(world) == before


def test_bad_scenes_settings_and_snapshots_leave_the_world_alone(world):
    before = state_of(world)
    with pytest.raises(tumble.Error) as scene:
        world.load_scene({"bodies": [{"shape": "box", "size": [1, -1, 1]}]})
    assert "bodies[0].size[1]" in scene.value.message
    with pytest.raises(tumble.Error) as unknown:
        world.load_builtin("pile:many")
    assert unknown.value.code == grpc.StatusCode.INVALID_ARGUMENT
    with pytest.raises(tumble.Error) as dt:
        world.settings(dt=-1)
    assert "dt" in dt.value.message
    with pytest.raises(tumble.Error) as passes:
        world.settings(iterations=20, joint_position_passes=-1)
    assert "joint_position_passes" in passes.value.message
    assert world.settings().iterations == 10
    with pytest.raises(tumble.ArgumentError) as sweeps:
        world.settings(iterations=2.5)
    assert "iterations" in sweeps.value.message
    with pytest.raises(tumble.ArgumentError) as huge:
        world.settings(substeps=2**40)
    assert "substeps" in huge.value.message
    with pytest.raises(tumble.Error) as snapshot:
        world.restore(b"not a snapshot")
    assert snapshot.value.code == grpc.StatusCode.INVALID_ARGUMENT
    assert state_of(world) == before
    assert world.settings().dt == 1 / 60


def test_an_unreachable_server_raises_at_connect_naming_the_address():
    address = f"127.0.0.1:{free_port()}"
    started = time.monotonic()
    with pytest.raises(tumble.Error) as unreachable:
        tumble.connect(address, timeout=5)
    assert time.monotonic() - started < 10
    assert unreachable.value.code in (grpc.StatusCode.UNAVAILABLE,
                                      grpc.StatusCode.DEADLINE_EXCEEDED)
    assert address in str(unreachable.value)
    assert unreachable.value.call == "connect"


def test_a_token_is_required_when_the_server_has_one():
    server = Server(env={"TUMBLE_TOKEN": "s3cret"})
    try:
        with pytest.raises(tumble.Error) as refused:
            tumble.connect(server.address, token="wrong")
        assert refused.value.code == grpc.StatusCode.UNAUTHENTICATED
        assert server.address in str(refused.value)
        with pytest.raises(tumble.Error):
            tumble.connect(server.address, token="")
        with tumble.connect(server.address, token="s3cret") as world:
            assert world.info().body_count == 51
            box = world.spawn_box(size=(1, 1, 1), pos=(0, 0, 9))
            with world.frames(ids=[box]) as frames:
                assert next(frames).ids.tolist() == [box]
    finally:
        assert server.stop()[0] == 0


def test_tls_with_the_servers_certificate_authority(tmp_path):
    made = subprocess.run(
        ["openssl", "req", "-x509", "-newkey", "rsa:2048", "-nodes", "-days", "2",
         "-subj", "/CN=localhost", "-addext", "subjectAltName=DNS:localhost,IP:127.0.0.1",
         "-keyout", str(tmp_path / "key.pem"), "-out", str(tmp_path / "cert.pem")],
        capture_output=True, text=True, timeout=60)
    assert made.returncode == 0, made.stderr
    server = Server("--tls-cert", str(tmp_path / "cert.pem"), "--tls-key", str(tmp_path / "key.pem"))
    try:
        with tumble.connect(server.address, tls_ca=tmp_path / "cert.pem") as world:
            assert world.info().body_count == 51
        with pytest.raises(tumble.Error):  # plaintext to a TLS server
            tumble.connect(server.address, timeout=2)
        with pytest.raises(tumble.ArgumentError) as missing:
            tumble.connect(server.address, tls_ca=tmp_path / "absent.pem")
        assert "absent.pem" in str(missing.value)
    finally:
        assert server.stop()[0] == 0
