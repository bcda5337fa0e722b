// The official MCAP reader (@mcap/core, with @mcap/support's zstd and lz4) judges a file:
//   node check_mcap.mjs FILE.mcap
// Reads it twice, as a stream (every record, chunk CRCs checked) and through its index (summary,
// chunk indexes, message indexes, attachment CRCs), and prints one JSON object: header, schemas,
// channels with their message counts from both passes, statistics, attachments, metadata, whether
// log times never decrease in file order, and per channel the sequence numbers' gaps. Exits 1
// with the reader's error if either pass fails.
import { open } from "node:fs/promises";
import { McapIndexedReader, McapStreamReader } from "@mcap/core";
import { loadDecompressHandlers } from "@mcap/support";

const path = process.argv[2];
if (!path) {
  console.error("usage: node check_mcap.mjs FILE.mcap");
  process.exit(2);
}

const decompressHandlers = await loadDecompressHandlers();
const out = { file: path };

try {
  // 1. Stream: every record in file order.
  const stream = new McapStreamReader({ decompressHandlers, validateCrcs: true });
  const file = await open(path, "r");
  const streamCounts = new Map();
  const lastSeq = new Map();
  const gaps = new Map();
  let lastLogTime = -1n;
  let monotonic = true;
  let records = 0;
  const buffer = new Uint8Array(1 << 20);
  for (;;) {
    const { bytesRead } = await file.read(buffer, 0, buffer.length, null);
    if (bytesRead === 0) break;
    stream.append(buffer.slice(0, bytesRead));
    for (let r; (r = stream.nextRecord()); ) {
      ++records;
      if (r.type === "Header") out.header = { profile: r.profile, library: r.library };
      if (r.type === "Message") {
        streamCounts.set(r.channelId, (streamCounts.get(r.channelId) ?? 0) + 1);
        if (r.logTime < lastLogTime) monotonic = false;
        lastLogTime = r.logTime;
        const prev = lastSeq.get(r.channelId);
        if (prev !== undefined && r.sequence > prev + 1) gaps.set(r.channelId, (gaps.get(r.channelId) ?? 0) + (r.sequence - prev - 1));
        lastSeq.set(r.channelId, r.sequence);
      }
    }
  }
  await file.close();
  if (!stream.done()) throw new Error(`stream reader: the file ends before its footer (${stream.bytesRemaining()} bytes left unparsed)`);
  out.stream = { records, monotonicLogTimes: monotonic };

  // 2. Index: summary, chunk and message indexes.
  const handle = await open(path, "r");
  const size = BigInt((await handle.stat()).size);
  const readable = {
    size: async () => size,
    read: async (offset, length) => {
      const b = new Uint8Array(Number(length));
      const { bytesRead } = await handle.read(b, 0, b.length, Number(offset));
      if (bytesRead !== b.length) throw new Error(`short read at ${offset}`);
      return b;
    },
  };
  const reader = await McapIndexedReader.Initialize({ readable, decompressHandlers });
  const indexCounts = new Map();
  let indexed = 0;
  for await (const m of reader.readMessages({ validateCrcs: true })) {
    indexCounts.set(m.channelId, (indexCounts.get(m.channelId) ?? 0) + 1);
    ++indexed;
  }
  out.schemas = [...reader.schemasById.values()].map((s) => ({ id: s.id, name: s.name, encoding: s.encoding, bytes: s.data.length }));
  out.channels = [...reader.channelsById.values()].map((c) => ({
    id: c.id,
    topic: c.topic,
    messageEncoding: c.messageEncoding,
    schemaId: c.schemaId,
    schemaName: reader.schemasById.get(c.schemaId)?.name ?? null,
    schemaEncoding: reader.schemasById.get(c.schemaId)?.encoding ?? null,
    metadata: Object.fromEntries(c.metadata),
    streamCount: streamCounts.get(c.id) ?? 0,
    indexCount: indexCounts.get(c.id) ?? 0,
    sequenceGaps: gaps.get(c.id) ?? 0,
  }));
  const st = reader.statistics;
  out.statistics = st
    ? {
        messageCount: Number(st.messageCount),
        channelCount: st.channelCount,
        chunkCount: st.chunkCount,
        attachmentCount: st.attachmentCount,
        metadataCount: st.metadataCount,
        messageStartTime: st.messageStartTime.toString(),
        messageEndTime: st.messageEndTime.toString(),
        channelMessageCounts: Object.fromEntries([...st.channelMessageCounts].map(([k, v]) => [k, Number(v)])),
      }
    : null;
  out.indexedMessages = indexed;
  out.chunkIndexes = reader.chunkIndexes.length;
  out.attachments = [];
  for await (const a of reader.readAttachments({ validateCrcs: true })) out.attachments.push({ name: a.name, mediaType: a.mediaType, bytes: a.data.length });
  out.metadata = [];
  for await (const m of reader.readMetadata()) out.metadata.push({ name: m.name, metadata: Object.fromEntries(m.metadata) });
  await handle.close();
  console.log(JSON.stringify(out, null, 1));
} catch (e) {
  console.error(`check_mcap: ${path}: ${e.message ?? e}`);
  process.exit(1);
}
