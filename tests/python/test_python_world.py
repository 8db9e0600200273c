"""The Python client changes and runs a real server's world, and reads back what it did."""

import math
import time

import numpy as np
import pytest

import tumble


def test_every_shape_spawns_and_reads_back(empty_world):
    world = empty_world
    points = [[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]]
    ground = world.spawn_ground(friction=0.8)
    box = world.spawn_box(size=(1, 2, 3), mass=2.0, pos=(0, 0, 5), color=(1, 0, 0))
    ball = world.spawn_sphere(0.5, pos=(3, 0, 1), vel=(1, 0, 0))
    capsule = world.spawn_capsule(0.25, 0.5, mass=1.5, pos=(-3, 0, 1), angular_velocity=(0, 0, 2))
    hull = world.spawn_hull(points, density=500, pos=(0, 4, 1))
    bodies = {body.id: body for body in world.bodies()}
    assert sorted(bodies) == sorted([ground, box, ball, capsule, hull])

    assert bodies[ground].static and bodies[ground].mass == 0
    assert isinstance(bodies[ground].shape, tumble.Plane)
    assert bodies[box].shape == tumble.Box((1.0, 2.0, 3.0))
    assert bodies[box].mass == 2.0
    assert bodies[box].color == 0xFF0000FF
    np.testing.assert_array_equal(bodies[box].position, [0, 0, 5])
    # The server's default density, 1000 kg/m^3, gives the sphere its mass.
    assert math.isclose(bodies[ball].mass, 1000 * 4 / 3 * math.pi * 0.5**3, rel_tol=1e-12)
    np.testing.assert_array_equal(bodies[ball].linear_velocity, [1, 0, 0])
    assert bodies[capsule].shape == tumble.Capsule(0.25, 0.5)
    np.testing.assert_array_equal(bodies[capsule].angular_velocity, [0, 0, 2])
    # A hull's body frame has its origin at the centre of mass: the points come back shifted by it.
    hull_points = bodies[hull].shape.points
    assert hull_points.shape == (4, 3)
    centroid = np.mean(points, axis=0)  # a tetrahedron's centre of mass is its vertices' mean
    # (in Qhull's order)
    shifted_back = sorted(map(tuple, np.round(hull_points + centroid, 12) + 0.0))
    assert shifted_back == sorted(map(tuple, np.array(points, dtype=float)))
    assert math.isclose(bodies[hull].mass, 500 / 6, rel_tol=1e-9)


def test_a_batch_spawns_whole_in_order(empty_world):
    specs = [tumble.BodySpec(tumble.Sphere(0.1), pos=(i, 0, 1), mass=1.0) for i in range(10)]
    ids = empty_world.spawn_many(specs)
    assert len(ids) == 10 and len(set(ids)) == 10
    by_id = {body.id: body for body in empty_world.bodies(ids)}
    for i, body_id in enumerate(ids):
        np.testing.assert_array_equal(by_id[body_id].position, [i, 0, 1])


def test_free_fall_follows_the_integrator_and_the_analytic_path(empty_world):
    world = empty_world
    ball = world.spawn_sphere(0.5, mass=1.0, pos=(0, 0, 100))
    settings = world.settings()
    steps = 60
    assert world.step(steps) == steps
    body = world.body(ball)
    t = steps * settings.dt
    g = -settings.gravity[2]
    # Semi-implicit Euler: z_n = z0 - g dt^2 n (n + 1) / 2, within rounding of the sum.
    expected = 100 - g * settings.dt**2 * steps * (steps + 1) / 2
    assert math.isclose(body.position[2], expected, rel_tol=0, abs_tol=1e-9)
    # ... and within one step's worth (g t dt) of the exact parabola.
    assert abs(body.position[2] - (100 - g * t * t / 2)) <= g * t * settings.dt
    assert math.isclose(body.linear_velocity[2], -g * t, rel_tol=1e-12)
    assert world.info().step == steps


def test_step_reset_and_settings(world):
    before = {b.id: b.position for b in world.bodies()}
    assert world.step(30) == 30
    moved = {b.id: b.position for b in world.bodies()}
    assert any(not np.array_equal(before[i], moved[i]) for i in before)
    world.reset()
    info = world.info()
    assert info.step == 0 and not info.running
    after = {b.id: b.position for b in world.bodies()}
    assert len(after) == len(before)
    # Reset gives new ids (an id never names another body) to the same scene.
    for a, b in zip(sorted(before.items()), sorted(after.items())):
        np.testing.assert_array_equal(a[1], b[1])

    now = world.settings(dt=1 / 120, substeps=8, solver="soft", gravity=(0, 0, -3.7),
                         real_time_factor=0)
    assert now.dt == 1 / 120 and now.substeps == 8 and now.solver == "soft"
    assert now.gravity == (0, 0, -3.7)
    assert now.real_time_factor == 0
    assert now.iterations == 10 and now.joint_position_passes == 3
    assert world.settings() == now
    swept = world.settings(solver="pgs", iterations=20, joint_position_passes=2)
    assert swept.iterations == 20 and swept.joint_position_passes == 2
    assert swept.solver == "pgs" and swept.substeps == 8
    assert world.step(2) == 2
    assert world.settings() == swept


