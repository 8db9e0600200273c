"""Joints from Python (world.hinge, world.joint, world.drive, world.joints): the same calls on a
server and on the engine in this process, with the same answers; refusals name the field."""

import math

import pytest

import tumble


def spin_a_plate(world):
    """A plate hinged to the world about z, its motor at 2 rad/s, then -3 rad/s."""
    world.load_scene({"name": "empty", "bodies": []})
    world.settings(real_time_factor=0)
    plate = world.spawn_box(size=(1, 1, 0.2), mass=1.0, position=(0, 0, 5))
    hinge = world.hinge(plate, anchor=(0, 0, 5), axis=(0, 0, 1), motor=(2.0, 100.0),
                        limits=(-math.pi, math.pi))
    world.step(60)
    first = world.joints([hinge])[0]
    world.drive(hinge, motor=(-3.0, 100.0))
    world.step(30)
    return hinge, first, world.joints()[0]


@pytest.mark.parametrize("where", ["remote", "local"])
def test_a_motor_drives_a_hinge_and_changes_while_running(world, where):
    hinge, first, later = spin_a_plate(world if where == "remote" else tumble.World())
    assert first["id"] == hinge and first["kind"] == "hinge" and first["b"] == 0
    assert first["speed"] == pytest.approx(2.0, abs=1e-9)
    assert abs(first["force"][2]) == pytest.approx(9.81, rel=1e-2)  # it holds the plate up
    assert later["speed"] == pytest.approx(-3.0, abs=1e-9)
    assert later["error"] < 1e-6


def test_the_same_script_gives_the_same_bits_here_and_on_a_server(world):
    _, _, remote = spin_a_plate(world)
    _, _, local = spin_a_plate(tumble.World())
    for key in ("position", "speed", "effort"):
        assert remote[key] == local[key]


def test_bad_joints_are_refused_naming_the_field_and_removal_is_all_or_nothing(world):
    world.load_scene({"name": "empty", "bodies": []})
    ball = world.spawn_sphere(0.1, mass=1.0, position=(0, 0, 3))
    with pytest.raises(tumble.Error, match=r"joints\[0\]\.axis: must not be zero"):
        world.hinge(ball, anchor=(0, 0, 3), axis=(0, 0, 0))
    with pytest.raises(tumble.Error, match=r"joints\[0\]\.motor: only hinges and sliders"):
        world.joint("ball", ball, anchor=(0, 0, 4), motor=(1, 1))
    with pytest.raises(tumble.Error, match="kind: must be one of"):
        world.joint("rope", ball)
    rod = world.joint("distance", ball, anchor=(0, 0, 3), anchor_b=(0, 0, 4))
    assert world.info().joint_count == 1
    with pytest.raises(tumble.Error, match=r"ids\[1\]: no joint"):
        world.remove_joints([rod, 987654])
    assert len(world.joints()) == 1
    world.remove_joints(rod)
    assert world.joints() == []


@pytest.mark.parametrize("where", ["remote", "local"])
def test_frames_carry_the_joints_states_and_their_catalogue(world, where):
    """frames(joints=True): every frame has each joint's state as GetJoints reads it, the first
    frame describes every joint, later ones only what was added or removed."""
    world = world if where == "remote" else tumble.World()
    world.load_scene({"name": "empty", "bodies": []})
    world.settings(real_time_factor=0)
    plate = world.spawn_box(size=(1, 1, 0.2), mass=1.0, position=(0, 0, 5))
    hinge = world.hinge(plate, anchor=(0, 0, 5), axis=(0, 0, 1), motor=(2.0, 100.0))
    stream = world.frames(joints=True, count=40 if where == "local" else None)
    frames = iter(stream)
    # The stream's first frame is the state now; the steps come after it is open (stepped
    # before, a subscription that opened after the 30 steps waited for frames that never came).
    first = next(frames)
    if where == "remote":
        world.step(30)
    assert [d["id"] for d in first.joints_added] == [hinge]
    assert first.joints_added[0]["kind"] == "hinge" and first.joints_added[0]["b"] == 0
    assert list(first.joints.ids) == [hinge]
    later = next(frames)
    assert later.joints_added == [] and later.joints_removed == []
    while later.step < 5:  # past the frames of the state before the steps
        later = next(frames)
    assert later.joints.speeds[0] == pytest.approx(2.0, abs=1e-6)
    assert abs(later.joints.forces[0][2]) == pytest.approx(9.81, rel=1e-2)
    assert stream.joints[hinge]["kind"] == "hinge"
    # A frame without joints asked for has none.
    if where == "local":
        plain = next(iter(world.frames(count=1)))
        assert plain.joints is None and plain.joints_added == []
    stream.close()


@pytest.mark.parametrize("where", ["remote", "local"])
def test_joint_friction_holds_a_level_bar_and_is_checked(world, where):
    """A 1 kg bar 1 m long held level on a hinge at its end: friction above its weight's torque
    (m g L / 2 = 4.905 N m) holds it still, giving that torque; below zero is refused."""
    world = world if where == "remote" else tumble.World()
    world.load_scene({"name": "empty", "bodies": []})
    world.settings(real_time_factor=0)
    bar = world.spawn_box(size=(1, 0.04, 0.04), mass=1.0, position=(0.5, 0, 5))
    held = world.hinge(bar, anchor=(0, 0, 5), axis=(0, 1, 0), friction=6.0)
    world.step(60)
    state = world.joints([held])[0]
    assert abs(state["effort"]) == pytest.approx(9.81 / 2, rel=1e-3)
    assert abs(state["speed"]) < 1e-9
    with pytest.raises(tumble.Error, match=r"joints\[0\]\.friction: must be finite, >= 0"):
        world.hinge(bar, anchor=(0, 0, 5), axis=(0, 1, 0), friction=-1.0)
