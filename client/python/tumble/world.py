"""The world's calls (WorldCalls), shared by a connection to a Tumble server and the world it
steps (RemoteWorld, the tumble.v1.World service) and the engine in this process (tumble.World,
tumble/local.py): both take and answer the same tumble.v1 messages."""

import json
import os
import time
from dataclasses import dataclass
from types import SimpleNamespace

import grpc
import numpy as np

from tumble import convert, shapes
from tumble.bodies import Body, BodySpec, aliased, bits
from tumble.errors import ArgumentError, Error, from_rpc
from tumble.frames import FrameStream, plain
from tumble.shapes import Box, Capsule, HeightField, Hull, Mesh, Plane, Sphere
from tumble.v1 import world_pb2 as pb
from tumble.v1 import world_pb2_grpc as pb_grpc

# Frames and snapshots of large worlds exceed gRPC's default 4 MiB (the C++ client's limit too).
_MAX_MESSAGE_BYTES = 512 << 20

_SOLVERS = {
    "exact": pb.SOLVER_KIND_EXACT,
    "pgs": pb.SOLVER_KIND_PGS,
    "soft": pb.SOLVER_KIND_SOFT,
    "auto": pb.SOLVER_KIND_AUTO,
}


def _placed(query, shape, position, orientation, mask, call):
    """Fills the shape a query places in the world (OverlapQuery, ShapeCastQuery): shape,
    position, orientation and mask."""
    if not isinstance(shape, shapes.SHAPES):
        raise ArgumentError(f"shape: expected a Box, Sphere, Capsule, Hull or Compound, got "
                            f"{shape!r}", call)
    query.shape.CopyFrom(shape.to_proto())
    convert.set_vec3(query.position, position, "position")
    if orientation is not None:
        convert.set_quat(query.orientation, orientation, "orientation")
    if mask is not None:
        query.mask = bits(mask, "mask")
    return query


@dataclass
class Settings:
    """The run's settings in force: dt (s), substeps (soft solver), solver, gravity (m/s^2),
    real_time_factor (1: wall-clock pace, 0: as fast as the machine can), sleeping (bodies at
    rest fall asleep and cost nothing until touched), iterations (pgs's velocity sweeps a step),
    joint_position_passes (position passes over the joints solved joint by joint, soft and pgs,
    after each move)."""

    dt: float
    substeps: int
    solver: str
    gravity: tuple
    real_time_factor: float
    sleeping: bool = True
    iterations: int = 10
    joint_position_passes: int = 3

    @staticmethod
    def from_proto(settings):
        solver = next((k for k, v in _SOLVERS.items() if v == settings.solver), "unspecified")
        gravity = (settings.gravity.x, settings.gravity.y, settings.gravity.z)
        return Settings(settings.dt, settings.substeps, solver, gravity, settings.real_time_factor,
                        settings.sleeping, settings.iterations, settings.joint_position_passes)


@dataclass
class Info:
    version: str
    step: int
    time: float  # s, simulated
    body_count: int
    running: bool
    settings: Settings
    last_step: SimpleNamespace  # the last step's statistics (tumble.v1.StepStats)
    subscribers: int
    # Simulated seconds per wall-clock second over the last second of running, and whether the
    # world is late on its real-time factor (by more than a quarter second).
    achieved_real_time_factor: float = 0.0
    behind: bool = False
    joint_count: int = 0


@dataclass
class Snapshot:
    """The whole world's state at `step`; World.restore continues the run from it bit for bit.
    `state` is what `tumble snapshot FILE` writes, so files move between the two."""

    step: int
    state: bytes


@dataclass
class LoadedScene:
    name: str
    ids: list  # the scene's bodies, in its order


@dataclass
class States:
    """Bodies' states as parallel arrays: ids[i] is at positions[i] (m, centre of mass) with
    orientations[i] (w, x, y, z), linear_velocities[i] (m/s) and angular_velocities[i] (rad/s,
    world); asleep[i] says whether it sleeps."""

    ids: np.ndarray  # (N,) uint64
    positions: np.ndarray  # (N, 3)
    orientations: np.ndarray  # (N, 4)
    linear_velocities: np.ndarray  # (N, 3)
    angular_velocities: np.ndarray  # (N, 3)
    asleep: np.ndarray  # (N,) bool

    def __len__(self):
        return len(self.ids)


