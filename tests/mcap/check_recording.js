// Reads a Tumble recording with MCAP's reference TypeScript reader (@mcap/core, from npm; a test
// tool only) and prints what it found as one JSON object: the indexed reader's view (summary CRC,
// chunk indexes, statistics, every message through the indexes with chunk CRCs checked) and the
// stream reader's (every record in order, chunk CRCs checked), and whether the data section's CRC
// matches. Any malformed part throws, and the process fails. Usage: node check_recording.js FILE
"use strict";
const fs = require("fs");
const { McapIndexedReader, McapStreamReader } = require("@mcap/core");
const { crc32 } = require("@foxglove/crc");

async function main(path) {
  const bytes = new Uint8Array(fs.readFileSync(path));
  const readable = {
    size: async () => BigInt(bytes.length),
    read: async (offset, length) => bytes.subarray(Number(offset), Number(offset + length)),
  };
  const indexed = await McapIndexedReader.Initialize({ readable });
  const schemas = {};
  for (const [id, schema] of indexed.schemasById)
    schemas[id] = { name: schema.name, encoding: schema.encoding,
                    data: Buffer.from(schema.data).toString("base64") };
  const channels = {};
  for (const [id, channel] of indexed.channelsById)
    channels[id] = { topic: channel.topic, schemaId: channel.schemaId,
                     messageEncoding: channel.messageEncoding };
  const byTopic = {};
  for await (const message of indexed.readMessages({ validateCrcs: true })) {
    const topic = indexed.channelsById.get(message.channelId).topic;
    (byTopic[topic] ??= { count: 0, sequences: [], first: null });
    byTopic[topic].count += 1;
    byTopic[topic].sequences.push(message.sequence);
    if (byTopic[topic].first === null)
      byTopic[topic].first = Buffer.from(message.data).toString("base64");
  }

  const stream = new McapStreamReader({ validateCrcs: true });
  stream.append(bytes);
  const streamed = {};
  let record;
  let dataEndAt = null;
  let offset = 8;  // after the leading magic
  while ((record = stream.nextRecord()) !== undefined) {
    streamed[record.type] = (streamed[record.type] ?? 0) + 1;
    if (record.type === "DataEnd") dataEndAt = record;
  }
  const dataEndOffset = Number(indexed.dataEndOffset);
  const dataSectionCrcMatches = crc32(bytes.subarray(0, dataEndOffset)) === indexed.dataSectionCrc;
  const stats = indexed.statistics;
  console.log(JSON.stringify({
    done: stream.done(),
    header: indexed.header,
    schemas, channels, byTopic, streamed,
    chunkIndexes: indexed.chunkIndexes.length,
    statistics: {
      messageCount: Number(stats.messageCount),
      chunkCount: stats.chunkCount,
      channelCount: stats.channelCount,
      channelMessageCounts: Object.fromEntries(
        [...stats.channelMessageCounts].map(([id, n]) => [id, Number(n)])),
    },
    dataSectionCrc: indexed.dataSectionCrc ?? 0,
    dataSectionCrcMatches,
  }));
}

main(process.argv[2]).catch((error) => {
  console.error(`check_recording: ${error.message}`);
  process.exit(1);
});
