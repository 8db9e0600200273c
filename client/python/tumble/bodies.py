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
    `vel` are accepted for position and linear_velocity."""

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

    def __init__(self, shape, position=None, linear_velocity=None, orientation=None,
                 angular_velocity=None, mass=None, density=None, friction=None, restitution=None,
                 color=None, static=False, *, pos=None, vel=None):
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

    def to_proto(self, name="bodies[0]"):
        if not isinstance(self.shape, shapes.SHAPES):
            kinds = ", ".join(kind.__name__ for kind in shapes.SHAPES)
            raise ArgumentError(f"{name}.shape: expected one of {kinds}, got {self.shape!r}")
        spec = pb.BodySpec()
        spec.shape.CopyFrom(self.shape.to_proto())
        spec.type = pb.BODY_TYPE_STATIC if self.static else pb.BODY_TYPE_DYNAMIC
        convert.set_vec3(spec.position, self.position, f"{name}.position")
        convert.set_vec3(spec.linear_velocity, self.linear_velocity, f"{name}.linear_velocity")
        if self.orientation is not None:
            convert.set_quat(spec.orientation, self.orientation, f"{name}.orientation")
        else:
            spec.orientation.w = 1.0
        if self.angular_velocity is not None:
            convert.set_vec3(spec.angular_velocity, self.angular_velocity, f"{name}.angular_velocity")
        for field in ("mass", "density", "friction", "restitution"):
            value = getattr(self, field)
            if value is not None:
                setattr(spec, field, convert.number(value, f"{name}.{field}"))
        spec.color = convert.color(self.color, f"{name}.color")
        return spec


@dataclass
class Description:
    """What a body is: sent once per body (GetBodies, and a frame's `added`)."""

    id: int
    shape: object
    static: bool
    mass: float  # kg; 0 for static bodies
    color: int  # 0xRRGGBBAA; 0: the viewer chooses

    @staticmethod
    def from_proto(description):
        return Description(
            id=description.id,
            shape=shapes.from_proto(description.shape),
            static=description.type == pb.BODY_TYPE_STATIC,
            mass=description.mass,
            color=description.color,
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
        )
