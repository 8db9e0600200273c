"""Ray casts from Python (world.cast_rays, world.cast_ray): numpy arrays in and out, a lidar
sweep of 100,000 rays in one call, the same answers on a server and in this process, every hit
along a ray, and refusals naming the field."""

import numpy as np
import pytest

import tumble


def boxes_on_the_ground(world):
    """The ground, and a 1 m cube on it at x = 0, y = 0."""
    world.load_scene({"name": "empty", "bodies": []})
    world.settings(real_time_factor=0)
    ground = world.spawn_ground()
    cube = world.spawn_box((1, 1, 1), mass=1.0, position=(0, 0, 0.5))
    return ground, cube


@pytest.mark.parametrize("where", ["remote", "local"])
def test_a_lidar_of_100000_rays_in_one_call(world, where):
    world = world if where == "remote" else tumble.World()
    ground, cube = boxes_on_the_ground(world)
    # A 400 x 250 grid of rays straight down from z = 10 over [-2, 2] x [-2, 2].
    xs, ys = np.meshgrid(np.linspace(-2, 2, 400), np.linspace(-2, 2, 250))
    origins = np.column_stack([xs.ravel(), ys.ravel(), np.full(xs.size, 10.0)])
    directions = np.tile([0.0, 0.0, -1.0], (xs.size, 1))
    found = world.cast_rays(origins, directions, 20.0)
    assert found.hit.shape == (100000,) and found.hit.all()
    on_cube = (np.abs(origins[:, 0]) < 0.5) & (np.abs(origins[:, 1]) < 0.5)
    off_cube = (np.abs(origins[:, 0]) > 0.5) | (np.abs(origins[:, 1]) > 0.5)
    assert np.all(found.body[on_cube] == cube) and np.all(found.body[off_cube] == ground)
    np.testing.assert_allclose(found.distance[on_cube], 9.0, atol=1e-9)
    np.testing.assert_allclose(found.distance[off_cube], 10.0, atol=1e-12)
    np.testing.assert_allclose(found.fraction[off_cube], 0.5, atol=1e-12)
    np.testing.assert_allclose(found.normal[off_cube], [[0, 0, 1]] * off_cube.sum(), atol=1e-12)
    np.testing.assert_allclose(found.point[:, :2], origins[:, :2], atol=1e-12)


def test_rays_give_the_same_bits_here_and_on_a_server(world):
    rng = np.random.default_rng(3)
    origins = rng.uniform(-3, 3, (500, 3)) + [0, 0, 3]
    directions = rng.normal(size=(500, 3))
    answers = []
    for w in (world, tumble.World()):
        boxes_on_the_ground(w)
        answers.append(w.cast_rays(origins, directions, 10.0))
    remote, local = answers
    assert np.array_equal(remote.hit, local.hit)
    assert np.array_equal(remote.distance[remote.hit], local.distance[local.hit])


def test_every_hit_along_a_ray_and_a_mask(world):
    world.load_scene({"name": "empty", "bodies": []})
    row = [world.spawn_box((0.5, 0.5, 0.5), mass=1.0, position=(2.0 * k, 0, 5), gravity_scale=0.0,
                           collision_layers=1 << k) for k in range(1, 5)]
    found = world.cast_rays([[0, 0, 5]], [[1, 0, 0]], 100.0, hits_per_ray=3)
    assert list(found.counts) == [3] and found.left_out
    assert list(found.body) == row[:3]
    np.testing.assert_allclose(found.distance, [1.75, 3.75, 5.75], atol=1e-12)
    # Layers 2 and 8 only (the first and third boxes): the first hit is the second box.
    assert world.cast_ray((0, 0, 5), (1, 0, 0), mask=0b10100)["body"] == row[1]
    assert world.cast_ray((0, 0, 5), (-1, 0, 0)) is None


def test_bad_rays_are_refused_naming_the_field(world):
    boxes_on_the_ground(world)
    with pytest.raises(tumble.Error, match=r"rays\[1\]\.direction: must not be zero"):
        world.cast_rays([[0, 0, 5], [0, 0, 5]], [[0, 0, -1], [0, 0, 0]])
    with pytest.raises(tumble.Error, match=r"max_distance: must be in"):
        world.cast_ray((0, 0, 5), (0, 0, -1), max_distance=0.0)
    with pytest.raises(tumble.Error, match=r"hits_per_ray: must be in \[0, 64\]"):
        world.cast_rays([[0, 0, 5]], [[0, 0, -1]], hits_per_ray=65)
    with pytest.raises(tumble.Error, match=r"above the 262144") as refused:
        world.cast_rays(np.zeros((262145, 3)), np.ones((262145, 3)))
    assert refused.value.code.name == "RESOURCE_EXHAUSTED"
    with pytest.raises(tumble.ArgumentError, match=r"directions: expected shape"):
        world.cast_rays([[0, 0, 5]], [[0, 0, -1], [0, 0, 1]])


