"""Heightfields from Python: a numpy grid of heights spawned as static terrain, the same on a
server and in this process; what lands on it rests on its surface; rays meet it; refusals name
the field."""

import numpy as np
import pytest

import tumble

DT = 1.0 / 60


def valley(world):
    """A V valley along x (slopes of 1 in 2), 0.5 m cells, and a ball of 0.3 m dropped in it."""
    world.load_scene({"name": "empty", "bodies": []})
    world.settings(real_time_factor=0, dt=DT)
    y = (np.arange(17) - 8) * 0.5
    heights = np.tile(0.5 * np.abs(y)[:, None], (1, 9))  # rows along y, columns along x
    ground = world.spawn_heightfield(heights, (0.5, 0.5))
    ball = world.spawn_sphere(0.3, mass=1.0, position=(0.1, 0.0, 1.0))
    world.step(180)
    return ground, ball


@pytest.mark.parametrize("where", ["remote", "local"])
def test_a_ball_rests_in_a_valley_of_a_heightfield(world, where):
    world = world if where == "remote" else tumble.World()
    ground, ball = valley(world)
    assert world.body(ground).static
    # Touching both slopes: its centre r / cos(a) above the valley line, tan(a) = 1/2.
    assert world.body(ball).position[2] == pytest.approx(0.3 / np.cos(np.arctan(0.5)), abs=1e-3)
    assert world.body(ball).position[1] == pytest.approx(0.0, abs=1e-4)  # the valley line
    hit = world.cast_ray((1.5, 2.0, 5.0), (0, 0, -1), 10.0)
    assert hit is not None and hit["body"] == ground
    assert hit["point"][2] == pytest.approx(1.0, abs=1e-12)  # 0.5 * |y|, y = 2


def test_terrain_gives_the_same_bits_here_and_on_a_server(world):
    _, remote = valley(world)
    local_world = tumble.World()
    _, local = valley(local_world)
    assert list(world.body(remote).position) == list(local_world.body(local).position)


def test_bad_heightfields_are_refused_naming_the_field(world):
    world.load_scene({"name": "empty", "bodies": []})
    with pytest.raises(tumble.ArgumentError, match=r"heights: expected a 2-D array"):
        world.spawn_heightfield(np.zeros(5), (1, 1))
    with pytest.raises(tumble.Error, match=r"shape.heightfield.spacing_y: must be in \(0, 1e4\]"):
        world.spawn_heightfield(np.zeros((3, 3)), (1, 0))
    with pytest.raises(tumble.Error, match=r"heightfield must be static"):
        world.spawn(tumble.HeightField(np.zeros((3, 3)), (1, 1)), mass=1.0)
    assert len(world.states()) == 0
