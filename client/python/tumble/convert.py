"""Python values to and from the wire's messages. Shape checks only (three numbers, not two);
the values themselves are judged by the server, whose messages name the field and the limit."""

import numbers

import numpy as np

from tumble.errors import ArgumentError


def number(value, name):
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise ArgumentError(f"{name}: expected a number, got {value!r}")
    return float(value)


def integer(value, name):
    """A whole number the wire carries as int32 (its range the server's to judge)."""
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise ArgumentError(f"{name}: expected an integer, got {value!r}")
    if not -2**31 <= value < 2**31:
        raise ArgumentError(f"{name}: {value} is out of range")
    return int(value)


def array(value, count, name):
    try:
        values = np.asarray(value, dtype=float).ravel()
    except (TypeError, ValueError):
        raise ArgumentError(f"{name}: expected {count} numbers, got {value!r}") from None
    if values.size != count:
        raise ArgumentError(f"{name}: expected {count} numbers, got {values.size}")
    return values


def set_vec3(message, value, name):
    message.x, message.y, message.z = array(value, 3, name).tolist()


def set_quat(message, value, name):
    """A quaternion given as (w, x, y, z), the identity being (1, 0, 0, 0)."""
    message.w, message.x, message.y, message.z = array(value, 4, name).tolist()


def vec3(message):
    return np.array([message.x, message.y, message.z])


def quat(message):
    return np.array([message.w, message.x, message.y, message.z])


def points(value, name):
    try:
        values = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise ArgumentError(f"{name}: expected an (N, 3) array of numbers") from None
    if values.ndim != 2 or values.shape[1] != 3:
        raise ArgumentError(f"{name}: expected an (N, 3) array, got shape {values.shape}")
    return values


def color(value, name="color"):
    """0xRRGGBBAA from an int, or from (r, g, b) or (r, g, b, a) in [0, 1]."""
    if value is None:
        return 0
    if isinstance(value, numbers.Integral) and not isinstance(value, bool):
        if not 0 <= value <= 0xFFFFFFFF:
            raise ArgumentError(f"{name}: 0x{value:x} is not a 32-bit 0xRRGGBBAA")
        return int(value)
    try:
        channels = np.asarray(value, dtype=float).ravel()
    except (TypeError, ValueError):
        channels = np.zeros(0)
    if channels.size not in (3, 4) or not np.all((channels >= 0) & (channels <= 1)):
        raise ArgumentError(f"{name}: expected 0xRRGGBBAA or 3 or 4 channels in [0, 1], got {value!r}")
    if channels.size == 3:
        channels = np.append(channels, 1.0)
    rgba = 0
    for channel in np.rint(channels * 255).astype(int):
        rgba = (rgba << 8) | int(channel)
    return rgba


def ids(values, name="ids"):
    """Body ids: a single id or an iterable of them."""
    if isinstance(values, numbers.Integral) and not isinstance(values, bool):
        values = [values]
    out = []
    for i, value in enumerate(values):
        if isinstance(value, bool) or not isinstance(value, numbers.Integral) or value < 0:
            raise ArgumentError(f"{name}[{i}]: expected a body id (an integer >= 0), got {value!r}")
        out.append(int(value))
    return out
