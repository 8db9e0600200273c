"""Frames read from their bytes (tumble.wire) equal what protobuf reads from the same bytes."""

import numpy as np
import pytest
from google.protobuf.message import DecodeError

from tumble.frames import Frame
from tumble.v1 import world_pb2 as pb


def made_frame(bodies, seed):
    rng = np.random.default_rng(seed)
    frame = pb.Frame(step=7, time=0.125, dropped=3, stepped_at_unix_ns=2**63 + 5)
    # Ids of every varint length, up to the largest 64-bit value.
    ids = [0, 1, 127, 128, 16383, 16384, 2**53 - 1, 2**63, 2**64 - 1]
    ids += rng.integers(0, 2**62, bodies - len(ids)).tolist()
    frame.ids.extend(ids)
    frame.positions.extend(rng.normal(size=3 * bodies) * 1e3)
    frame.orientations.extend(rng.normal(size=4 * bodies))
    frame.linear_velocities.extend(rng.normal(size=3 * bodies))
    frame.angular_velocities.extend([np.inf, -0.0, np.nan] + rng.normal(size=3 * bodies - 3).tolist())
    contacts = frame.contacts
    contacts.body_a.extend(ids[:5])
    contacts.body_b.extend(ids[5:10])
    contacts.points.extend(rng.normal(size=15))
    contacts.normals.extend(rng.normal(size=15))
    contacts.depths.extend(rng.normal(size=5))
    contacts.impulses.extend(rng.normal(size=5))
    frame.stats.pairs = 12
    frame.stats.total_seconds = 0.004
    added = frame.added.add(id=2**53 - 1, mass=2.0, color=0xFF0000FF)
    added.shape.box.size.x = 1
    frame.removed.extend([4, 2**60])
    return frame


def assert_same(ours, theirs):
    for field in ("step", "time", "dropped", "stepped_at_unix_ns", "removed", "added"):
        assert getattr(ours, field) == getattr(theirs, field), field
    for field in ("ids", "positions", "orientations", "linear_velocities", "angular_velocities"):
        np.testing.assert_array_equal(getattr(ours, field), getattr(theirs, field), field)
    for field in ("body_a", "body_b", "points", "normals", "depths", "impulses"):
        np.testing.assert_array_equal(getattr(ours.contacts, field),
                                      getattr(theirs.contacts, field), field)
    assert ours.ids.dtype == np.uint64 and ours.positions.flags.writeable
    assert ours.stats == theirs.stats


def test_every_field_reads_as_protobuf_reads_it():
    for bodies in (9, 10, 1000):
        data = made_frame(bodies, bodies).SerializeToString()
        ours = Frame.from_bytes(data, True, True, True)
        theirs = Frame.from_proto(pb.Frame.FromString(data), True, True, True)
        assert_same(ours, theirs)
        assert ours.ids[:9].tolist() == [0, 1, 127, 128, 16383, 16384, 2**53 - 1, 2**63, 2**64 - 1]


def test_fields_in_several_chunks_concatenate_as_protobuf_merges_them():
    # The server sends shared bytes followed by a subscriber's own; repeated fields may come twice.
    first, second = made_frame(9, 1), made_frame(12, 2)
    data = first.SerializeToString() + second.SerializeToString()
    ours = Frame.from_bytes(data, True, True, True)
    assert_same(ours, Frame.from_proto(pb.Frame.FromString(data), True, True, True))
    assert len(ours.ids) == 21 and len(ours.contacts) == 10


def test_unexpected_or_damaged_bytes_are_left_to_protobuf():
    data = made_frame(10, 3).SerializeToString()
    unpacked = pb.Frame(step=1)
    # Doubles one by one (wire type 1) instead of packed: legal protobuf, not what we read whole.
    raw = b"".join(b"\x21" + np.float64(v).tobytes() for v in (1.0, 2.0, 3.0))
    frame = Frame.from_bytes(unpacked.SerializeToString() + raw, False, False, False)
    np.testing.assert_array_equal(frame.positions, [[1.0, 2.0, 3.0]])
    # Cut inside a field: refused by protobuf, never read as a shorter frame.
    for cut in (1, 7, len(data) // 2):
        with pytest.raises(DecodeError):
            Frame.from_bytes(data[:-cut], True, True, True)