@pytest.mark.parametrize("where", ["remote", "local"])
def test_overlap_finds_the_bodies_a_shape_meets(world, where):
    world = world if where == "remote" else tumble.World()
    ground, cube = boxes_on_the_ground(world)
    assert world.overlap(tumble.Sphere(0.6), (0, 0, 1.5)) == [cube]
    assert world.overlap(tumble.Sphere(0.6), (0, 0, 0.3)) == [ground, cube]
    assert world.overlap(tumble.Box((1, 1, 1)), (5, 5, 5)) == []
    # Turned 45 degrees about z, a flat box's corner reaches the cube's side at x = 0.5.
    turned = (np.cos(np.pi / 8), 0, 0, np.sin(np.pi / 8))
    assert world.overlap(tumble.Box((1, 1, 0.2)), (1.2, 0, 0.5), turned) == [cube]
    assert world.overlap(tumble.Box((1, 1, 0.2)), (1.2, 0, 0.5)) == []
    assert world.overlap(tumble.Sphere(0.6), (0, 0, 0.3), mask=0) == []
    with pytest.raises(tumble.Error, match=r"overlaps\[0\]\.shape: a half-space"):
        world.overlap(tumble.Plane(), (0, 0, 0))


def test_closest_point_of_a_body(world):
    ground, cube = boxes_on_the_ground(world)
    near = world.closest_point(cube, (3, 0.2, 0.5))
    assert near["distance"] == pytest.approx(2.5, abs=1e-9)
    np.testing.assert_allclose(near["point"], [0.5, 0.2, 0.5], atol=1e-9)
    np.testing.assert_allclose(near["normal"], [1, 0, 0], atol=1e-9)
    inside = world.closest_point(cube, (0, 0, 0.9))
    assert inside["distance"] == pytest.approx(-0.1, abs=1e-9)
    assert world.closest_point(cube, (30, 0, 0.5), max_distance=10) is None
    with pytest.raises(tumble.Error, match=r"closest_points\[0\]\.id: no body"):
        world.closest_point(987654, (0, 0, 0))
    with pytest.raises(tumble.Error, match=r"closest_points\[0\]\.max_distance: must be in"):
        world.closest_point(cube, (0, 0, 0), max_distance=-1)


@pytest.mark.parametrize("where", ["remote", "local"])
def test_cast_shape_finds_the_first_body_a_sweep_meets(world, where):
    world = world if where == "remote" else tumble.World()
    ground, cube = boxes_on_the_ground(world)
    # A ball of 0.25 swept along x at the cube's height meets its face x = -0.5 when its centre
    # is at -0.75: 4.25 m of the 10.
    hit = world.cast_shape(tumble.Sphere(0.25), (-5, 0, 0.5), (10, 0, 0))
    assert hit["body"] == cube and hit["converged"]
    assert hit["fraction"] * 10 == pytest.approx(4.25, abs=1e-6)
    np.testing.assert_allclose(hit["point"], [-0.5, 0, 0.5], atol=1e-5)
    np.testing.assert_allclose(hit["normal"], [-1, 0, 0], atol=1e-9)
    # A box dropped from 5 m lands on the ground (its bottom at z = 0: centre at 0.1).
    hit = world.cast_shape(tumble.Box((1, 1, 0.2)), (3, 0, 5), (0, 0, -10))
    assert hit["body"] == ground
    assert hit["fraction"] == pytest.approx(0.49, abs=1e-12)
    assert world.cast_shape(tumble.Sphere(0.25), (-5, 3, 0.5), (10, 0, 0)) is None
    assert world.cast_shape(tumble.Sphere(0.25), (-5, 0, 0.5), (10, 0, 0), mask=0) is None
    with pytest.raises(tumble.Error, match=r"shape_casts\[0\]\.shape: a half-space"):
        world.cast_shape(tumble.Plane(), (0, 0, 0), (1, 0, 0))
    with pytest.raises(tumble.Error, match=r"shape_casts\[0\]\.translation: must be finite"):
        world.cast_shape(tumble.Sphere(0.25), (0, 0, 0), (float("nan"), 0, 0))
