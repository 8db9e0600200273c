"""The README's Python example runs as printed, against a real server."""

import os
import re
import subprocess
import sys


def readme_example():
    with open(os.environ["TUMBLE_README"]) as file:
        blocks = re.findall(r"```python\n(.*?)```", file.read(), re.S)
    assert blocks, "README.md has no python example"
    return blocks[0]


def test_the_readme_example_runs_as_printed(server):
    example = readme_example()
    assert len(example.strip().splitlines()) <= 5
    assert '"127.0.0.1:50051"' in example
    run = subprocess.run([sys.executable, "-c", example.replace("127.0.0.1:50051", server.address)],
                         capture_output=True, text=True, timeout=60)
    assert run.returncode == 0, run.stderr
    lines = run.stdout.splitlines()
    assert len(lines) == 60
    # Each line: simulated time, then the box's position; the box falls.
    times = [float(line.split()[0]) for line in lines]
    heights = [float(line.rstrip("]").split()[-1]) for line in lines]
    assert times == sorted(times) and times[-1] > times[0]
    assert heights[-1] < heights[0] <= 5
