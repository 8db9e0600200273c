#!/usr/bin/python3
"""The Python client's cost of reading frames, beside the bare generated stub in the same run.

For piles of 100, 1000 and 10000 bodies: the time to turn one received frame (with velocities)
into numpy arrays, the client's way (tumble.wire: arrays read whole from the bytes) and the plain
way (protobuf parses, numpy copies each repeated field), medians of 200; and the frames per second
one Python subscriber receives while the world steps as fast as it can, through the client (arrays)
and through the bare stub (protobuf messages, no arrays), with the share of the world's steps
that is (reader and world share the machine, so the share is the fairer comparison). Prints a table (docs/PERFORMANCE.md,
"Python client").

    PYTHONPATH=build/python /usr/bin/python3 bench/python_frames.py build/server/tumble-server
"""

import statistics
import subprocess
import sys
import time

import tumble
from tumble.frames import Frame
from tumble.v1 import world_pb2 as pb

SECONDS = 2.0


def start(binary, scene):
    process = subprocess.Popen([binary, "--listen", "127.0.0.1:0", "--paused", "--standard", scene,
                                "--real-time-factor", "0"], stdout=subprocess.PIPE, text=True)
    line = process.stdout.readline()
    return process, line.split("listening on ")[1].split()[0]


def median_seconds(work):
    times = []
    for _ in range(200):
        started = time.perf_counter()
        work()
        times.append(time.perf_counter() - started)
    return statistics.median(times)


def decode_seconds(world):
    """Median times to make arrays of one frame's bytes: the client's way, the plain way. Of a
    step's frame (the first one also describes every body)."""
    call = world._raw_frames(pb.StreamFramesRequest(velocities=True))
    next(call)
    world.step(1)
    data = next(call)
    while pb.Frame.FromString(data).step == 0:
        data = next(call)
    call.cancel()
    ours = median_seconds(lambda: Frame.from_bytes(data, True, False, False))
    plain = median_seconds(lambda: Frame.from_proto(pb.Frame.FromString(data), True, False, False))
    return ours, plain


def frames_per_second(world, bare):
    """Frames one subscriber receives per second, and the steps the world made meanwhile."""
    step_before = world.info().step
    started = time.monotonic()
    received = 0
    if bare:
        call = world._stub.StreamFrames(pb.StreamFramesRequest(), timeout=SECONDS)
        try:
            for _ in call:
                received += 1
        except Exception:  # the deadline ends it
            pass
    else:
        for _ in world.frames(duration=SECONDS):
            received += 1
    elapsed = time.monotonic() - started
    return received / elapsed, (world.info().step - step_before) / elapsed


def main():
    binary = sys.argv[1] if len(sys.argv) > 1 else "build/server/tumble-server"
    print(f"{'bodies':>7} {'arrays µs/frame':>16} {'plain µs/frame':>15} "
          f"{'client frames/s (% of steps)':>29} {'bare stub frames/s (% of steps)':>32}")
    for bodies in (100, 1000, 10000):
        process, address = start(binary, f"pile:{bodies}")
        try:
            with tumble.connect(address) as world:
                ours, plain = decode_seconds(world)
                world.step(120)  # past the first impacts: both ways see the same world
                world.play()
                # Alternated, twice each, medians: the world and the reader share the machine.
                runs = {True: [], False: []}
                for bare_stub in (False, True, False, True):
                    runs[bare_stub].append(frames_per_second(world, bare=bare_stub))
                world.pause()
                client, client_steps = map(statistics.median, zip(*runs[False]))
                bare, bare_steps = map(statistics.median, zip(*runs[True]))
        finally:
            process.terminate()
            process.wait()
        print(f"{bodies:>7} {ours * 1e6:>16.0f} {plain * 1e6:>15.0f} "
              f"{f'{client:.0f} ({100 * client / client_steps:.0f}%)':>29} "
              f"{f'{bare:.0f} ({100 * bare / bare_steps:.0f}%)':>32}")


if __name__ == "__main__":
    main()
