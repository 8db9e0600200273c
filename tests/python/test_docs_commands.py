"""The commands the README and docs/ print run as printed: every program they name exists, takes
every option they give it, and the examples with a printed answer give that answer. (The Python
example has its own test, test_python_readme; `make` targets and containers are run by CI and
`make test-container`.)"""

import glob
import os
import re
import shlex
import subprocess

SOURCE = os.environ["TUMBLE_SOURCE_DIR"]
BUILD = os.environ["TUMBLE_BUILD_DIR"]

# Where each program the docs name is built.
PROGRAMS = {
    "tumble": "client/tumble",
    "tumble-server": "server/tumble-server",
    "tumble-run": "apps/tumble-run",
    "tumble-viewer": "viewer/tumble-viewer",
    "tumble-dds-echo": "client/tumble-dds-echo",
}


def documents():
    return [os.path.join(SOURCE, "README.md")] + sorted(glob.glob(os.path.join(SOURCE, "docs/*.md")))


def command_lines():
    """(document, command) for each line of a code block, and each inline `...` span, that runs
    one of our programs."""
    found = []
    names = "|".join(re.escape(name) for name in sorted(PROGRAMS, key=len, reverse=True))
    program = re.compile(rf"^(?:\$ )?(?:[A-Z_]+=\S+ )*(?:build/\w+/)?({names})(?:\s|$)")
    for path in documents():
        text = open(path).read()
        spans = [line for block in re.findall(r"```[a-z]*\n(.*?)```", text, re.S)
                 for line in block.splitlines()]
        spans += re.findall(r"`([^`\n]+)`", re.sub(r"```.*?```", "", text, flags=re.S))
        # The CLI's tables: a row's first span starting with one of tumble's commands.
        commands = tumble_commands()
        for row in re.findall(r"^\| `([^`]+)`", text, re.M):
            if row.split()[0] in commands:
                spans.append("tumble " + row)
        for span in spans:
            span = span.split("#")[0].strip()
            match = program.match(span)
            if match:
                found.append((os.path.basename(path), match.group(1), span))
    return found


def tumble_commands():
    text = help_text("tumble")
    listed = text[text.index("Subcommands:"):]
    return set(re.findall(r"^  (\S+)", listed, re.M))


def options_of(span):
    """The long options a command line gives (as printed: `[--frames 60]`, `--limit a=b`)."""
    return sorted(set(re.findall(r"(?<![\w-])(--[a-z][a-z0-9-]*)", span)))


def subcommand_of(span):
    words = shlex.split(re.sub(r"[\[\]|]", " ", span.split("&")[0]))
    words = [w for w in words if not re.match(r"^[A-Z_]+=", w) and w != "$"]
    # tumble [--server X] [--token T] [--tls-ca F] COMMAND ...
    i = 1
    while i < len(words) and words[i].startswith("--"):
        i += 2 if "=" not in words[i] else 1
    word = words[i] if i < len(words) else ""
    # COMMAND and the like are placeholders, not commands.
    return word if word and not word.startswith("-") and not word.isupper() else None


def help_text(program, subcommand=None):
    binary = os.path.join(BUILD, PROGRAMS[program])
    assert os.access(binary, os.X_OK), f"{binary} is not built"
    command = [binary] + ([subcommand] if subcommand else []) + ["--help"]
    run = subprocess.run(command, capture_output=True, text=True, timeout=30)
    assert run.returncode == 0, f"{' '.join(command)}: {run.stdout}{run.stderr}"
    return run.stdout


def test_every_documented_command_names_options_its_program_has():
    lines = command_lines()
    assert len(lines) > 20, lines  # the extraction finds the docs' commands
    checked = 0
    for document, program, span in lines:
        if program != "tumble" and not os.path.exists(os.path.join(BUILD, PROGRAMS[program])):
            continue  # a build without Cyclone DDS, or without the viewer
        subcommand = subcommand_of(span) if program == "tumble" else None
        text = help_text(program) if subcommand is None else help_text(program) + help_text(
            program, subcommand)
        for option in options_of(span):
            assert re.search(rf"(?<![\w-]){re.escape(option)}(?![\w-])", text), \
                f"{document}: `{span}`: {program} {subcommand or ''} has no {option}"
        checked += 1
    assert checked > 20


def test_the_scene_error_example_prints_as_documented(tmp_path):
    text = open(os.path.join(SOURCE, "docs/SCENES.md")).read()
    command, answer = re.search(r"```\n\$ (build/apps/tumble-run --scene bad.json)\n(.*?)\n```",
                                text).groups()
    (tmp_path / "bad.json").write_text(
        '{"bodies": [{"shape": "plane"}, {"shape": "plane"}, {"shape": "plane"},'
        ' {"shape": "box", "size": [1, 0, 1]}]}')
    run = subprocess.run(shlex.split(command.replace("build/", BUILD + "/", 1)), cwd=tmp_path,
                         capture_output=True, text=True, timeout=30)
    assert run.returncode == 2
    assert run.stderr.strip() == answer
