// SPDX-License-Identifier: Apache-2.0
// A replay judged against its original by the official MCAP reader (@mcap/core):
//   node compare_replay.mjs ORIGINAL.mcap REPLAY.mcap TOPIC...
// For each topic: whether the replay holds the original's payloads in the original's order (the
// replay may start and end inside the original's run: its payloads must be one unbroken run of
// the original's), and the pace: the original's log-time span of that run over the replay's. Prints
// one JSON object per topic: {original, replayed, firstIndex, inOrder, firstMismatch, originalSpanS,
// replaySpanS, pace}.
import { createHash } from "node:crypto";
import { loadDecompressHandlers } from "@mcap/support";
import { openIndexed } from "./indexed_reader.mjs";

const [original, replay, ...topics] = process.argv.slice(2);
if (!replay || topics.length === 0) {
  console.error("usage: node compare_replay.mjs ORIGINAL.mcap REPLAY.mcap TOPIC...");
  process.exit(2);
}
const decompressHandlers = await loadDecompressHandlers();

async function messages(path) {
  const { reader, close } = await openIndexed(path, decompressHandlers);
  const byTopic = new Map();
  for await (const m of reader.readMessages({ validateCrcs: true })) {
    const topic = reader.channelsById.get(m.channelId).topic;
    if (!byTopic.has(topic)) byTopic.set(topic, []);
    byTopic.get(topic).push({ t: m.logTime, digest: createHash("sha1").update(m.data).digest("hex") });
  }
  await close();
  return byTopic;
}

try {
  const a = await messages(original);
  const b = await messages(replay);
  const out = {};
  for (const topic of topics) {
    const orig = a.get(topic) ?? [];
    const rep = b.get(topic) ?? [];
    const first = rep.length ? orig.findIndex((m) => m.digest === rep[0].digest) : -1;
    let firstMismatch = null;
    for (let i = 0; i < rep.length && firstMismatch === null; ++i)
      if (first < 0 || first + i >= orig.length || orig[first + i].digest !== rep[i].digest) firstMismatch = i;
    const span = (list, i, j) => (list.length && j > i ? Number(list[j].t - list[i].t) * 1e-9 : 0);
    const originalSpanS = first >= 0 && rep.length ? span(orig, first, Math.min(orig.length - 1, first + rep.length - 1)) : 0;
    const replaySpanS = span(rep, 0, rep.length - 1);
    out[topic] = {
      original: orig.length,
      replayed: rep.length,
      firstIndex: first,
      inOrder: first >= 0 && firstMismatch === null,
      firstMismatch,
      originalSpanS,
      replaySpanS,
      pace: replaySpanS > 0 ? originalSpanS / replaySpanS : 0,
    };
  }
  console.log(JSON.stringify(out, null, 1));
} catch (e) {
  console.error(`compare_replay: ${e.message ?? e}`);
  process.exit(1);
}
