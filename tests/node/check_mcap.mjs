// SPDX-License-Identifier: Apache-2.0
// The official MCAP reader (@mcap/core, with @mcap/support's zstd and lz4) judges a file:
//   node check_mcap.mjs FILE.mcap
// Reads it twice, as a stream (every record, chunk CRCs checked) and through its index (summary,
// chunk indexes, message indexes, attachment CRCs), and prints one JSON object: header, schemas,
// channels with their message counts from both passes, statistics, attachments, metadata, whether
// log times never decrease in file order, and per writer the sequence numbers missing between its
// first and last. Exits 1
// with the reader's error if either pass fails.
//   node check_mcap.mjs --cut FILE.mcap
// A file cut short (a recorder killed): only the stream pass, up to where the reader stops; prints
// {"messages": N, "error": "..."}: the messages of its complete chunks.
import { open } from "node:fs/promises";
import { McapStreamReader } from "@mcap/core";
import { loadDecompressHandlers } from "@mcap/support";
import { openIndexed } from "./indexed_reader.mjs";

const cut = process.argv[2] === "--cut";
const path = process.argv[cut ? 3 : 2];
if (!path) {
  console.error("usage: node check_mcap.mjs FILE.mcap");
  process.exit(2);
}

const decompressHandlers = await loadDecompressHandlers();
// In --cut mode the reader's first error ends the stream pass (a record cut in two).
let cutError = null;
function nextRecord(stream) {
  if (!cut || cutError) return cutError ? undefined : stream.nextRecord();
  try {
    return stream.nextRecord();
  } catch (e) {
    cutError = e.message ?? String(e);
    return undefined;
  }
}
const out = { file: path };

try {
  // 1. Stream: every record in file order.
  const stream = new McapStreamReader({ decompressHandlers, validateCrcs: true });
  const file = await open(path, "r");
  const streamCounts = new Map();
  const writerOf = new Map();  // channel -> its writer (channels of one writer's keys share its numbers)
  const sequences = new Map();  // writer -> the sequence numbers seen
  let lastLogTime = -1n;
  let monotonic = true;
  let records = 0;
  const buffer = new Uint8Array(1 << 20);
  for (;;) {
    const { bytesRead } = await file.read(buffer, 0, buffer.length, null);
    if (bytesRead === 0) break;
    stream.append(buffer.slice(0, bytesRead));
    for (let r; (r = nextRecord(stream)); ) {
      ++records;
      if (r.type === "Header") out.header = { profile: r.profile, library: r.library };
      if (r.type === "Channel") writerOf.set(r.id, r.metadata.get("writer") ? `writer ${r.metadata.get("writer")}` : `channel ${r.id}`);
      if (r.type === "Message") {
        streamCounts.set(r.channelId, (streamCounts.get(r.channelId) ?? 0) + 1);
        if (r.logTime < lastLogTime) monotonic = false;
        lastLogTime = r.logTime;
        const writer = writerOf.get(r.channelId) ?? `channel ${r.channelId}`;
        if (!sequences.has(writer)) sequences.set(writer, new Set());
        sequences.get(writer).add(r.sequence);
      }
    }
  }
  await file.close();
  if (cut) {
    console.log(JSON.stringify({ messages: [...streamCounts.values()].reduce((a, b) => a + b, 0), records, complete: stream.done(), error: cutError }));
    process.exit(0);
  }
  if (!stream.done()) throw new Error(`stream reader: the file ends before its footer (${stream.bytesRemaining()} bytes left unparsed)`);
  out.stream = { records, monotonicLogTimes: monotonic };
  // Per writer: the numbers between its first and last that are not in the file.
  out.writers = Object.fromEntries(
    [...sequences].map(([w, set]) => {
      const seqs = [...set];
      const lo = seqs.reduce((a, b) => (a < b ? a : b));
      const hi = seqs.reduce((a, b) => (a > b ? a : b));
      return [w, { first: lo, last: hi, messages: set.size, missing: hi - lo + 1 - set.size }];
    }),
  );

  // 2. Index: summary, chunk and message indexes.
  const { reader, close } = await openIndexed(path, decompressHandlers);
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
  await close();
  console.log(JSON.stringify(out, null, 1));
} catch (e) {
  console.error(`check_mcap: ${path}: ${e.message ?? e}`);
  process.exit(1);
}
