"""Tumble's Python client: spawn, step and stream a Tumble server's world, or the engine in this
process (tumble.World()) with the same calls.

    import tumble
    world = tumble.connect("127.0.0.1:50051")      # or: world = tumble.World()
    box = world.spawn_box(size=(1, 1, 1), mass=2.0, position=(0, 0, 5))
    world.step(120)
    for frame in world.frames(rate=60, count=10): print(frame.step, frame.position(box))

Built from proto/tumble/v1/world.proto by `make python` into build/python (docs/PYTHON.md).
"""

from tumble.bodies import Body, BodySpec, Description
from tumble.errors import ArgumentError, Error
from tumble.frames import Contacts, Frame, FrameStream, JointStates
from tumble.shapes import (Box, Capsule, Compound, HeightField, Hull, Mesh, Part, Plane, Sphere,
                           hull_points)
from tumble.local import World
from tumble.world import Info, LoadedScene, RemoteWorld, Settings, Snapshot, States, connect

__all__ = [
    "ArgumentError", "Body", "BodySpec", "Box", "Capsule", "Compound", "Contacts", "Description", "Error",
    "Frame", "FrameStream", "HeightField", "Hull", "Info", "JointStates", "LoadedScene", "Mesh", "Part", "Plane",
    "Settings",
    "Snapshot",
    "RemoteWorld", "Sphere", "States", "World", "connect", "hull_points",
]
