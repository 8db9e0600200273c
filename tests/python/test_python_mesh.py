"""Triangle meshes from Python: numpy vertices and triangles spawned as static geometry, the same
on a server and in this process; what lands on them rests on their triangles' fronts; rays meet
them; refusals name the field."""

import numpy as np
import pytest

import tumble

DT = 1.0 / 60


def floor_and_ramp():
    """A 4 x 4 m floor of two triangles and, beside it, a closed unit cube: both facing out."""
    vertices = [(-2, -2, 0), (2, -2, 0), (2, 2, 0), (-2, 2, 0)]
    triangles = [(0, 1, 2), (0, 2, 3)]
    cube = np.array([(x, y, z) for z in (0, 1) for y in (0, 1) for x in (0, 1)], dtype=float)
    cube += (3.0, -0.5, 0.0)
    quads = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
    first = len(vertices)
    vertices += [tuple(v) for v in cube]
    for a, b, c, d in quads:
        triangles += [(first + a, first + b, first + c), (first + a, first + c, first + d)]
    return np.array(vertices, dtype=float), np.array(triangles, dtype=np.int64)


def drop(world):
    world.load_scene({"name": "empty", "bodies": []})
    world.settings(real_time_factor=0, dt=DT)
    vertices, triangles = floor_and_ramp()
    ground = world.spawn_mesh(vertices, triangles)
    on_floor = world.spawn_box((0.4, 0.4, 0.4), mass=1.0, position=(0.3, -0.2, 0.5))
    on_cube = world.spawn_sphere(0.2, mass=1.0, position=(3.5, 0.0, 1.5))
    world.step(120)
    return ground, on_floor, on_cube


@pytest.mark.parametrize("where", ["remote", "local"])
def test_bodies_rest_on_a_mesh_and_rays_meet_it(world, where):
    world = world if where == "remote" else tumble.World()
    ground, on_floor, on_cube = drop(world)
    assert world.body(ground).static
    assert world.body(on_floor).position[2] == pytest.approx(0.2, abs=1e-3)
    assert world.body(on_cube).position[2] == pytest.approx(1.2, abs=1e-3)
    hit = world.cast_ray((1.0, 1.0, 5.0), (0, 0, -1), 10.0)
    assert hit is not None and hit["body"] == ground
    assert hit["point"][2] == pytest.approx(0.0, abs=1e-12)
    assert hit["normal"][2] == pytest.approx(1.0, abs=1e-12)
    # From below, the floor's backs let the ray through.
    assert world.cast_ray((1.0, 1.0, -1.0), (0, 0, 1), 10.0) is None


def test_a_mesh_gives_the_same_bits_here_and_on_a_server(world):
    ground, remote, _ = drop(world)
    local_world = tumble.World()
    _, local, _ = drop(local_world)
    assert list(world.body(remote).position) == list(local_world.body(local).position)
    # The body's description carries the mesh back as it was sent.
    shape = world.body(ground).shape
    vertices, triangles = floor_and_ramp()
    assert isinstance(shape, tumble.Mesh)
    assert np.array_equal(shape.vertices, vertices)
    assert np.array_equal(shape.triangles, triangles)


def test_bad_meshes_are_refused_naming_the_field(world):
    world.load_scene({"name": "empty", "bodies": []})
    vertices, triangles = floor_and_ramp()
    with pytest.raises(tumble.ArgumentError, match=r"triangles: expected an \(M, 3\) array"):
        world.spawn_mesh(vertices, triangles.ravel())
    with pytest.raises(tumble.ArgumentError, match=r"triangles: indices must be 0 to 11"):
        world.spawn_mesh(vertices, triangles + 100)
    with pytest.raises(tumble.Error, match=r"shape.mesh.triangles\[0\]: degenerate"):
        world.spawn_mesh([(0, 0, 0), (1, 0, 0), (2, 0, 0)], [(0, 1, 2)])
    with pytest.raises(tumble.Error, match=r"shape.mesh.vertices\[1\]: must be finite"):
        world.spawn_mesh([(0, 0, 0), (np.inf, 0, 0), (0, 1, 0)], [(0, 1, 2)])
    with pytest.raises(tumble.Error, match=r"mesh must be static"):
        world.spawn(tumble.Mesh(vertices, triangles), mass=1.0)
    assert len(world.states()) == 0
