"""The engine in this process: tumble.World(), as pybullet and MuJoCo users expect.

    import tumble
    world = tumble.World()                      # or tumble.connect("host:50051"): same calls
    world.spawn_ground()
    box = world.spawn_box(size=(1, 1, 1), position=(0, 0, 5))
    world.step(120)
    states = world.states()                     # numpy arrays of every body

It is the server's world without the server: the same shapes, settings, solvers, limits, scene
files, snapshots (bytes that move between the two) and refusals (tumble.Error with the gRPC code
the server would send). It does not run by itself: step(n) runs n steps before it returns, and
frames() steps once per frame it yields."""

import os
import time

import grpc
import numpy as np

from tumble.errors import ArgumentError, Error
from tumble.frames import Contacts, FrameStream
from tumble.v1 import world_pb2 as pb
from tumble.world import States, WorldCalls

# The step's OpenMP threads wait for work passively, as tumble-server's do: spinning, they fight the
# Python thread and anything else on the machine for the cores (docs/PERFORMANCE.md, "Threads on
# a busy machine"). libgomp reads this when the module loads it; a value already set is kept.
os.environ.setdefault("OMP_WAIT_POLICY", "passive")

try:
    from tumble import _engine
except ImportError as error:  # a build without pybind11 has the remote client only
    _engine = None
    _missing = error


class World(WorldCalls):
    """A world in this process. threads: the step's OpenMP threads (0: every core). max_bodies
    and limits ({"max_size": 100, ...}, the names of docs/SCENES.md "Limits") bound what it
    accepts, as tumble-server's --max-bodies and --limit do. scene: a dict, JSON text or path
    (docs/SCENES.md); builtin: a standard scene ("pile:1000"); neither: an empty world."""

    def __init__(self, scene=None, *, builtin=None, threads=0, max_bodies=100000, limits=None):
        if _engine is None:
            raise Error(grpc.StatusCode.UNIMPLEMENTED,
                        f"this build of tumble has no engine module ({_missing})", "World")
        try:
            self._engine = _engine.LocalWorld(int(threads), int(max_bodies), dict(limits or {}))
        except _engine.Refused as refusal:
            raise _error(refusal, "World") from None
        if scene is not None and builtin is not None:
            raise ArgumentError("scene and builtin: give one", "World")
        if scene is not None:
            self.load_scene(scene)
        elif builtin is not None:
            self.load_builtin(builtin)

    def step(self, n=1, timeout=None):
        """Runs n steps; returns the step reached. (timeout: accepted for the remote world's
        signature; the steps run before this returns.)"""
        if isinstance(n, bool) or not isinstance(n, int) or not 1 <= n < 2**32:
            raise ArgumentError(f"n: expected a number of steps in [1, 2^32), got {n!r}", "step")
        try:
            return self._engine.step(n)
        except _engine.Refused as refusal:
            raise _error(refusal, "step") from None

    def states(self, ids=None):
        """The states of every body (or of `ids`, in that order) as arrays (States)."""
        return States(**self._engine_call("states", _ids_or_none(ids)))

    def set_states(self, ids, positions=None, orientations=None, linear_velocities=None,
                   angular_velocities=None):
        """Sets the given arrays' rows ((N, 3) or (N, 4), w x y z) on the bodies of `ids`, all or
        nothing: a refused row (an unknown id, a value beyond the limits) changes no body."""
        self._engine_call("set_states", _ids_or_none(ids), _rows(positions),
                          _rows(orientations), _rows(linear_velocities),
                          _rows(angular_velocities))

    def apply_impulses(self, ids, impulses, points=None):
        """Impulses (N s, world) at points (m, world; default the centres of mass), one row per
        id, applied at once, all or nothing."""
        self._engine_call("apply_impulses", _ids_or_none(ids), _rows(impulses), _rows(points))

    def contacts(self):
        """Every contact point of the last step, and of the islands asleep, with its impulse
        (Contacts; as a frame's contacts)."""
        return Contacts(**self._engine_call("contacts"))

    def frames(self, rate=0.0, velocities=False, contacts=False, stats=False, ids=(), count=None,
               duration=None, joints=False):
        """Frames as the remote world streams them, one per step: each one steps the world. The
        first describes every body (Frame.added); later ones what was added and removed. Ends
        after `count` frames or `duration` seconds of wall time (default: never; break out).
        rate: accepted for the remote world's signature (every step's frame comes here)."""
        if count is not None and (isinstance(count, bool) or not isinstance(count, int)
                                  or count < 0):
            raise ArgumentError(f"count: expected an integer >= 0, got {count!r}", "frames")
        request = pb.StreamFramesRequest(velocities=bool(velocities), contacts=bool(contacts),
                                         stats=bool(stats), ids=[int(i) for i in ids],
                                         joints=bool(joints))
        reader = _engine.Reader(self._engine, request.velocities, request.contacts,
                                request.stats, list(request.ids), request.joints)
        return FrameStream(_LocalFrames(reader, duration), request, count, False, "frames")

    def close(self):
        """Nothing to close: for the remote world's signature."""

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def _rpc(self, method, request, timeout=None):
        answer = self._engine_call("call", method, request.SerializeToString())
        return getattr(pb, f"{method}Response").FromString(answer)

    def _engine_call(self, name, *args):
        try:
            return getattr(self._engine, name)(*args)
        except _engine.Refused as refusal:
            raise _error(refusal, name) from None


class _LocalFrames:
    """What FrameStream reads: the next frame's bytes, one step each."""

    def __init__(self, reader, duration):
        self._reader = reader
        self._deadline = None if duration is None else time.monotonic() + float(duration)
        self._closed = False

    def __iter__(self):
        return self

    def __next__(self):
        if self._closed or (self._deadline is not None and time.monotonic() > self._deadline):
            raise StopIteration
        try:
            return self._reader.next(True)
        except _engine.Refused as refusal:
            raise _error(refusal, "frames") from None

    def cancel(self):
        self._closed = True


def _error(refusal, call):
    code, message = refusal.args
    return Error(getattr(grpc.StatusCode, code), message, call)


def _ids_or_none(ids):
    if ids is None:
        return None
    array = np.asarray(ids)
    if array.ndim != 1 or not (array.size == 0 or np.issubdtype(array.dtype, np.integer)):
        raise ArgumentError("ids: expected a 1-D sequence of body ids")
    if array.size and array.min() < 0:
        raise ArgumentError("ids: body ids are >= 1")
    return array.astype(np.uint64)


def _rows(values):
    return None if values is None else np.asarray(values, dtype=float)
