"""Held forces, gravity scale, damping and collision filters from Python: spawn options and
set_state, read back by body(); the same answers on a server and in this process; refusals name
the field."""

import math

import pytest

import tumble

DT = 1.0 / 60


def float_and_push(world):
    """A floating 2 kg ball pushed by a held 3 N along x for a second, then a filter change."""
    world.load_scene({"name": "empty", "bodies": []})
    world.settings(real_time_factor=0, dt=DT)
    ball = world.spawn_sphere(0.5, mass=2.0, position=(0, 0, 10), gravity_scale=0.0,
                              force=(3.0, 0.0, 0.0), linear_damping=0.0,
                              collision_layers=2, collision_mask=0xFFFFFFFE)
    world.step(60)
    return ball, world.body(ball)


@pytest.mark.parametrize("where", ["remote", "local"])
def test_a_held_force_accelerates_a_floating_ball(world, where):
    world = world if where == "remote" else tumble.World()
    ball, state = float_and_push(world)
    assert state.linear_velocity[0] == pytest.approx(1.5, abs=1e-9)
    assert state.position[2] == pytest.approx(10.0, abs=1e-12)
    assert state.gravity_scale == 0.0
    assert list(state.force) == [3.0, 0.0, 0.0]
    assert (state.collision_layers, state.collision_mask) == (2, 0xFFFFFFFE)
    # Off with the force, on with damping and gravity at half strength.
    world.set_state(ball, force=(0, 0, 0), linear_damping=1.0, gravity_scale=0.5)
    world.step(60)
    later = world.body(ball)
    assert later.linear_damping == 1.0 and later.gravity_scale == 0.5
    assert 0 < later.linear_velocity[0] < 1.5 * math.exp(-1.0) * 1.05
    assert later.linear_velocity[2] < 0


def test_forces_give_the_same_bits_here_and_on_a_server(world):
    _, remote = float_and_push(world)
    _, local = float_and_push(tumble.World())
    assert list(remote.position) == list(local.position)
    assert list(remote.linear_velocity) == list(local.linear_velocity)


def test_a_force_at_a_point_spins_the_ball(world):
    world.load_scene({"name": "empty", "bodies": []})
    world.settings(real_time_factor=0, dt=DT)
    ball = world.spawn_sphere(0.5, mass=2.0, position=(0, 0, 10), gravity_scale=0.0)
    world.set_state(ball, force=(0, 1, 0), force_point=(0.5, 0, 10))
    assert world.body(ball).torque[2] == pytest.approx(0.5, abs=1e-15)
    world.step(60)
    assert world.body(ball).angular_velocity[2] == pytest.approx(0.5 / 0.2, abs=1e-9)


def test_filters_keep_bodies_apart(world):
    world.load_scene({"name": "empty", "bodies": []})
    world.settings(real_time_factor=0, dt=DT)
    world.spawn_ground()
    ghost = world.spawn_box((1, 1, 1), mass=1.0, position=(0, 0, 2), collision_mask=0)
    world.step(60)
    assert world.body(ghost).position[2] < 0  # it met nothing, not even the ground


def test_bad_forces_and_filters_are_refused_naming_the_field(world):
    world.load_scene({"name": "empty", "bodies": []})
    ball = world.spawn_sphere(0.5, mass=1.0, position=(0, 0, 3))
    with pytest.raises(tumble.Error, match=r"gravity_scale: must be finite"):
        world.spawn_sphere(0.5, gravity_scale=1e9)
    with pytest.raises(tumble.Error, match=r"linear_damping: must be in"):
        world.set_state(ball, linear_damping=-1)
    with pytest.raises(tumble.Error, match=r"force: it would change the speed"):
        world.set_state(ball, force=(1e20, 0, 0))
    with pytest.raises(tumble.Error, match=r"force_point: needs a force"):
        world.set_state(ball, force_point=(0, 0, 0))
    with pytest.raises(tumble.Error, match=r"force: a static body does not move"):
        world.spawn_ground(force=(1, 0, 0))
    with pytest.raises(tumble.ArgumentError, match=r"collision_mask: must be an integer"):
        world.set_state(ball, collision_mask=-1)
    with pytest.raises(tumble.ArgumentError, match=r"bodies\[0\]\.collision_layers"):
        world.spawn_sphere(0.5, collision_layers=2**32)
    state = world.body(ball)
    assert state.linear_damping == 0 and list(state.force) == [0, 0, 0]
