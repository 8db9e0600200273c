"""Failures of the Tumble client: one exception type, carrying the gRPC status code."""

import grpc


class Error(Exception):
    """A call the server refused or could not answer, or arguments it was never sent.

    `code` is a grpc.StatusCode (INVALID_ARGUMENT, NOT_FOUND, UNAVAILABLE, ...); `message` is the
    server's own text, which names the field at fault (e.g. "bodies[0].mass: ..."); `call` is the
    client method that failed.
    """

    def __init__(self, code, message, call=""):
        self.code = code
        self.message = message
        self.call = call
        where = f"{call}: " if call else ""
        super().__init__(f"{where}{code.name}: {message}")


class ArgumentError(Error, ValueError):
    """Arguments malformed before anything was sent (a vector of two numbers, an unknown solver).

    Also a ValueError, so that code written against Python's conventions catches it too."""

    def __init__(self, message, call=""):
        super().__init__(grpc.StatusCode.INVALID_ARGUMENT, message, call)


def from_rpc(error, call):
    """The exception for a failed gRPC call: its code and the server's message."""
    return Error(error.code(), error.details() or "(no message)", call)
