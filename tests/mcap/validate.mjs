// Reads MCAP files with the reference reader (@mcap/core), twice: through the summary's
// indexes (McapIndexedReader) and as a stream (McapStreamReader), CRCs checked both ways.
// Prints one JSON line per file:
//   {"file":..., "messages": N, "topics": {topic: count}, "attachments": N, "metadata": N, "chunks": N}
// and exits 1 on any error, or if the two reads (or the file's own statistics) disagree.
//   node tests/mcap/validate.mjs FILE...
import { open } from "node:fs/promises";
import { McapIndexedReader, McapStreamReader } from "@mcap/core";
import { FileHandleReadable } from "@mcap/nodejs";
import { loadDecompressHandlers } from "@mcap/support";

const decompressHandlers = await loadDecompressHandlers();

function count(map, key) {
  map[key] = (map[key] ?? 0) + 1;
}

async function readIndexed(path) {
  const handle = await open(path, "r");
  try {
    const reader = await McapIndexedReader.Initialize({
      readable: new FileHandleReadable(handle),
      decompressHandlers,
    });
    const topics = {};
    let messages = 0;
    let lastTime = -1n;
    for await (const message of reader.readMessages({ validateCrcs: true })) {
      const channel = reader.channelsById.get(message.channelId);
      if (channel === undefined) throw new Error(`message on unknown channel ${message.channelId}`);
      if (message.logTime < lastTime) throw new Error("indexed read: messages out of log-time order");
      lastTime = message.logTime;
      count(topics, channel.topic);
      messages++;
    }
    let attachments = 0;
    for await (const _ of reader.readAttachments({ validateCrcs: true })) attachments++;
    let metadata = 0;
    for await (const _ of reader.readMetadata()) metadata++;
    const stats = reader.statistics;
    if (stats === undefined) throw new Error("no Statistics record in the summary");
    if (stats.messageCount !== BigInt(messages))
      throw new Error(`statistics count ${stats.messageCount} messages, the index read ${messages}`);
    if (stats.chunkCount !== reader.chunkIndexes.length)
      throw new Error(`statistics count ${stats.chunkCount} chunks, the index has ${reader.chunkIndexes.length}`);
    return { messages, topics, attachments, metadata, chunks: reader.chunkIndexes.length };
  } finally {
    await handle.close();
  }
}

async function readStreamed(path) {
  const reader = new McapStreamReader({ validateCrcs: true, decompressHandlers, includeChunks: true });
  const channels = new Map();
  const result = { messages: 0, topics: {}, attachments: 0, metadata: 0, chunks: 0 };
  const handle = await open(path, "r");
  try {
    const buffer = new Uint8Array(1 << 20);
    for (;;) {
      const { bytesRead } = await handle.read(buffer, 0, buffer.length, null);
      if (bytesRead === 0) break;
      reader.append(buffer.slice(0, bytesRead));
      for (let record; (record = reader.nextRecord()); ) {
        if (record.type === "Channel") channels.set(record.id, record);
        else if (record.type === "Message") {
          result.messages++;
          count(result.topics, channels.get(record.channelId).topic);
        } else if (record.type === "Attachment") result.attachments++;
        else if (record.type === "Metadata") result.metadata++;
        else if (record.type === "Chunk") result.chunks++;
      }
    }
  } finally {
    await handle.close();
  }
  if (!reader.done()) throw new Error("stream read: the file ended before its footer and magic");
  return result;
}

// The counts as JSON with topics in name order, so two reads compare as strings.
function canonical({ messages, topics, attachments, metadata, chunks }) {
  const sorted = Object.fromEntries(Object.entries(topics).sort(([a], [b]) => (a < b ? -1 : a > b ? 1 : 0)));
  return JSON.stringify({ messages, topics: sorted, attachments, metadata, chunks });
}

let failed = false;
for (const file of process.argv.slice(2)) {
  try {
    const indexed = canonical(await readIndexed(file));
    const streamed = canonical(await readStreamed(file));
    if (indexed !== streamed) throw new Error(`indexed and stream reads disagree: ${indexed} vs ${streamed}`);
    console.log(JSON.stringify({ file, ...JSON.parse(indexed) }));
  } catch (error) {
    console.error(`${file}: ${error instanceof Error ? error.message : String(error)}`);
    failed = true;
  }
}
process.exit(failed ? 1 : 0);
