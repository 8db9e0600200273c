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


def hull_points(points, max_points=1024):
    """The points of an (N, 3) cloud to give a hull (which takes at most 1024): all of them when
    they are at most `max_points`; else, for each of `max_points` directions spread evenly over
    the sphere (a Fibonacci lattice, half a step off the axes' planes), the point farthest along
    it, each once, in the cloud's order. The CLI's `spawn hull --file` and scene files' hulls from
    mesh files keep the same points: a box keeps its 8 corners, a finely tessellated ball of radius
    r keeps max_points vertices whose hull lies within about 0.0034 r of it (docs/SCENES.md)."""
    cloud = convert.points(points, "points")
    if not (isinstance(max_points, int) and max_points >= 4):
        raise ArgumentError("max_points: must be an int of at least 4")
    if len(cloud) <= max_points:
        return cloud
    k = np.arange(max_points, dtype=float)
    z = 1 - (2 * k + 1) / max_points
    ring = np.sqrt(np.maximum(0.0, 1 - z * z))
    longitude = np.pi * (3 - np.sqrt(5.0)) * (k + 0.5)
    directions = np.stack([ring * np.cos(longitude), ring * np.sin(longitude), z], axis=1)
    # In slices of the cloud, so that a million points do not take directions x points of memory.
    best = np.zeros(max_points, dtype=np.int64)
    farthest = np.full(max_points, -np.inf)
    for start in range(0, len(cloud), 8192):
        along = directions @ cloud[start:start + 8192].T
        here = np.argmax(along, axis=1)
        value = along[np.arange(max_points), here]
        better = value > farthest
        best[better] = start + here[better]
        farthest[better] = value[better]
    return cloud[np.unique(best)]


@dataclass(frozen=True)
class Plane:
    """The half-space z <= 0 of the body's frame: a ground (static bodies only)."""

    def to_proto(self):
        shape = pb.Shape()
        shape.plane.SetInParent()
        return shape


@dataclass(frozen=True)
class HeightField:
    """Terrain (static bodies only): `heights`, an array of shape (samples along y, samples
    along x) in m, row j at y = (j - (rows - 1) / 2) * spacing[1] and column i at
    x = (i - (columns - 1) / 2) * spacing[0]; the grid is centred on the body's origin and the
    solid lies below its surface. Each cell is two triangles split along its diagonal from
    (i, j) to (i + 1, j + 1)."""

    heights: np.ndarray = field(default_factory=lambda: np.zeros((2, 2)))
    spacing: tuple = (1.0, 1.0)

    def to_proto(self):
        heights = np.asarray(self.heights, dtype=float)
        if heights.ndim != 2 or heights.shape[0] < 2 or heights.shape[1] < 2:
            raise ArgumentError(f"heights: expected a 2-D array of at least 2 x 2 samples, got "
                                f"shape {heights.shape}")
        if not np.all(np.isfinite(heights)):
            raise ArgumentError("heights: must be finite")
        spacing = convert.array(self.spacing, 2, "spacing")
        shape = pb.Shape()
        shape.heightfield.samples_y, shape.heightfield.samples_x = heights.shape
        shape.heightfield.spacing_x = float(spacing[0])
        shape.heightfield.spacing_y = float(spacing[1])
        shape.heightfield.heights.extend(heights.ravel().tolist())
        return shape


@dataclass(frozen=True)
class Mesh:
    """Static geometry of triangles (static bodies only): `vertices` (N, 3) in m in the body's
    frame, `triangles` (M, 3) of indices into them. Triangles are one-sided: each holds bodies on
    its front, the side from which its corners run counter-clockwise (a floor's triangles run
    counter-clockwise seen from above; a room's walls face in)."""

    vertices: np.ndarray = field(default_factory=lambda: np.zeros((3, 3)))
    triangles: np.ndarray = field(default_factory=lambda: np.zeros((1, 3), dtype=np.uint32))

    def to_proto(self):
        vertices = convert.points(self.vertices, "vertices")
        triangles = np.asarray(self.triangles)
        if triangles.ndim != 2 or triangles.shape[1] != 3 or triangles.shape[0] < 1:
            raise ArgumentError(f"triangles: expected an (M, 3) array of vertex indices, got "
                                f"shape {triangles.shape}")
        if not np.issubdtype(triangles.dtype, np.integer):
            raise ArgumentError("triangles: must be integers (indices into vertices)")
        if triangles.min() < 0 or triangles.max() >= len(vertices):
            raise ArgumentError(f"triangles: indices must be 0 to {len(vertices) - 1}")
        shape = pb.Shape()
        shape.mesh.vertices.extend(np.asarray(vertices, dtype=float).ravel().tolist())
        shape.mesh.triangles.extend(triangles.astype(np.uint32).ravel().tolist())
        return shape


@dataclass(frozen=True)
class Part:
    """One convex part of a Compound: `shape` (Box, Sphere, Capsule or Hull) placed at
    `position` (m) with `orientation` (w, x, y, z) in the body's frame."""

    shape: object
    position: tuple = (0.0, 0.0, 0.0)
    orientation: tuple = (1.0, 0.0, 0.0, 0.0)


@dataclass(frozen=True)
class Compound:
    """One body of several convex parts (a table of boxes, a dumbbell): `parts`, 1 to 256 Part
    entries. The body's mass properties are its parts' together at its one density; each part
    touches other bodies with contacts of its own."""

    parts: tuple = ()

    def to_proto(self):
        if not self.parts:
            raise ArgumentError("parts: a compound needs at least one part")
        shape = pb.Shape()
        for i, part in enumerate(self.parts):
            name = f"parts[{i}]"
            if not isinstance(part, Part):
                raise ArgumentError(f"{name}: expected a tumble.Part, got {part!r}")
            if not isinstance(part.shape, (Box, Sphere, Capsule, Hull)):
                raise ArgumentError(f"{name}.shape: a compound's parts must be a Box, Sphere, "
                                    f"Capsule or Hull, got {part.shape!r}")
            out = shape.compound.parts.add()
            out.shape.CopyFrom(part.shape.to_proto())
            convert.set_vec3(out.position, part.position, f"{name}.position")
            convert.set_quat(out.orientation, part.orientation, f"{name}.orientation")
        return shape


SHAPES = (Box, Sphere, Capsule, Hull, Plane, HeightField, Mesh, Compound)


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
    if kind == "heightfield":
        field_ = shape.heightfield
        heights = np.array(field_.heights, dtype=float).reshape(field_.samples_y, field_.samples_x)
        return HeightField(heights, (field_.spacing_x, field_.spacing_y))
    if kind == "mesh":
        return Mesh(np.array(shape.mesh.vertices, dtype=float).reshape(-1, 3),
                    np.array(shape.mesh.triangles, dtype=np.uint32).reshape(-1, 3))
    if kind == "compound":
        return Compound(tuple(
            Part(from_proto(part.shape), tuple(convert.vec3(part.position)),
                 tuple(convert.quat(part.orientation)) if part.HasField("orientation")
                 else (1.0, 0.0, 0.0, 0.0))
            for part in shape.compound.parts))
    raise ArgumentError(f"shape: unknown kind {kind!r}")
