"""Frames streamed by the server, as numpy arrays.

Each step's frame lists the bodies as parallel arrays: ids[i] is at positions[i] with
orientations[i] (w, x, y, z). A subscriber's first frame describes every body in `added`; later
frames list only additions and removals, which FrameStream keeps in `bodies`."""

from dataclasses import dataclass, field
from types import SimpleNamespace
from typing import Optional

import grpc
import numpy as np
from google.protobuf.message import DecodeError

from tumble import wire
from tumble.bodies import Description
from tumble.errors import Error, from_rpc
from tumble.v1 import world_pb2 as pb


@dataclass
class Contacts:
    """One entry per contact point: body_a and body_b (ids), point (m, world, on b's surface),
    normal (unit, a to b), depth (m; > 0 overlapping, < 0 a speculative gap), impulse (N s)."""

    body_a: np.ndarray
    body_b: np.ndarray
    points: np.ndarray
    normals: np.ndarray
    depths: np.ndarray
    impulses: np.ndarray

    def __len__(self):
        return len(self.depths)

    @staticmethod
    def from_bytes(data):
        chunks, _ = wire.split(data, (1, 2, 3, 4, 5, 6))
        return Contacts(
            body_a=wire.varints(chunks[1]),
            body_b=wire.varints(chunks[2]),
            points=wire.doubles(chunks[3], 3),
            normals=wire.doubles(chunks[4], 3),
            depths=wire.doubles(chunks[5]),
            impulses=wire.doubles(chunks[6]),
        )

    @staticmethod
    def from_proto(contacts):
        return Contacts(
            body_a=np.array(contacts.body_a, dtype=np.uint64),
            body_b=np.array(contacts.body_b, dtype=np.uint64),
            points=_rows(contacts.points, 3),
            normals=_rows(contacts.normals, 3),
            depths=np.array(contacts.depths, dtype=float),
            impulses=np.array(contacts.impulses, dtype=float),
        )


@dataclass
class JointStates:
    """Every joint's state at the frame's step: ids[i] has positions[i] (its free coordinate: a
    hinge's angle in rad, a slider's offset or a distance joint's length in m, a ball's twist),
    speeds[i], efforts[i] (N m or N along it) and the reaction on b, forces[i] (N) and torques[i]
    (N m), world; anchors[i] (m) and axes[i], where the joint is now."""

    ids: np.ndarray
    positions: np.ndarray
    speeds: np.ndarray
    efforts: np.ndarray
    forces: np.ndarray
    torques: np.ndarray
    anchors: np.ndarray
    axes: np.ndarray

    def __len__(self):
        return len(self.ids)

    @staticmethod
    def from_proto(joints):
        return JointStates(
            ids=np.array(joints.ids, dtype=np.uint64),
            positions=np.array(joints.positions, dtype=float),
            speeds=np.array(joints.speeds, dtype=float),
            efforts=np.array(joints.efforts, dtype=float),
            forces=_rows(joints.forces, 3),
            torques=_rows(joints.torques, 3),
            anchors=_rows(joints.anchors, 3),
            axes=_rows(joints.axes, 3),
        )


def joint_description(description):
    """A joint new to the subscriber (Frame.joints_added): its id, kind and bodies (b: 0 for the
    world) and its definition (tumble.v1.JointSpec) as it was made."""
    names = {v: k for k, v in pb.JointKind.items()}
    spec = description.spec
    return {"id": description.id, "kind": names[spec.kind].removeprefix("JOINT_KIND_").lower(),
            "a": spec.a, "b": spec.b, "spec": spec}