def connect(address=None, token=None, *, tls_ca=None, timeout=5.0):
    """Connects to a Tumble server and checks that it answers: an unreachable server, or one
    that refuses the token, raises tumble.Error here (naming the address), not on first use.

    address: HOST:PORT (default: $TUMBLE_SERVER when set, else 127.0.0.1:50051, as the CLI).
    token: sent as "authorization: Bearer TOKEN" (default: $TUMBLE_TOKEN when set).
    tls_ca: path of the PEM certificate authority that signed the server's certificate; when
    given, the connection uses TLS. timeout: s to wait for the server's first answer."""
    if address is None:
        address = os.environ.get("TUMBLE_SERVER") or "127.0.0.1:50051"
    if token is None:
        token = os.environ.get("TUMBLE_TOKEN") or None
    options = [("grpc.max_receive_message_length", _MAX_MESSAGE_BYTES),
               ("grpc.max_send_message_length", _MAX_MESSAGE_BYTES)]
    if tls_ca is not None:
        try:
            with open(tls_ca, "rb") as file:
                authority = file.read()
        except OSError as error:
            raise ArgumentError(f"tls_ca: cannot read {tls_ca}: {error.strerror}", "connect") from None
        channel = grpc.secure_channel(address, grpc.ssl_channel_credentials(authority), options)
    else:
        channel = grpc.insecure_channel(address, options)
    world = RemoteWorld(channel, address, token)
    try:
        world._rpc("GetInfo", pb.GetInfoRequest(), timeout=timeout)
    except Error as error:
        world.close()
        raise Error(error.code, f"the Tumble server at {address} did not answer: {error.message}",
                    "connect") from None
    return world


