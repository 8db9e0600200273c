"""Kinematic bodies from Python: spawned with kinematic=True, steered by set_state, read back by
body() and the frames' descriptions; the same bits on a server and in this process; refusals name
the field."""

import pytest

import tumble

DT = 1.0 / 60


def conveyor(world):
    """A deck moving at 0.5 m/s along x under a box, for a second."""
    world.load_scene({"name": "empty", "bodies": []})
    world.settings(real_time_factor=0, dt=DT)
    deck = world.spawn_box((4, 4, 0.2), position=(0, 0, 0), linear_velocity=(0.5, 0, 0),
                           kinematic=True)
    rider = world.spawn_box((0.5, 0.5, 0.5), mass=1.0, position=(0, 0, 0.35),
                            linear_velocity=(0.5, 0, 0))
    world.step(60)
    return deck, rider


@pytest.mark.parametrize("where", ["remote", "local"])
def test_a_kinematic_deck_carries_a_box_and_is_steered(world, where):
    world = world if where == "remote" else tumble.World()
    deck, rider = conveyor(world)
    state = world.body(deck)
    assert state.kinematic and not state.static and state.mass == 0
    assert state.position[0] == pytest.approx(0.5, abs=1e-12)  # x0 + v t, exactly
    assert world.body(rider).position[0] == pytest.approx(0.5, abs=1e-3)
    assert world.body(rider).linear_velocity[0] == pytest.approx(0.5, abs=1e-6)
    world.set_state(deck, linear_velocity=(0, 0, 0), angular_velocity=(0, 0, 0.5))
    world.step(60)
    assert world.body(deck).position[0] == pytest.approx(0.5, abs=1e-12)
    assert world.body(deck).angular_velocity[2] == 0.5


def test_kinematic_bodies_give_the_same_bits_here_and_on_a_server(world):
    _, remote = conveyor(world)
    local_world = tumble.World()
    _, local = conveyor(local_world)
    assert list(world.body(remote).position) == list(local_world.body(local).position)


def test_bad_kinematic_requests_are_refused_naming_the_field(world):
    world.load_scene({"name": "empty", "bodies": []})
    with pytest.raises(tumble.Error, match=r"force: a kinematic body moves only by the velocity"):
        world.spawn_box((1, 1, 1), kinematic=True, force=(1, 0, 0))
    with pytest.raises(tumble.ArgumentError, match=r"kinematic: a body is static or kinematic"):
        world.spawn_box((1, 1, 1), kinematic=True, static=True)
    deck = world.spawn_box((1, 1, 1), kinematic=True)
    with pytest.raises(tumble.Error, match=r"linear_damping: a kinematic body moves only"):
        world.set_state(deck, linear_damping=1.0)
    with pytest.raises(tumble.Error, match=r"linear_velocity"):
        world.set_state(deck, linear_velocity=(1e9, 0, 0))
    assert list(world.body(deck).linear_velocity) == [0, 0, 0]
