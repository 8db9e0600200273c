"""The engine in this process (tumble.World): the remote client's calls, answered alike, plus
batches of states as numpy arrays; snapshots that move between it and a server."""

import numpy as np
import pytest

import tumble


def drop_a_box(world):
    """The same script for either world: a box dropped on the ground, its height after 2 s."""
    world.load_scene({"name": "empty", "bodies": []})
    world.settings(real_time_factor=0)
    world.spawn_ground()
    box = world.spawn_box(size=(1, 1, 1), mass=2.0, position=(0, 0, 3))
    world.step(120)
    return box, world.states([box]).positions[0]


def test_the_same_script_runs_on_a_local_and_a_remote_world_with_the_same_result(world):
    local_box, local_position = drop_a_box(tumble.World())
    remote_box, remote_position = drop_a_box(world)
    assert local_position[2] == pytest.approx(0.5, abs=1e-3)
    # The same engine, settings and order of calls: the same bits.
    assert np.array_equal(local_position, remote_position)


def test_states_come_out_and_go_in_as_arrays_without_a_loop_per_body():
    world = tumble.World(builtin="pile:200")
    states = world.states()
    assert len(states) == 201 and states.positions.shape == (201, 3)
    assert states.orientations.shape == (201, 4) and states.ids.dtype == np.uint64
    dynamic = states.ids[1:]
    lifted = states.positions[1:] + [0, 0, 10]
    spin = np.tile([0.0, 0.0, 2.0], (len(dynamic), 1))
    world.set_states(dynamic, positions=lifted, angular_velocities=spin)
    after = world.states(dynamic[::-1])
    assert np.array_equal(after.ids, dynamic[::-1])
    assert np.array_equal(after.positions, lifted[::-1])
    assert np.array_equal(after.angular_velocities, spin)


def test_a_refused_row_changes_no_body_and_is_named():
    world = tumble.World()
    a = world.spawn_sphere(0.5, position=(0, 0, 1))
    b = world.spawn_sphere(0.5, position=(3, 0, 1))
    before = world.states()
    with pytest.raises(tumble.Error) as refused:
        world.set_states([a, b], positions=[[0, 0, 2], [0, 0, 1e300]])
    assert "[1].position" in refused.value.message
    assert refused.value.code.name == "INVALID_ARGUMENT"
    assert np.array_equal(world.states().positions, before.positions)
    with pytest.raises(tumble.Error) as unknown:
        world.states([a, 999])
    assert unknown.value.code.name == "NOT_FOUND" and "ids[1]" in unknown.value.message
    with pytest.raises(tumble.Error) as shape:
        world.set_states([a], positions=[[0, 0]])
    assert "positions: expected shape (1, 3)" in shape.value.message


def test_impulses_in_a_batch_and_contacts_with_their_impulses():
    world = tumble.World()
    world.spawn_ground()
    boxes = [world.spawn_box(size=(1, 1, 1), mass=10.0, position=(3 * i, 0, 0.5)) for i in range(3)]
    world.step(30)
    contacts = world.contacts()
    assert len(contacts) >= 12
    # At rest, the points under the boxes carry their weight: m g dt each step.
    weight_per_step = 3 * 10.0 * 9.81 / 60
    assert contacts.impulses.sum() == pytest.approx(weight_per_step, rel=1e-3)
    world.apply_impulses(boxes, [[20, 0, 0], [0, 20, 0], [0, 0, 0]])
    velocities = world.states(boxes).linear_velocities
    assert np.allclose(velocities[:, :2], [[2, 0], [0, 2], [0, 0]])


def test_a_snapshot_moves_between_the_local_world_and_a_server(world):
    local = tumble.World(builtin="pile:50")
    local.step(40)
    snapshot = local.snapshot()
    new_ids = world.restore(snapshot)
    assert len(new_ids) == 51  # another world's ids: each body gets a new one here
    local.step(20)
    world.step(20)
    remote = world.states([new_ids[int(i)] for i in local.states().ids])
    assert np.array_equal(remote.positions, local.states().positions)
    # and back: the server's snapshot in a new local world
    again = tumble.World()
    again.restore(world.snapshot())
    assert np.array_equal(again.states().positions, world.states().positions)


def test_limits_and_refusals_are_the_servers():
    world = tumble.World(limits={"max_size": 10}, max_bodies=3)
    with pytest.raises(tumble.Error) as large:
        world.spawn_sphere(20.0)
    assert "limits.max_size" in large.value.message
    world.spawn_many([tumble.BodySpec(tumble.Sphere(0.5), position=(2 * i, 0, 0))
                      for i in range(3)])
    with pytest.raises(tumble.Error) as full:
        world.spawn_sphere(0.5, position=(0, 5, 0))
    assert full.value.code.name == "RESOURCE_EXHAUSTED"
    with pytest.raises(tumble.Error) as unknown:
        tumble.World(limits={"max_sizes": 1})
    assert "limits.max_sizes: no such limit" in unknown.value.message
    with pytest.raises(tumble.Error) as solver:
        world.settings(dt=-1)
    assert solver.value.message.startswith("settings.dt")
    with pytest.raises(tumble.Error) as passes:
        world.settings(iterations=5, joint_position_passes=1001)
    assert passes.value.message.startswith("settings.joint_position_passes: must be in [0, 1000]")
    assert world.settings().iterations == 10
    now = world.settings(iterations=5, joint_position_passes=2)
    assert (now.iterations, now.joint_position_passes) == (5, 2)


def test_frames_step_the_local_world_and_describe_its_bodies_first():
    world = tumble.World(builtin="pile:20")
    frames = list(world.frames(count=3, velocities=True, contacts=True, stats=True))
    assert [frame.step for frame in frames] == [1, 2, 3]
    assert len(frames[0].added) == 21 and frames[1].added == []
    assert frames[2].linear_velocities.shape == (21, 3) and frames[2].stats.step == 3


def test_every_solver_and_a_reset_and_two_worlds_alike():
    for solver in ("exact", "pgs", "soft", "auto"):
        one, two = tumble.World(builtin="pyramid:4"), tumble.World(builtin="pyramid:4")
        for world in (one, two):
            world.settings(solver=solver)
            world.step(60)
        assert np.array_equal(one.states().positions, two.states().positions), solver
    one.reset()
    assert one.info().step == 0 and one.info().body_count == two.info().body_count


def test_threads_sharing_a_world_take_turns():
    import threading

    world = tumble.World(builtin="pile:50")
    reads = []

    def stepper():
        for _ in range(40):
            world.step(1)

    def reader():
        for _ in range(200):
            reads.append(world.states().positions.shape)

    threads = [threading.Thread(target=stepper), threading.Thread(target=stepper),
               threading.Thread(target=reader)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    assert world.info().step == 80
    assert reads == [(51, 3)] * 200


def test_a_thread_count_beyond_reason_is_refused():
    for threads in (-1, 10**6):
        with pytest.raises(tumble.Error) as refused:
            tumble.World(threads=threads)
        assert refused.value.message.startswith("threads: must be in [0, 1024]")
    assert tumble.World(threads=2).step(1) == 1