class WorldCalls:
    """What a world answers, remote or in this process. Every change is applied between two steps,
    all at once: a refused call raises tumble.Error and leaves the world exactly as it was."""

    def _rpc(self, method, request, timeout=None):
        raise NotImplementedError

    # --- bodies -------------------------------------------------------------------------------

    def spawn(self, shape, position=None, linear_velocity=None, **options):
        """Spawns one body of `shape` (Box, Sphere, Capsule, Hull, Plane, HeightField, Mesh or
        Compound); returns its id.
        Options are BodySpec's: orientation, angular_velocity, mass, density, friction,
        restitution, color, static, kinematic (moved only by its velocity: linear_velocity,
        angular_velocity, and set_state's), gravity_scale, linear_damping, angular_damping,
        force, torque, collision_layers, collision_mask (and pos, vel: the older names of
        position and linear_velocity)."""
        return self.spawn_many([BodySpec(shape, position, linear_velocity, **options)])[0]

    def spawn_many(self, specs):
        """Spawns a batch of BodySpec all or nothing; returns their ids in the order given."""
        request = pb.SpawnBodiesRequest()
        for i, spec in enumerate(specs):
            if not isinstance(spec, BodySpec):
                raise ArgumentError(f"bodies[{i}]: expected a BodySpec, got {spec!r}", "spawn")
            request.bodies.append(spec.to_proto(f"bodies[{i}]"))
        return list(self._rpc("SpawnBodies", request).ids)

    def spawn_box(self, size, mass=None, position=None, linear_velocity=None, **options):
        """A box of full extents `size` (m); mass in kg (default: from density)."""
        return self.spawn(Box(tuple(convert.array(size, 3, "size"))), position, linear_velocity,
                          mass=mass, **options)

    def spawn_sphere(self, radius, mass=None, position=None, linear_velocity=None, **options):
        return self.spawn(Sphere(radius), position, linear_velocity, mass=mass, **options)

    def spawn_capsule(self, radius, half_height, mass=None, position=None, linear_velocity=None,
                      **options):
        """A capsule along the body's z axis: a segment of length 2 half_height swept by a
        sphere of `radius`."""
        return self.spawn(Capsule(radius, half_height), position, linear_velocity, mass=mass,
                          **options)

    def spawn_hull(self, points, mass=None, position=None, linear_velocity=None, **options):
        """The convex hull of `points` ((N, 3), body frame, m)."""
        return self.spawn(Hull(convert.points(points, "points")), position, linear_velocity,
                          mass=mass, **options)

    def spawn_ground(self, height=0.0, **options):
        """A static ground: the half-space below z = height."""
        return self.spawn(Plane(), (0.0, 0.0, height), static=True, **options)

    def spawn_heightfield(self, heights, spacing, position=None, **options):
        """Static terrain: `heights` ((rows along y, columns along x), m) on a grid of `spacing`
        (x, y, m), centred on `position`; see HeightField."""
        return self.spawn(HeightField(np.asarray(heights, dtype=float), tuple(spacing)), position,
                          static=True, **options)

    def spawn_mesh(self, vertices, triangles, position=None, **options):
        """Static geometry of triangles: `vertices` ((N, 3), body frame, m) and `triangles`
        ((M, 3) indices, counter-clockwise seen from the front); see Mesh."""
        return self.spawn(Mesh(convert.points(vertices, "vertices"), np.asarray(triangles)),
                          position, static=True, **options)

    def remove(self, ids):
        """Removes a body or a list of them, all or nothing (one unknown id: NOT_FOUND)."""
        self._rpc("RemoveBodies", pb.RemoveBodiesRequest(ids=convert.ids(ids)))

    def set_state(self, body_id, position=None, orientation=None, linear_velocity=None,
                  angular_velocity=None, *, pos=None, vel=None, force=None, torque=None,
                  force_point=None, gravity_scale=None, linear_damping=None,
                  angular_damping=None, collision_layers=None, collision_mask=None):
        """Moves a body, sets its velocities, what acts on it or its collision filter (BodySpec's
        fields); values not given are left as they are (pos and vel: the older names of position
        and linear_velocity). force (N) and torque (N m) are held every step until changed; with
        force_point (m, world) the force acts there and the held torque becomes its moment about
        the centre of mass plus `torque`. The body wakes."""
        update = pb.BodyStateUpdate(id=convert.ids(body_id, "id")[0])
        for field, value in (("force", force), ("torque", torque), ("force_point", force_point)):
            if value is not None:
                convert.set_vec3(getattr(update, field), value, field)
        for field, value in (("gravity_scale", gravity_scale), ("linear_damping", linear_damping),
                             ("angular_damping", angular_damping)):
            if value is not None:
                setattr(update, field, convert.number(value, field))
        for field, value in (("collision_layers", collision_layers),
                             ("collision_mask", collision_mask)):
            if value is not None:
                setattr(update, field, bits(value, field))
        position = aliased("position", position, "pos", pos, None)
        linear_velocity = aliased("linear_velocity", linear_velocity, "vel", vel, None)
        if position is not None:
            convert.set_vec3(update.position, position, "position")
        if orientation is not None:
            convert.set_quat(update.orientation, orientation, "orientation")
        if linear_velocity is not None:
            convert.set_vec3(update.linear_velocity, linear_velocity, "linear_velocity")
        if angular_velocity is not None:
            convert.set_vec3(update.angular_velocity, angular_velocity, "angular_velocity")
        self._rpc("SetBodyState", pb.SetBodyStateRequest(updates=[update]))

    def apply_impulse(self, body_id, impulse, point=None):
        """An impulse (N s, world) at `point` (m, world; default the centre of mass) before the
        next step."""
        entry = pb.Impulse(id=convert.ids(body_id, "id")[0])
        convert.set_vec3(entry.impulse, impulse, "impulse")
        if point is not None:
            convert.set_vec3(entry.point, point, "point")
        self._rpc("ApplyImpulse", pb.ApplyImpulseRequest(impulses=[entry]))

    def bodies(self, ids=()):
        """Every body (or those of `ids`) with its state at the current step."""
        response = self._rpc("GetBodies", pb.GetBodiesRequest(ids=convert.ids(ids)))
        return [Body.from_proto(d, s, response.step)
                for d, s in zip(response.descriptions, response.states)]

    def body(self, body_id):
        return self.bodies([body_id])[0]

    # --- queries ------------------------------------------------------------------------------

    def cast_rays(self, origins, directions, max_distance=1000.0, *, mask=None, hits_per_ray=0):
        """Casts N rays between two steps: origins and directions are (N, 3) arrays (m, world;
        directions of any length but zero), max_distance one number or N (m). A ray meets the
        bodies whose collision layers share a bit with `mask` (default every layer).

        hits_per_ray=0 returns each ray's nearest hit as arrays of N rows: `hit` (bool), `body`
        (ids, 0 for no hit), `distance` (m) and `fraction` (of max_distance; NaN for no hit),
        `point` and `normal` ((N, 3), world; NaN for no hit). hits_per_ray=k (1 to 64) returns
        each ray's first k hits, nearest first, as arrays over the hits with `ray` (which ray
        each belongs to) and `counts` (hits per ray), and `left_out` (some ray met more)."""
        origins = convert.points(origins, "origins")
        directions = convert.points(directions, "directions")
        if directions.shape != origins.shape:
            raise ArgumentError(f"directions: expected shape {origins.shape}, got "
                                f"{directions.shape}", "cast_rays")
        request = pb.QueryRequest(ray_origins=origins.ravel().tolist(),
                                  ray_directions=directions.ravel().tolist())
        distances = np.asarray(max_distance, dtype=float).ravel()
        request.ray_max_distances.extend(distances.tolist())
        if mask is not None:
            request.ray_mask = bits(mask, "mask")
        if isinstance(hits_per_ray, bool) or not isinstance(hits_per_ray, int) or hits_per_ray < 0:
            raise ArgumentError(f"hits_per_ray: expected an integer >= 0, got {hits_per_ray!r}",
                                "cast_rays")
        request.hits_per_ray = hits_per_ray
        response = self._rpc("Query", request)
        counts = np.array(response.hit_counts, dtype=np.int64)
        ids = np.array(response.hit_ids, dtype=np.uint64)
        distance = np.array(response.hit_distances)
        fraction = np.array(response.hit_fractions)
        point = np.array(response.hit_points).reshape(-1, 3)
        normal = np.array(response.hit_normals).reshape(-1, 3)
        if hits_per_ray > 0:
            return SimpleNamespace(counts=counts, ray=np.repeat(np.arange(len(counts)), counts),
                                   body=ids, distance=distance, fraction=fraction, point=point,
                                   normal=normal, left_out=response.hits_left_out,
                                   step=response.step)
        hit = counts > 0
        n = len(counts)
        out = SimpleNamespace(hit=hit, body=np.zeros(n, dtype=np.uint64),
                              distance=np.full(n, np.nan), fraction=np.full(n, np.nan),
                              point=np.full((n, 3), np.nan), normal=np.full((n, 3), np.nan),
                              step=response.step)
        out.body[hit], out.distance[hit], out.fraction[hit] = ids, distance, fraction
        out.point[hit], out.normal[hit] = point, normal
        return out

    def overlap(self, shape, position, orientation=None, *, mask=None):
        """The ids of the bodies that `shape` (Box, Sphere, Capsule, Hull or Compound) placed at
        `position` (m, world) and `orientation` (w, x, y, z) overlaps or touches, in the order of
        their slots; `mask`: the collision layers it meets (default every layer)."""
        query = _placed(pb.OverlapQuery(), shape, position, orientation, mask, "overlap")
        response = self._rpc("Query", pb.QueryRequest(overlaps=[query]))
        return [int(body) for body in response.overlap_ids]

    def closest_point(self, body_id, point, max_distance=1000.0):
        """The point of the body's surface nearest to `point` (m, world), as a dict (distance,
        negative inside the body; point; normal, outward), or None when the body is farther
        than max_distance (m)."""
        query = pb.ClosestPointQuery(id=convert.ids(body_id, "id")[0],
                                     max_distance=convert.number(max_distance, "max_distance"))
        convert.set_vec3(query.point, point, "point")
        response = self._rpc("Query", pb.QueryRequest(closest_points=[query]))
        if not response.closest_found[0]:
            return None
        return {"distance": response.closest_distances[0],
                "point": np.array(response.closest_surface_points[:3]),
                "normal": np.array(response.closest_normals[:3])}

    def cast_shape(self, shape, position, translation, orientation=None, *, mask=None):
        """Sweeps `shape` (Box, Sphere, Capsule, Hull or Compound) from `position` (m, world) along
        `translation` (m, world) without turning it (`orientation`: w, x, y, z); returns the first
        body it meets as a dict (body, fraction of the translation at first contact, 0 if it
        starts touching; point on the body and the body's outward normal there, world; converged:
        False when the advancement stopped at its bound), or None. `mask`: the collision layers
        it meets (default every layer)."""
        query = _placed(pb.ShapeCastQuery(), shape, position, orientation, mask, "cast_shape")
        convert.set_vec3(query.translation, translation, "translation")
        response = self._rpc("Query", pb.QueryRequest(shape_casts=[query]))
        if not response.cast_hits[0]:
            return None
        return {"body": int(response.cast_ids[0]), "fraction": response.cast_fractions[0],
                "point": np.array(response.cast_points[:3]),
                "normal": np.array(response.cast_normals[:3]),
                "converged": response.cast_converged[0]}

    def cast_ray(self, origin, direction, max_distance=1000.0, *, mask=None):
        """One ray's nearest hit as a dict (body, distance, fraction, point, normal), or None."""
        found = self.cast_rays([convert.array(origin, 3, "origin")],
                               [convert.array(direction, 3, "direction")], max_distance,
                               mask=mask)
        if not found.hit[0]:
            return None
        return {"body": int(found.body[0]), "distance": float(found.distance[0]),
                "fraction": float(found.fraction[0]), "point": found.point[0],
                "normal": found.normal[0]}

    # --- joints -------------------------------------------------------------------------------

    def joint(self, kind, a, b=0, anchor=(0.0, 0.0, 0.0), *, anchor_b=None, axis=None,
              length=0.0, limits=None, motor=None, spring=None, max_swing=None,
              friction=0.0, collide_connected=False):
        """Joins body `a` to body `b` (0: the world) with a joint of `kind` ("ball", "hinge",
        "fixed", "distance" or "slider") at `anchor` (m, world); returns its id. limits:
        (lower, upper) of the free coordinate (rad or m); motor: (speed, max_force); spring:
        (target, stiffness, damping); max_swing: a ball's cone (rad); friction: the joint's own
        friction against its free motion (N m for a ball or hinge, N for a slider)."""
        kinds = {"ball": pb.JOINT_KIND_BALL, "hinge": pb.JOINT_KIND_HINGE,
                 "fixed": pb.JOINT_KIND_FIXED, "distance": pb.JOINT_KIND_DISTANCE,
                 "slider": pb.JOINT_KIND_SLIDER}
        if kind not in kinds:
            raise ArgumentError(f"kind: must be one of {', '.join(kinds)}, got {kind!r}", "joint")
        spec = pb.JointSpec(kind=kinds[kind], a=convert.ids(a, "a")[0],
                            b=convert.ids(b, "b")[0] if b else 0, length=float(length),
                            friction=float(friction), collide_connected=bool(collide_connected))
        convert.set_vec3(spec.anchor, anchor, "anchor")
        if anchor_b is not None:
            convert.set_vec3(spec.anchor_b, anchor_b, "anchor_b")
        if axis is not None:
            convert.set_vec3(spec.axis, axis, "axis")
        if limits is not None:
            lower, upper = convert.array(limits, 2, "limits")
            spec.limit.lower, spec.limit.upper = float(lower), float(upper)
        if motor is not None:
            speed, force = convert.array(motor, 2, "motor")
            spec.motor.speed, spec.motor.max_force = float(speed), float(force)
        if spring is not None:
            target, stiffness, damping = convert.array(spring, 3, "spring")
            spec.spring.target, spec.spring.stiffness = float(target), float(stiffness)
            spec.spring.damping = float(damping)
        if max_swing is not None:
            spec.max_swing = float(max_swing)
        return list(self._rpc("CreateJoints", pb.CreateJointsRequest(joints=[spec])).ids)[0]

    def hinge(self, a, b=0, anchor=(0.0, 0.0, 0.0), axis=(0.0, 0.0, 1.0), **options):
        """A hinge about `axis` through `anchor`; options as joint()'s (limits, motor, spring)."""
        return self.joint("hinge", a, b, anchor, axis=axis, **options)

    def drive(self, joint_id, motor=None, spring=None, *, motor_off=False, spring_off=False):
        """Changes a running joint's motor (speed, max_force) or spring (target, stiffness,
        damping), or turns them off."""
        update = pb.JointDriveUpdate(id=convert.ids(joint_id, "id")[0], motor_off=motor_off,
                                     spring_off=spring_off)
        if motor is not None:
            update.motor.speed, update.motor.max_force = (
                float(v) for v in convert.array(motor, 2, "motor"))
        if spring is not None:
            target, stiffness, damping = convert.array(spring, 3, "spring")
            update.spring.target, update.spring.stiffness = float(target), float(stiffness)
            update.spring.damping = float(damping)
        self._rpc("SetJointDrives", pb.SetJointDrivesRequest(updates=[update]))

    def remove_joints(self, ids):
        """Removes a joint or a list of them, all or nothing."""
        self._rpc("RemoveJoints", pb.RemoveJointsRequest(ids=convert.ids(ids)))

    def joints(self, ids=()):
        """Every joint (or those of `ids`): a dict of id, kind, a, b, position, speed, effort,
        force, torque and error at the current step."""
        response = self._rpc("GetJoints", pb.GetJointsRequest(ids=convert.ids(ids)))
        names = {v: k for k, v in pb.JointKind.items()}
        return [{"id": i, "kind": names[spec.kind].removeprefix("JOINT_KIND_").lower(),
                 "a": spec.a, "b": spec.b, "position": state.position, "speed": state.speed,
                 "effort": state.effort, "force": convert.vec3(state.force),
                 "torque": convert.vec3(state.torque), "error": state.error}
                for i, spec, state in zip(response.ids, response.specs, response.states)]

    # --- the run ------------------------------------------------------------------------------

    def play(self):
        """Steps continuously (at the real-time factor's pace)."""
        self._control(pb.ControlRequest(play=True))

    def pause(self, timeout=60.0):
        """Stops after the current step; returns the step it stopped at once it has."""
        response = self._control(pb.ControlRequest(pause=True))
        return self._wait_until_stopped(response, timeout, "pause")

    def step(self, n=1, timeout=600.0):
        """Runs n steps, pauses, and returns the step reached once they are computed."""
        if isinstance(n, bool) or not isinstance(n, int) or not 1 <= n < 2**32:
            raise ArgumentError(f"n: expected a number of steps in [1, 2^32), got {n!r}", "step")
        response = self._control(pb.ControlRequest(step=n))
        return self._wait_until_stopped(response, timeout, "step")

    def reset(self):
        """Back to the scene as last loaded, at step 0."""
        self._control(pb.ControlRequest(reset=True))

    def settings(self, dt=None, substeps=None, solver=None, gravity=None, real_time_factor=None,
                 sleeping=None, iterations=None, joint_position_passes=None):
        """Changes the settings given (none: reads them); returns the settings in force."""
        request = pb.ControlRequest()
        settings = request.settings
        if dt is not None:
            settings.dt = convert.number(dt, "dt")
        if substeps is not None:
            settings.substeps = convert.integer(substeps, "substeps")
        if iterations is not None:
            settings.iterations = convert.integer(iterations, "iterations")
        if joint_position_passes is not None:
            settings.joint_position_passes = convert.integer(joint_position_passes,
                                                             "joint_position_passes")
        if solver is not None:
            if solver not in _SOLVERS:
                raise ArgumentError(
                    f"solver: expected one of {', '.join(_SOLVERS)}, got {solver!r}", "settings")
            settings.solver = _SOLVERS[solver]
        if gravity is not None:
            convert.set_vec3(settings.gravity, gravity, "gravity")
        if real_time_factor is not None:
            settings.real_time_factor = convert.number(real_time_factor, "real_time_factor")
        if sleeping is not None:
            if not isinstance(sleeping, bool):
                raise ArgumentError(f"sleeping: expected True or False, got {sleeping!r}",
                                    "settings")
            settings.sleeping = sleeping
        return Settings.from_proto(self._rpc("Control", request).settings)

    def load_scene(self, scene):
        """Replaces the world with a scene: a dict or JSON text in the format of docs/SCENES.md,
        or a path (os.PathLike) to such a file."""
        if isinstance(scene, os.PathLike):
            with open(scene, "rb") as file:
                text = file.read()
        elif isinstance(scene, dict):
            text = json.dumps(scene).encode()
        elif isinstance(scene, (str, bytes)):
            text = scene.encode() if isinstance(scene, str) else scene
        else:
            raise ArgumentError(f"scene: expected a dict, JSON text or a path, got {scene!r}",
                                "load_scene")
        return self._loaded(self._rpc("LoadScene", pb.LoadSceneRequest(scene_json=text)))

    def load_builtin(self, name):
        """Replaces the world with a built-in scene: "default", "pile:1000", "pyramid:20", ..."""
        request = pb.LoadSceneRequest(builtin=str(name).encode())
        return self._loaded(self._rpc("LoadScene", request))

    def info(self):
        response = self._rpc("GetInfo", pb.GetInfoRequest())
        return Info(response.version, response.step, response.time, response.body_count,
                    response.running, Settings.from_proto(response.settings),
                    plain(response.last_step), response.subscribers,
                    response.achieved_real_time_factor, response.behind, response.joint_count)

    # --- snapshots ---------------------------------------------------------------------------

    def snapshot(self):
        response = self._rpc("Snapshot", pb.SnapshotRequest())
        return Snapshot(response.step, response.state)

    def restore(self, snapshot):
        """Restores a Snapshot (or its bytes). Returns {old id: new id} for bodies that got new
        ids (a snapshot made by another server process); empty when every id was kept."""
        state = snapshot.state if isinstance(snapshot, Snapshot) else snapshot
        if not isinstance(state, (bytes, bytearray)):
            raise ArgumentError(f"snapshot: expected a Snapshot or bytes, got {type(state)!r}",
                                "restore")
        return dict(self._rpc("Restore", pb.RestoreRequest(state=bytes(state))).new_ids)

    def _control(self, request):
        return self._rpc("Control", request)

    def _wait_until_stopped(self, response, timeout, call):
        # The server answers at once; the steps asked for (or the one under way) end later.
        deadline = time.monotonic() + timeout
        step, running = response.step, response.running
        while running:
            if time.monotonic() > deadline:
                raise Error(grpc.StatusCode.DEADLINE_EXCEEDED,
                            f"the world did not stop within {timeout} s (at step {step})", call)
            time.sleep(0.002)
            info = self._rpc("GetInfo", pb.GetInfoRequest())
            step, running = info.step, info.running
        return step

    def _loaded(self, response):
        return LoadedScene(response.name, list(response.ids))


