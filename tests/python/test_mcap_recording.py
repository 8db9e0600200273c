"""A recording made by the server (`tumble-server --record`) opens in MCAP's reference reader
(@mcap/core from npm, run by Debian's node: tests/mcap/check_recording.js) with every frame there,
every CRC right and its summary whole; each message decodes with the schema the file embeds, as
Foxglove decodes it; and `tumble replay` reads back the same frames."""

import base64
import json
import os
import re
import subprocess

from google.protobuf import descriptor_pb2, descriptor_pool, message_factory

import tumble
from conftest import Server

CHECK = os.path.join(os.environ["TUMBLE_SOURCE_DIR"], "tests", "mcap", "check_recording.js")
TOPICS = ("/tumble/bodies", "/tumble/frames", "/tumble/contacts", "/tumble/stats")


def message_class(schema, name):
    """The message type `name` built from a schema's FileDescriptorSet, as a generic reader does:
    nothing of Tumble's own Python package is used."""
    pool = descriptor_pool.DescriptorPool()
    for file in descriptor_pb2.FileDescriptorSet.FromString(base64.b64decode(schema["data"])).file:
        pool.Add(file)
    return message_factory.MessageFactory(pool).GetPrototype(pool.FindMessageTypeByName(name))


def test_the_servers_recording_opens_in_the_reference_mcap_reader_with_every_frame(tmp_path):
    path = tmp_path / "run.mcap"
    server = Server("--record", str(path))
    with tumble.connect(server.address) as world:
        world.step(50)
    code, log = server.stop()
    assert code == 0, log
    recorded = int(re.search(r"--record: (\d+) frames", log).group(1))
    assert recorded >= 50

    checked = subprocess.run(["node", CHECK, path], capture_output=True, text=True, timeout=120)
    assert checked.returncode == 0, checked.stderr
    found = json.loads(checked.stdout)
    assert found["done"] and found["dataSectionCrcMatches"] and found["dataSectionCrc"] != 0
    assert sorted(channel["topic"] for channel in found["channels"].values()) == sorted(TOPICS)
    by_topic = found["byTopic"]
    # Every frame, with its contacts and statistics (the server records all three); the first
    # describes every body.
    for topic in ("/tumble/frames", "/tumble/contacts", "/tumble/stats"):
        assert by_topic[topic]["count"] == recorded, topic
        assert by_topic[topic]["sequences"][-1] == 50
        assert by_topic[topic]["sequences"] == sorted(by_topic[topic]["sequences"])
    assert by_topic["/tumble/bodies"]["count"] >= 1
    stats = found["statistics"]
    assert stats["messageCount"] == sum(entry["count"] for entry in by_topic.values())
    assert stats["chunkCount"] == found["chunkIndexes"] >= 1
    assert found["streamed"]["Message"] == stats["messageCount"]

    schemas = {schema["name"]: schema for schema in found["schemas"].values()}
    assert all(schema["encoding"] == "protobuf" for schema in schemas.values())
    bodies = message_class(schemas["tumble.v1.BodyChanges"], "tumble.v1.BodyChanges").FromString(
        base64.b64decode(by_topic["/tumble/bodies"]["first"]))
    frame = message_class(schemas["tumble.v1.Frame"], "tumble.v1.Frame").FromString(
        base64.b64decode(by_topic["/tumble/frames"]["first"]))
    assert len(bodies.added) == 51 and len(frame.ids) == 51 and len(frame.positions) == 3 * 51
    assert frame.linear_velocities  # the server records velocities

    cli = os.path.join(os.environ["TUMBLE_BUILD_DIR"], "client", "tumble")
    replay = subprocess.run([cli, "replay", path], capture_output=True, text=True, timeout=60)
    assert replay.returncode == 0, replay.stderr
    lines = replay.stdout.splitlines()
    assert len(lines) == recorded
    assert json.loads(lines[-1])["step"] == 50 and "added" in json.loads(lines[0])
