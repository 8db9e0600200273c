"""Frames arrive as numpy arrays that equal the world's state at their step."""

import time

import numpy as np

import tumble


def until_step(frames, step):
    """Frames up to the first of `step`: changes (spawns, control) publish frames of their own."""
    out = []
    for frame in frames:
        out.append(frame)
        if frame.step >= step or len(out) > 20:
            break
    assert out and out[-1].step == step, [f.step for f in out]
    return out


def test_frames_are_arrays_equal_to_the_bodies_at_their_step(world):
    bodies = world.bodies()
    with world.frames(velocities=True, contacts=True, stats=True) as frames:
        # The first frame is the world as it is now, describing every body.
        first = next(frames)
        assert first.step == 0
        assert {d.id for d in first.added} == {b.id for b in bodies}
        assert set(frames.bodies) == {b.id for b in bodies}
        world.step(1)
        frame = until_step(frames, 1)[-1]
    assert frame.added == [] and frame.removed == []
    n = len(bodies)
    assert frame.ids.dtype == np.uint64 and frame.ids.shape == (n,)
    assert frame.positions.shape == (n, 3) and frame.orientations.shape == (n, 4)
    assert frame.linear_velocities.shape == (n, 3) and frame.angular_velocities.shape == (n, 3)
    for body in world.bodies():
        row = frame.index(body.id)
        np.testing.assert_array_equal(frame.positions[row], body.position)
        np.testing.assert_array_equal(frame.orientation(body.id), body.orientation)
        np.testing.assert_array_equal(frame.linear_velocities[row], body.linear_velocity)
        np.testing.assert_array_equal(frame.angular_velocities[row], body.angular_velocity)
    assert frame.stats.step == 1 and frame.stats.total_seconds > 0
    assert frame.stats.contact_points == len(frame.contacts)


def test_contacts_of_a_resting_box(empty_world):
    world = empty_world
    ground = world.spawn_ground()
    box = world.spawn_box(size=(1, 1, 1), mass=1.0, pos=(0, 0, 0.5))
    world.step(30)
    with world.frames(contacts=True) as frames:
        contacts = next(frames).contacts
    assert len(contacts) >= 4  # a face on the ground: its four corners at least
    assert contacts.points.shape == (len(contacts), 3)
    assert set(contacts.body_a.tolist()) | set(contacts.body_b.tolist()) == {ground, box}
    np.testing.assert_allclose(np.linalg.norm(contacts.normals, axis=1), 1, atol=1e-12)
    # Together the points hold the box up: its weight over one step.
    dt = world.settings().dt
    assert abs(contacts.impulses.sum() - 9.81 * dt) < 0.01 * 9.81 * dt


def test_a_filtered_subscription_and_the_added_and_removed_bodies(empty_world):
    world = empty_world
    a = world.spawn_sphere(0.5, pos=(0, 0, 10))
    b = world.spawn_sphere(0.5, pos=(5, 0, 10))
    with world.frames(ids=[b]) as only_b, world.frames() as everything:
        assert next(only_b).ids.tolist() == [b]
        assert next(everything).ids.tolist() == [a, b]
        c = world.spawn_sphere(0.5, pos=(9, 0, 10))
        world.remove(a)
        world.step(1)
        later = until_step(everything, 1)
        assert [d.id for f in later for d in f.added] == [c]
        assert [i for f in later for i in f.removed] == [a]
        assert sorted(everything.bodies) == [b, c]
        assert all(f.ids.tolist() == [b] for f in until_step(only_b, 1))


def test_count_and_duration_end_a_subscription(world):
    world.settings(real_time_factor=0)
    world.play()
    try:
        received = list(world.frames(count=5))
    finally:
        world.pause()
    assert len(received) == 5
    steps = [frame.step for frame in received]
    assert steps == sorted(steps)
    # A paused world sends its one frame, then nothing: the duration ends the loop quietly.
    started = time.monotonic()
    quiet = list(world.frames(duration=0.5))
    assert len(quiet) == 1 and 0.4 < time.monotonic() - started < 10


def test_a_slow_reader_is_told_what_it_missed(world):
    world.load_builtin("pile:1000")  # 56 kB frames: the transport's buffers fill within a second
    world.settings(real_time_factor=0)
    with world.frames() as frames:
        previous = next(frames)
        world.play()
        # The play command sends a frame of its own at the step it found (PYTHON.md); when the
        # mailbox drops that one, it is counted in `dropped` without being a step.
        play_frame_unseen = True
        try:
            missed = 0
            for frame in frames:
                # Steps only after that (no changes while playing): each frame is one step after
                # the one before it plus those the mailbox dropped.
                gap = frame.step - previous.step
                assert (
                    gap == 1 + frame.dropped
                    or (play_frame_unseen and frame.dropped > 0 and gap == frame.dropped)
                    or gap == 0
                )
                play_frame_unseen = False
                missed += frame.dropped
                previous = frame
                if missed > 0 and frame.step > 50:
                    break
                time.sleep(0.05)
        finally:
            world.pause()
    assert missed > 0


def test_closing_a_subscription_ends_it_on_the_server(world):
    frames = world.frames()
    next(frames)
    assert world.info().subscribers == 1
    frames.close()
    deadline = time.monotonic() + 10
    while world.info().subscribers != 0 and time.monotonic() < deadline:
        time.sleep(0.01)
    assert world.info().subscribers == 0


def test_the_stream_ends_when_the_server_stops(server):
    world = tumble.connect(server.address)
    frames = world.frames()
    next(frames)
    code, _ = server.stop()
    assert code == 0
    assert list(frames) == []  # ended cleanly: no exception, no frame


def test_changes_only_frames_list_what_moved(empty_world):
    world = empty_world
    world.spawn_ground()
    resting = world.spawn_box(size=(1, 1, 1), mass=1.0, pos=(0, 0, 0.5))
    world.step(120)  # the box settles and sleeps
    falling = world.spawn_sphere(0.25, pos=(20, 0, 50))
    with world.frames(changes_only=True) as frames:
        first = next(frames)
        assert not first.changes_only and len(first.ids) == 3  # joining: every body
        world.step(1)
        frame = until_step(frames, world.info().step)[-1]
    assert frame.changes_only
    assert frame.ids.tolist() == [falling]  # the sleeping box and the ground are not sent
    np.testing.assert_array_equal(frame.position(falling), world.body(falling).position)
    assert resting not in frame.ids.tolist()
