#!/usr/bin/python3
"""Batches of states in Python: the engine in the process (tumble.World) against a server's world
(tumble.connect) in the same run, and the batch calls against a Python loop per body.

For piles of 1000 and 10000 bodies, medians of 20 calls: states() of every body, set_states() of
every body's position, and (local) the same with a loop of set_state calls; and one step of the
pile awake, local step(1) beside the server's Control step (the same engine: the difference is the
call's own cost). Prints a table (docs/PERFORMANCE.md, "Python: batches of states").

    PYTHONPATH=build/python /usr/bin/python3 bench/python_states.py build/server/tumble-server
"""

import statistics
import subprocess
import sys
import time

import tumble

REPEATS = 20


def median_ms(work, repeats=REPEATS):
    times = []
    for _ in range(repeats):
        started = time.perf_counter()
        work()
        times.append(time.perf_counter() - started)
    return 1e3 * statistics.median(times)


def start(binary, scene):
    process = subprocess.Popen([binary, "--listen", "127.0.0.1:0", "--paused", "--standard", scene,
                                "--real-time-factor", "0"], stdout=subprocess.PIPE, text=True)
    line = process.stdout.readline()
    return process, line.split("listening on ")[1].split()[0]


def measure(world, loop):
    world.settings(sleeping=False)
    states = world.states()
    ids, positions = states.ids[1:], states.positions[1:]  # the dynamic bodies
    row = {
        "states": median_ms(world.states),
        "set_states": median_ms(lambda: world.set_states(ids, positions=positions)),
        "step": median_ms(lambda: world.step(1), repeats=10),
    }
    if loop:
        row["loop"] = median_ms(lambda: [world.set_state(int(i), position=p)
                                         for i, p in zip(ids, positions)], repeats=3)
    return row


def main(binary):
    print("Python: batches of states (ms, medians; local = tumble.World, remote = a server on "
          "loopback)")
    print(f"{'bodies':>7} {'world':>7} {'states()':>9} {'set_states()':>13} "
          f"{'set_state loop':>15} {'step(1)':>8}")
    for n in (1000, 10000):
        local = measure(tumble.World(builtin=f"pile:{n}"), loop=True)
        process, address = start(binary, f"pile:{n}")
        try:
            with tumble.connect(address) as world:
                remote = measure(world, loop=False)
        finally:
            process.terminate()
            process.wait()
        for name, row in (("local", local), ("remote", remote)):
            loop = f"{row['loop']:15.2f}" if "loop" in row else f"{'-':>15}"
            print(f"{n:7d} {name:>7} {row['states']:9.3f} {row['set_states']:13.3f} {loop} "
                  f"{row['step']:8.2f}")


if __name__ == "__main__":
    main(sys.argv[1])
