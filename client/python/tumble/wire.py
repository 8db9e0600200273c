"""Frames read straight from their bytes: packed arrays become numpy arrays without a Python
object per number.

protobuf's Python API hands out repeated fields one float at a time (about 3 µs a body for a
frame's poses); the wire format stores them as packed little-endian doubles and varints, which numpy
reads whole (https://protobuf.dev/programming-guides/encoding/). Only the large packed fields are
read here; the rest of the message (step, added bodies, statistics, ...) is handed to protobuf.
Repeated fields may come in several chunks, which concatenate, as the server's shared frames
do (docs/SERVICE.md, "Streams")."""

import numpy as np

_VARINT, _I64, _LEN, _I32 = 0, 1, 2, 5


def _varint(data, at):
    value, shift = 0, 0
    while True:
        if at >= len(data) or shift > 63:
            raise ValueError("truncated varint")
        byte = data[at]
        at += 1
        value |= (byte & 0x7F) << shift
        if byte < 0x80:
            return value, at
        shift += 7


def split(data, packed):
    """The chunks of the fields in `packed` (field number -> list of memoryviews) and the
    message's other fields as bytes, in their order. ValueError for anything unexpected (the
    caller then lets protobuf read the whole message)."""
    view = memoryview(data)
    chunks = {number: [] for number in packed}
    rest = []
    at = 0
    while at < len(view):
        start = at
        key, at = _varint(view, at)
        number, kind = key >> 3, key & 7
        if kind == _VARINT:
            _, at = _varint(view, at)
        elif kind == _I64:
            at += 8
        elif kind == _I32:
            at += 4
        elif kind == _LEN:
            length, at = _varint(view, at)
            at += length
        else:
            raise ValueError(f"field {number}: wire type {kind} unknown")
        if at > len(view):
            raise ValueError(f"field {number}: truncated")
        if number not in chunks:
            rest.append(view[start:at])
        elif kind == _LEN:
            chunks[number].append(view[at - length:at])
        else:
            raise ValueError(f"field {number}: not packed")
    return chunks, b"".join(rest)


def doubles(chunks, width=None):
    """Packed doubles as a writable array, (N,) or (N, width) (a copy: the message's bytes
    stay read-only and may be shared)."""
    data = b"".join(chunks)
    if len(data) % (8 * (width or 1)):
        raise ValueError(f"packed doubles: {len(data)} bytes are not rows of {width}")
    values = np.frombuffer(data, dtype="<f8").astype(float)
    return values if width is None else values.reshape(-1, width)


def varints(chunks):
    """Packed unsigned varints (uint64), decoded together."""
    data = np.frombuffer(b"".join(chunks), dtype=np.uint8)
    if data.size == 0:
        return np.zeros(0, dtype=np.uint64)
    if data[-1] >= 0x80:
        raise ValueError("packed varints: truncated")
    ends = np.flatnonzero(data < 0x80)
    starts = np.concatenate(([0], ends[:-1] + 1))
    lengths = ends - starts + 1
    if lengths.max() > 10:
        raise ValueError("packed varints: a value longer than 10 bytes")
    place = np.arange(data.size) - np.repeat(starts, lengths)
    parts = (data & 0x7F).astype(np.uint64) << (7 * place).astype(np.uint64)
    # The 7-bit groups of one value do not overlap: their sum is the value.
    return np.add.reduceat(parts, starts)
