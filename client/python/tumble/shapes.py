"""Shapes, in the body's frame (m), and their wire form (tumble.v1.Shape)."""

from dataclasses import dataclass, field

import numpy as np

from tumble import convert
from tumble.errors import ArgumentError
from tumble.v1 import world_pb2 as pb


@dataclass(frozen=True)
class Box:
    """A box of full extents `size` (x, y, z), centred on the body's origin."""

    size: tuple = (1.0, 1.0, 1.0)

    def to_proto(self):
        shape = pb.Shape()
        convert.set_vec3(shape.box.size, self.size, "size")
        return shape


@dataclass(frozen=True)
class Sphere:
    radius: float = 0.5

    def to_proto(self):
        shape = pb.Shape()
        shape.sphere.radius = convert.number(self.radius, "radius")
        return shape


@dataclass(frozen=True)
class Capsule:
    """A segment of length 2 half_height along the body's z axis, swept by a sphere."""

    radius: float = 0.25
    half_height: float = 0.5

    def to_proto(self):
        shape = pb.Shape()
        shape.capsule.radius = convert.number(self.radius, "radius")
        shape.capsule.half_height = convert.number(self.half_height, "half_height")
        return shape


@dataclass(frozen=True)
class Hull:
    """The convex hull of `points`, an (N, 3) array in the body's frame."""

    points: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))

    def to_proto(self):
        points = convert.points(self.points, "points")
        shape = pb.Shape()
        shape.hull.points.extend(points.ravel().tolist())
        return shape


@dataclass(frozen=True)
class Plane:
    """The half-space z <= 0 of the body's frame: a ground (static bodies only)."""

    def to_proto(self):
        shape = pb.Shape()
        shape.plane.SetInParent()
        return shape


SHAPES = (Box, Sphere, Capsule, Hull, Plane)


def from_proto(shape):
    """The dataclass of a tumble.v1.Shape."""
    kind = shape.WhichOneof("kind")
    if kind == "box":
        return Box(tuple(convert.vec3(shape.box.size)))
    if kind == "sphere":
        return Sphere(shape.sphere.radius)
    if kind == "capsule":
        return Capsule(shape.capsule.radius, shape.capsule.half_height)
    if kind == "hull":
        return Hull(np.array(shape.hull.points, dtype=float).reshape(-1, 3))
    if kind == "plane":
        return Plane()
    raise ArgumentError(f"shape: unknown kind {kind!r}")