@dataclass
class Frame:
    step: int
    time: float  # s, simulated
    ids: np.ndarray  # (N,) uint64
    positions: np.ndarray  # (N, 3) m, centres of mass
    orientations: np.ndarray  # (N, 4) w, x, y, z
    linear_velocities: Optional[np.ndarray]  # (N, 3) m/s, when asked for
    angular_velocities: Optional[np.ndarray]  # (N, 3) rad/s, when asked for
    contacts: Optional[Contacts]  # when asked for
    stats: Optional[SimpleNamespace]  # the step's statistics (tumble.v1.StepStats), when asked for
    added: list  # Description of each body added since the previous frame (first frame: all)
    removed: list  # ids removed since the previous frame
    dropped: int  # frames this subscriber missed since its previous one (it was too slow)
    stepped_at_unix_ns: int  # when the step ended, by the server's clock
    # Only the bodies changed since the previous frame are in the arrays (frames(changes_only=
    # True)); the others are where the previous frames left them.
    changes_only: bool = False
    # When asked for (frames(joints=True)): every joint's state, the joints new to this
    # subscriber (joint_description) and the ids of those gone.
    joints: Optional[JointStates] = None
    joints_added: list = field(default_factory=list)
    joints_removed: list = field(default_factory=list)

    def index(self, body_id):
        """The row of `body_id` in this frame's arrays; KeyError if it is not in the frame."""
        if self._rows is None:
            self._rows = {int(i): row for row, i in enumerate(self.ids)}
        return self._rows[int(body_id)]

    def position(self, body_id):
        return self.positions[self.index(body_id)]

    def orientation(self, body_id):
        return self.orientations[self.index(body_id)]

    _rows: Optional[dict] = field(default=None, repr=False, compare=False)

    @staticmethod
    def from_bytes(data, velocities, contacts, stats, joints=False):
        """A frame from its wire bytes: the arrays read whole (tumble.wire), the rest by
        protobuf; anything unexpected in the bytes is left to protobuf entirely."""
        try:
            chunks, rest = wire.split(data, (3, 4, 5, 6, 7, 8))
            return Frame._assembled(
                pb.Frame.FromString(rest), stats, joints,
                ids=wire.varints(chunks[3]),
                positions=wire.doubles(chunks[4], 3),
                orientations=wire.doubles(chunks[5], 4),
                linear_velocities=wire.doubles(chunks[6], 3) if velocities else None,
                angular_velocities=wire.doubles(chunks[7], 3) if velocities else None,
                # Several chunks of one message field merge: their bytes concatenate.
                contacts=Contacts.from_bytes(b"".join(chunks[8])) if contacts else None)
        except ValueError:
            return Frame.from_proto(pb.Frame.FromString(data), velocities, contacts, stats, joints)

    @staticmethod
    def from_proto(frame, velocities, contacts, stats, joints=False):
        return Frame._assembled(
            frame, stats, joints,
            ids=np.array(frame.ids, dtype=np.uint64),
            positions=_rows(frame.positions, 3),
            orientations=_rows(frame.orientations, 4),
            linear_velocities=_rows(frame.linear_velocities, 3) if velocities else None,
            angular_velocities=_rows(frame.angular_velocities, 3) if velocities else None,
            contacts=Contacts.from_proto(frame.contacts) if contacts else None)

    @staticmethod
    def _assembled(message, stats, joints, **arrays):
        """The frame of the arrays given and of `message`'s other fields."""
        return Frame(
            joints=JointStates.from_proto(message.joints) if joints else None,
            joints_added=[joint_description(d) for d in message.joints_added],
            joints_removed=list(message.joints_removed),
            step=message.step,
            time=message.time,
            stats=plain(message.stats) if stats else None,
            added=[Description.from_proto(d) for d in message.added],
            removed=list(message.removed),
            dropped=message.dropped,
            stepped_at_unix_ns=message.stepped_at_unix_ns,
            changes_only=message.changes_only,
            **arrays,
        )


class FrameStream:
    """Frames of one subscription, in order; iterate over it. Closing it (or leaving a `with`
    block, or dropping the last reference) cancels the subscription on the server.

    `bodies` maps each id seen to its Description, updated from every frame's added and removed;
    `joints`, when asked for, each joint's description (joint_description) the same way."""

    def __init__(self, call, request, count, timed, method):
        self._call = call
        self._timed = timed
        self._request = request
        self._left = count
        self._method = method
        self.bodies = {}
        self.joints = {}

    def __iter__(self):
        return self

    def __next__(self):
        if self._left is not None and self._left <= 0:
            self.close()
            raise StopIteration
        try:
            message = next(self._call)
        except grpc.RpcError as error:
            # Closed by us, or the duration asked for is over: the end, not a failure.
            if error.code() == grpc.StatusCode.CANCELLED or (
                    self._timed and error.code() == grpc.StatusCode.DEADLINE_EXCEEDED):
                raise StopIteration from None
            raise from_rpc(error, self._method) from None
        if self._left is not None:
            self._left -= 1
        request = self._request
        try:
            frame = Frame.from_bytes(message, request.velocities, request.contacts, request.stats,
                                     request.joints)
        except DecodeError as error:
            raise Error(grpc.StatusCode.DATA_LOSS, f"a frame could not be read: {error}",
                        self._method) from None
        for description in frame.added:
            self.bodies[description.id] = description
        for body_id in frame.removed:
            self.bodies.pop(body_id, None)
        for description in frame.joints_added:
            self.joints[description["id"]] = description
        for joint_id in frame.joints_removed:
            self.joints.pop(joint_id, None)
        return frame

    def close(self):
        """Cancels the subscription; the iteration ends."""
        self._call.cancel()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def __del__(self):
        call = getattr(self, "_call", None)
        if call is not None:
            call.cancel()


def _rows(values, width):
    return np.array(values, dtype=float).reshape(-1, width)


def plain(message):
    """A flat protobuf message as attributes (stats.pairs, stats.solve_seconds, ...)."""
    return SimpleNamespace(**{f.name: getattr(message, f.name) for f in message.DESCRIPTOR.fields})
