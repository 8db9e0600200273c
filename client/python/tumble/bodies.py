"""Bodies: what to spawn (BodySpec), what a body is (Description) and where it is (Body)."""

from dataclasses import dataclass
from typing import Optional

import numpy as np

from tumble import convert, shapes
from tumble.errors import ArgumentError
from tumble.v1 import world_pb2 as pb


def aliased(name, value, alias_name, alias_value, default):
    """One concept has one name everywhere (position, linear_velocity); the short names of
    earlier versions (pos, vel) are still accepted, but not both at once."""
    if value is not None and alias_value is not None:
        raise ArgumentError(f"{name} and {alias_name} are the same value: give one")
    if value is not None:
        return value
    return alias_value if alias_value is not None else default


@dataclass(init=False)
class BodySpec:
    """One body to spawn. Absent values take the server's defaults: density 1000 kg/m^3 (the mass
    follows from the volume), friction 0.5, restitution 0, identity orientation, at rest.

    position: m, of the shape's origin; linear_velocity: m/s; angular_velocity: rad/s, world
    frame; orientation: (w, x, y, z); color: 0xRRGGBBAA or (r, g, b[, a]) in [0, 1]. `pos` and
    `vel` are accepted for position and linear_velocity.

    What acts on the body beyond gravity and contacts: gravity_scale (the world's gravity times
    this; default 1), linear_damping and angular_damping (1/s: each step takes v to
    v / (1 + c dt)), force (N) and torque (N m, about the centre of mass), world frame, held every
    step until changed (World.set_state). collision_layers and collision_mask (32 bits each;
    default 1 and every layer): two bodies collide when each one's layers meet the other's
    mask."""

    shape: object
    position: tuple = (0.0, 0.0, 0.0)
    linear_velocity: tuple = (0.0, 0.0, 0.0)
    orientation: Optional[tuple] = None
    angular_velocity: Optional[tuple] = None
    mass: Optional[float] = None
    density: Optional[float] = None
    friction: Optional[float] = None
    restitution: Optional[float] = None
    color: object = None
    static: bool = False
    gravity_scale: Optional[float] = None
    linear_damping: Optional[float] = None
    angular_damping: Optional[float] = None
    force: Optional[tuple] = None
    torque: Optional[tuple] = None
    collision_layers: Optional[int] = None
    collision_mask: Optional[int] = None
    kinematic: bool = False

    def __init__(self, shape, position=None, linear_velocity=None, orientation=None,
                 angular_velocity=None, mass=None, density=None, friction=None, restitution=None,
                 color=None, static=False, *, pos=None, vel=None, gravity_scale=None,
                 linear_damping=None, angular_damping=None, force=None, torque=None,
                 collision_layers=None, collision_mask=None, kinematic=False):
        self.shape = shape
        self.position = aliased("position", position, "pos", pos, (0.0, 0.0, 0.0))
        self.linear_velocity = aliased("linear_velocity", linear_velocity, "vel", vel,
                                       (0.0, 0.0, 0.0))
        self.orientation = orientation
        self.angular_velocity = angular_velocity
        self.mass = mass
        self.density = density
        self.friction = friction
        self.restitution = restitution
        self.color = color
        self.static = static
        self.kinematic = kinematic
        self.gravity_scale = gravity_scale
        self.linear_damping = linear_damping
        self.angular_damping = angular_damping
        self.force = force
        self.torque = torque
        self.collision_layers = collision_layers
        self.collision_mask = collision_mask

    def to_proto(self, name="bodies[0]"):
        if not isinstance(self.shape, shapes.SHAPES):
            kinds = ", ".join(kind.__name__ for kind in shapes.SHAPES)
            raise ArgumentError(f"{name}.shape: expected one of {kinds}, got {self.shape!r}")
        spec = pb.BodySpec()
        spec.shape.CopyFrom(self.shape.to_proto())
        if self.static and self.kinematic:
            raise ArgumentError(f"{name}.kinematic: a body is static or kinematic, not both")
        spec.type = (pb.BODY_TYPE_STATIC if self.static else
                     pb.BODY_TYPE_KINEMATIC if self.kinematic else pb.BODY_TYPE_DYNAMIC)
        convert.set_vec3(spec.position, self.position, f"{name}.position")
        convert.set_vec3(spec.linear_velocity, self.linear_velocity, f"{name}.linear_velocity")
        if self.orientation is not None:
            convert.set_quat(spec.orientation, self.orientation, f"{name}.orientation")
        else:
            spec.orientation.w = 1.0
        if self.angular_velocity is not None:
            convert.set_vec3(spec.angular_velocity, self.angular_velocity, f"{name}.angular_velocity")
        for field in ("mass", "density", "friction", "restitution", "gravity_scale",
                      "linear_damping", "angular_damping"):
            value = getattr(self, field)
            if value is not None:
                setattr(spec, field, convert.number(value, f"{name}.{field}"))
        for field in ("force", "torque"):
            value = getattr(self, field)
            if value is not None:
                convert.set_vec3(getattr(spec, field), value, f"{name}.{field}")
        for field in ("collision_layers", "collision_mask"):
            value = getattr(self, field)
            if value is not None:
                setattr(spec, field, bits(value, f"{name}.{field}"))
        spec.color = convert.color(self.color, f"{name}.color")
        return spec


def bits(value, name):
    """A collision filter's 32 bits, refused naming the field when it is not."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or not (
            0 <= int(value) <= 0xFFFFFFFF):
        raise ArgumentError(f"{name}: must be an integer in [0, 4294967295] (32 bits), "
                            f"got {value!r}")
    return int(value)


@dataclass
class Description:
    """What a body is: sent once per body (GetBodies, and a frame's `added`)."""

    id: int
    shape: object
    static: bool
    mass: float  # kg; 0 for static and kinematic bodies
    color: int  # 0xRRGGBBAA; 0: the viewer chooses
    # Moved only by the velocity given it (spawn, set_state), never pushed back.
    kinematic: bool = False

    @staticmethod
    def from_proto(description):
        return Description(
            id=description.id,
            shape=shapes.from_proto(description.shape),
            static=description.type == pb.BODY_TYPE_STATIC,
            mass=description.mass,
            color=description.color,
            kinematic=description.type == pb.BODY_TYPE_KINEMATIC,
        )


@dataclass
class Body(Description):
    """A body and its state at `step`: position of the centre of mass (m), orientation (w, x, y,
    z), velocities (m/s, rad/s in the world frame)."""

    step: int = 0
    position: np.ndarray = None
    orientation: np.ndarray = None
    linear_velocity: np.ndarray = None
    angular_velocity: np.ndarray = None
    asleep: bool = False
    # What acts on it beyond gravity and contacts (BodySpec), and its collision filter.
    gravity_scale: float = 1.0
    linear_damping: float = 0.0
    angular_damping: float = 0.0
    force: np.ndarray = None
    torque: np.ndarray = None
    collision_layers: int = 1
    collision_mask: int = 0xFFFFFFFF

    @staticmethod
    def from_proto(description, state, step):
        return Body(
            **vars(Description.from_proto(description)),
            step=step,
            position=convert.vec3(state.position),
            orientation=convert.quat(state.orientation),
            linear_velocity=convert.vec3(state.linear_velocity),
            angular_velocity=convert.vec3(state.angular_velocity),
            asleep=state.asleep,
            gravity_scale=description.gravity_scale,
            linear_damping=description.linear_damping,
            angular_damping=description.angular_damping,
            force=convert.vec3(description.force),
            torque=convert.vec3(description.torque),
            collision_layers=description.collision_layers,
            collision_mask=description.collision_mask,
        )
