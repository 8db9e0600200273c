"""Hulls of large clouds from Python: tumble.hull_points keeps the points a hull may be given (at
most 1024) as the CLI's `spawn hull --file` does; a box's cloud keeps its corners, a ball's its
shape, the same on a server and in this process; a cloud past the limit is refused naming it."""

import numpy as np
import pytest

import tumble


def ball(radius, rings=100):
    """A ball's surface as latitude rings of 2 * rings points, and its poles."""
    polar = np.pi * np.arange(1, rings) / rings
    azimuth = np.pi * np.arange(2 * rings) / rings
    p, a = np.meshgrid(polar, azimuth, indexing="ij")
    ring_points = np.column_stack([np.sin(p).ravel() * np.cos(a).ravel(),
                                   np.sin(p).ravel() * np.sin(a).ravel(), np.cos(p).ravel()])
    return radius * np.vstack([[0, 0, 1], ring_points, [0, 0, -1]])


def test_a_small_cloud_is_kept_whole_and_a_box_keeps_its_corners():
    few = np.random.default_rng(1).normal(size=(300, 3))
    np.testing.assert_array_equal(tumble.hull_points(few), few)
    # A 2 x 1 x 0.5 box's faces as 41 x 41 grids: 10,086 points, of which the corners are kept.
    half = np.array([1.0, 0.5, 0.25])
    grid = np.linspace(-1, 1, 41)
    u, v = (g.ravel() for g in np.meshgrid(grid, grid))
    faces = []
    for axis in range(3):
        for side in (-1.0, 1.0):
            face = np.zeros((u.size, 3))
            face[:, axis] = side
            face[:, (axis + 1) % 3] = u
            face[:, (axis + 2) % 3] = v
            faces.append(face * half)
    cloud = np.vstack(faces)
    corners = tumble.hull_points(cloud)
    assert len(corners) == 8
    np.testing.assert_array_equal(np.abs(corners), np.tile(half, (8, 1)))
    with pytest.raises(tumble.ArgumentError, match="max_points"):
        tumble.hull_points(cloud, max_points=3)


@pytest.mark.parametrize("where", ["remote", "local"])
def test_a_ball_of_19802_points_spawns_as_the_hull_of_1024(world, where):
    world = world if where == "remote" else tumble.World()
    cloud = ball(0.5)
    assert len(cloud) == 19802
    with pytest.raises(tumble.Error, match="points"):
        world.spawn_hull(cloud, mass=1.0, position=(50.0, 0.0, 5.0), static=True)
    kept = tumble.hull_points(cloud)
    assert len(kept) == 1024
    body = world.spawn_hull(kept, mass=1.0, position=(50.0, 0.0, 5.0), static=True)
    hit = world.cast_ray((50.49, 0.0, 8.0), (0.0, 0.0, -1.0), 5.0)
    assert hit is not None and hit["body"] == body
    assert world.cast_ray((50.51, 0.0, 8.0), (0.0, 0.0, -1.0), 5.0) is None
