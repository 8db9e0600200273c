"""Compound shapes from Python: a table of five boxes spawned as one body stands on its legs, the
same on a server and in this process; its description gives the parts back; rays see the parts and
not the gaps; a compound is a query's shape too; refusals name the part."""

import numpy as np
import pytest

import tumble

DT = 1.0 / 60
TOP = (1.2, 0.8, 0.1)
LEG = (0.1, 0.1, 0.7)


def table():
    """A table whose frame's origin is on the floor under its middle."""
    legs = [tumble.Part(tumble.Box(LEG), (x, y, 0.35)) for x in (-0.55, 0.55) for y in (-0.35, 0.35)]
    return tumble.Compound((tumble.Part(tumble.Box(TOP), (0.0, 0.0, 0.75)), *legs))


def centre_of_mass_height():
    top, leg = np.prod(TOP), np.prod(LEG)
    return (top * 0.75 + 4 * leg * 0.35) / (top + 4 * leg)


def drop(world):
    world.load_scene({"name": "empty", "bodies": [{"shape": "plane"}]})
    world.settings(real_time_factor=0, dt=DT)
    body = world.spawn(table(), position=(0.0, 0.0, 0.05), density=600.0)
    world.step(180)
    return body


@pytest.mark.parametrize("where", ["remote", "local"])
def test_a_table_stands_on_its_legs(world, where):
    world = world if where == "remote" else tumble.World()
    body = drop(world)
    state = world.body(body)
    assert state.position[2] == pytest.approx(centre_of_mass_height(), abs=0.01)
    assert np.linalg.norm(state.linear_velocity) < 1e-3
    volume = np.prod(TOP) + 4 * np.prod(LEG)
    assert world.body(body).mass == pytest.approx(600.0 * volume, rel=1e-12)
    # Down through the top; along the floor between the legs, nothing.
    hit = world.cast_ray((0.1, 0.1, 3.0), (0, 0, -1), 10.0)
    assert hit is not None and hit["body"] == body
    assert hit["point"][2] == pytest.approx(0.8, abs=2e-3)
    assert world.cast_ray((-3.0, 0.0, 0.3), (1, 0, 0), 6.0) is None
    # Two balls straddling a leg touch nothing; moved onto it, they touch the table.
    fingers = tumble.Compound((tumble.Part(tumble.Sphere(0.1), (0, -0.2, 0)),
                               tumble.Part(tumble.Sphere(0.1), (0, 0.2, 0))))
    leg = np.array(state.position[:2]) + (0.55, 0.35)
    assert world.overlap(fingers, (leg[0], leg[1], 0.3)) == []
    assert world.overlap(fingers, (leg[0], leg[1] - 0.15, 0.3)) == [body]


def test_a_compound_gives_the_same_bits_here_and_on_a_server(world):
    remote = drop(world)
    local_world = tumble.World()
    local = drop(local_world)
    assert list(world.body(remote).position) == list(local_world.body(local).position)
    # The description gives the parts back, moved so that the body's origin is its centre of mass.
    shape = world.body(remote).shape
    assert isinstance(shape, tumble.Compound) and len(shape.parts) == 5
    assert shape.parts[0].shape == tumble.Box(TOP)
    assert shape.parts[0].position[2] == pytest.approx(0.75 - centre_of_mass_height(), abs=1e-12)


def test_bad_compounds_are_refused_naming_the_part(world):
    world.load_scene({"name": "empty", "bodies": []})
    with pytest.raises(tumble.ArgumentError, match=r"parts: a compound needs at least one part"):
        world.spawn(tumble.Compound(()))
    with pytest.raises(tumble.ArgumentError, match=r"parts\[1\].shape: a compound's parts must be"):
        world.spawn(tumble.Compound((tumble.Part(tumble.Sphere(0.1)), tumble.Part(tumble.Plane()))))
    with pytest.raises(tumble.Error,
                       match=r"shape.compound.parts\[1\].shape.sphere.radius: must be finite"):
        world.spawn(tumble.Compound((tumble.Part(tumble.Sphere(0.1)),
                                     tumble.Part(tumble.Sphere(-1.0)))))
    with pytest.raises(tumble.Error, match=r"shape.compound.parts\[0\].orientation: must be a unit"):
        world.spawn(tumble.Compound((tumble.Part(tumble.Sphere(0.1), (0, 0, 0), (0, 0, 0, 0)),)))
    assert len(world.states()) == 0