def test_play_runs_until_paused(world):
    world.settings(real_time_factor=0)
    world.play()
    assert world.info().running
    deadline = time.monotonic() + 30
    while world.info().step < 20 and time.monotonic() < deadline:
        time.sleep(0.005)
    stopped_at = world.pause()
    stopped = world.info()
    assert not stopped.running and stopped.step == stopped_at >= 20


def test_remove_move_and_push(empty_world):
    world = empty_world
    world.settings(gravity=(0, 0, 0))
    a = world.spawn_box(size=(1, 1, 1), mass=2.0, pos=(0, 0, 0))
    b = world.spawn_box(size=(1, 1, 1), mass=2.0, pos=(10, 0, 0))
    world.remove(b)
    assert [body.id for body in world.bodies()] == [a]

    world.set_state(a, pos=(5, 5, 5), orientation=(0, 0, 0, 1))
    moved = world.body(a)
    np.testing.assert_array_equal(moved.position, [5, 5, 5])
    np.testing.assert_array_equal(moved.orientation, [0, 0, 0, 1])

    # 2 N s on 2 kg: 1 m/s. Off the centre by 0.5 m across it: a spin J r / I, I = m (1 + 1) / 12.
    world.apply_impulse(a, (2, 0, 0), point=(5, 5.5, 5))
    world.step(1)
    pushed = world.body(a)
    np.testing.assert_allclose(pushed.linear_velocity, [1, 0, 0], atol=1e-12)
    np.testing.assert_allclose(pushed.angular_velocity, [0, 0, -2 * 0.5 / (2 * 2 / 12)], atol=1e-9)


def test_one_name_per_concept_with_the_old_names_accepted(empty_world):
    world = empty_world
    world.settings(gravity=(0, 0, 0))
    a = world.spawn_box(size=(1, 1, 1), position=(1, 2, 3), linear_velocity=(0, 0, 1))
    b = world.spawn_box(size=(1, 1, 1), pos=(4, 5, 6), vel=(0, 0, 1))
    np.testing.assert_array_equal(world.body(a).position, [1, 2, 3])
    np.testing.assert_array_equal(world.body(b).position, [4, 5, 6])
    world.set_state(a, position=(7, 7, 7), linear_velocity=(1, 0, 0))
    np.testing.assert_array_equal(world.body(a).linear_velocity, [1, 0, 0])
    with pytest.raises(tumble.ArgumentError, match="position and pos"):
        world.spawn_box(size=(1, 1, 1), position=(0, 0, 0), pos=(1, 1, 1))
    assert [body.id for body in world.bodies()] == [a, b]  # nothing spawned by the refusal


def test_sleeping_is_switched_at_run_time(empty_world):
    world = empty_world
    world.spawn_ground()
    box = world.spawn_box(size=(1, 1, 1), mass=2.0, position=(0, 0, 0.5))
    world.step(90)
    assert world.body(box).asleep
    assert world.settings().sleeping
    assert not world.settings(sleeping=False).sleeping
    assert not world.body(box).asleep
    with pytest.raises(tumble.ArgumentError, match="sleeping"):
        world.settings(sleeping="no")


def test_snapshot_restore_continues_bit_for_bit(world):
    world.step(10)
    saved = world.snapshot()
    assert saved.step == 10 and len(saved.state) > 0
    world.step(40)
    first = {b.id: (b.position, b.orientation) for b in world.bodies()}
    assert world.restore(saved) == {}  # made by this server: every id kept
    assert world.info().step == 10
    world.step(40)
    second = {b.id: (b.position, b.orientation) for b in world.bodies()}
    assert first.keys() == second.keys()
    for body_id, (position, orientation) in first.items():
        np.testing.assert_array_equal(position, second[body_id][0])
        np.testing.assert_array_equal(orientation, second[body_id][1])


def test_restoring_elsewhere_maps_old_ids_to_new(world, server):
    from conftest import Server

    saved = world.snapshot()
    other = Server()
    try:
        with tumble.connect(other.address) as elsewhere:
            new_ids = elsewhere.restore(saved.state)
            old_ids = {b.id for b in world.bodies()}
            assert set(new_ids) == old_ids
            assert set(new_ids.values()) == {b.id for b in elsewhere.bodies()}
    finally:
        assert other.stop()[0] == 0


def test_scenes_from_a_dict_text_path_and_builtin(world, tmp_path):
    scene = {"name": "two", "bodies": [{"shape": "plane"},
                                       {"shape": "box", "size": [1, 1, 1], "position": [0, 0, 2]}]}
    loaded = world.load_scene(scene)
    assert loaded.name == "two" and len(loaded.ids) == 2
    path = tmp_path / "scene.json"
    path.write_text('{"name": "from a file", "bodies": [{"shape": "sphere"}]}')
    assert world.load_scene(path).name == "from a file"
    assert world.load_scene('{"name": "text"}').ids == []
    pyramid = world.load_builtin("pyramid:3")
    assert len(pyramid.ids) == len(world.bodies()) == 1 + 3 * 4 // 2