def _checked_ids(ids, call):
    array = np.asarray(ids)
    if array.ndim != 1 or not (array.size == 0 or np.issubdtype(array.dtype, np.integer)):
        raise ArgumentError("ids: expected a 1-D sequence of body ids", call)
    return [int(i) for i in array]


def _checked_rows(values, n, width, name, call):
    if values is None:
        return None
    array = np.asarray(values, dtype=float)
    if array.shape != (n, width):
        raise ArgumentError(f"{name}: expected shape ({n}, {width}), got {array.shape}", call)
    return array


class RemoteWorld(WorldCalls):
    """The world of one server, through a gRPC channel (tumble.connect makes one)."""

    def __init__(self, channel, address, token=None):
        self.address = address
        self._channel = channel
        self._stub = pb_grpc.WorldStub(channel)
        self._raw_frames = channel.unary_stream(
            "/tumble.v1.World/StreamFrames",
            request_serializer=pb.StreamFramesRequest.SerializeToString,
            response_deserializer=None)
        self._metadata = (("authorization", f"Bearer {token}"),) if token else ()

    def states(self, ids=None):
        """The states of every body (or of `ids`) as arrays (States)."""
        bodies = self.bodies(() if ids is None else _checked_ids(ids, "states"))
        return States(np.array([b.id for b in bodies], dtype=np.uint64),
                      np.array([b.position for b in bodies]).reshape(-1, 3),
                      np.array([b.orientation for b in bodies]).reshape(-1, 4),
                      np.array([b.linear_velocity for b in bodies]).reshape(-1, 3),
                      np.array([b.angular_velocity for b in bodies]).reshape(-1, 3),
                      np.array([b.asleep for b in bodies], dtype=bool))

    def set_states(self, ids, positions=None, orientations=None, linear_velocities=None,
                   angular_velocities=None):
        """Sets the given arrays' rows on the bodies of `ids`, all or nothing."""
        ids = _checked_ids(ids, "set_states")
        columns = [(name, _checked_rows(values, len(ids), width, name, "set_states"))
                   for name, values, width in (("position", positions, 3),
                                               ("orientation", orientations, 4),
                                               ("linear_velocity", linear_velocities, 3),
                                               ("angular_velocity", angular_velocities, 3))]
        request = pb.SetBodyStateRequest()
        for row, body_id in enumerate(ids):
            update = request.updates.add(id=body_id)
            for name, values in columns:
                if values is None:
                    continue
                if name == "orientation":
                    w, x, y, z = values[row]
                    update.orientation.w, update.orientation.x = w, x
                    update.orientation.y, update.orientation.z = y, z
                else:
                    field = getattr(update, name)
                    field.x, field.y, field.z = values[row]
        self._rpc("SetBodyState", request)

    def apply_impulses(self, ids, impulses, points=None):
        """Impulses (N s, world) at points (m, world; default the centres of mass), one row per
        id, applied together before the next step, all or nothing."""
        ids = _checked_ids(ids, "apply_impulses")
        impulses = _checked_rows(impulses, len(ids), 3, "impulses", "apply_impulses")
        points = _checked_rows(points, len(ids), 3, "points", "apply_impulses")
        request = pb.ApplyImpulseRequest()
        for row, body_id in enumerate(ids):
            entry = request.impulses.add(id=body_id)
            entry.impulse.x, entry.impulse.y, entry.impulse.z = impulses[row]
            if points is not None:
                entry.point.x, entry.point.y, entry.point.z = points[row]
        self._rpc("ApplyImpulse", request)

    # --- frames -----------------------------------------------------------------------------

    def frames(self, rate=0.0, velocities=False, contacts=False, stats=False, ids=(), count=None,
               duration=None, changes_only=False, full_frame_interval=0.0, joints=False):
        """Subscribes to the world's frames: every step's, or at most `rate` per second. A slow
        reader loses frames (Frame.dropped counts them), never slows the world. Frames come only
        while the world steps. The subscription ends after `count` frames or `duration` seconds,
        whichever comes first (default: when closed or when the server stops).

        With `changes_only`, a frame lists only the bodies that changed since the previous one
        (Frame.changes_only is then True; the others are where earlier frames left them): a world
        of sleeping bodies costs nothing a frame. The first frame, the first after the world is
        replaced, and one every `full_frame_interval` seconds (0: never) list every body.

        With `joints`, each frame carries every joint's state (Frame.joints) and the joints new
        to this subscription (Frame.joints_added; FrameStream.joints keeps them)."""
        request = pb.StreamFramesRequest(max_rate=convert.number(rate, "rate"),
                                         velocities=bool(velocities), contacts=bool(contacts),
                                         stats=bool(stats), ids=convert.ids(ids),
                                         changes_only=bool(changes_only), joints=bool(joints),
                                         full_frame_interval=convert.number(
                                             full_frame_interval, "full_frame_interval"))
        if count is not None and (isinstance(count, bool) or not isinstance(count, int)
                                  or count < 0):
            raise ArgumentError(f"count: expected an integer >= 0, got {count!r}", "frames")
        if duration is not None:
            duration = convert.number(duration, "duration")
        # Undecoded: FrameStream reads the arrays from the bytes (tumble.wire).
        call = self._raw_frames(request, metadata=self._metadata, timeout=duration)
        return FrameStream(call, request, count, duration is not None, "frames")

    # --- the connection -----------------------------------------------------------------------

    def close(self):
        self._channel.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def _rpc(self, method, request, timeout=None):
        try:
            return getattr(self._stub, method)(request, metadata=self._metadata, timeout=timeout)
        except grpc.RpcError as error:
            raise from_rpc(error, method) from None
