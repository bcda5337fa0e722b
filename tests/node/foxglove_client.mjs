// SPDX-License-Identifier: Apache-2.0
// A live session through viscera-console's Foxglove WebSocket protocol, read by the protocol's
// reference client (@foxglove/ws-protocol) and decoded with the schemas the bridge advertises
// (flatbuffers_reflection, as Foxglove decodes FlatBuffers): it connects, sees the channels,
// subscribes, and decodes forces, the scene state and surface frames.
// Usage: node foxglove_client.mjs URL_WITH_TOKEN
// Prints one JSON line; exit status 0 when every check passed.
import foxglove from '@foxglove/ws-protocol';
import WebSocket from 'ws';
import { ByteBuffer } from 'flatbuffers';
import { Parser, Schema, Table } from 'flatbuffers_reflection';

const { FoxgloveClient } = foxglove;

const url = process.argv[2].replace(/^http/, 'ws');
const checks = [];
const check = (name, ok, detail) => { checks.push({ name, ok: !!ok, detail }); console.error(`${ok ? 'PASS' : 'FAIL'} ${name}: ${detail}`); };
const client = new FoxgloveClient({ ws: new WebSocket(url, [FoxgloveClient.SUPPORTED_SUBPROTOCOL]) });
let info = null;
const channels = new Map(), decoders = new Map(), bySubscription = new Map(), decoded = new Map(), failures = [];
client.on('serverInfo', (i) => { info = i; });
client.on('advertise', (list) => {
  for (const c of list) {
    channels.set(c.id, c);
    const schema = Schema.getRootAsSchema(new ByteBuffer(Buffer.from(c.schema, 'base64')));
    const parser = new Parser(schema);
    decoders.set(c.id, (bytes) => parser.toObject(Table.getNamedTable(new ByteBuffer(bytes), schema, c.schemaName)));
  }
  for (const topic of ['viscera_force_feedback', 'viscera_scene_state', 'viscera_mesh_frame', 'viscera_surface_topology']) {
    const c = [...channels.values()].find((x) => x.topic === topic);
    if (c) bySubscription.set(client.subscribe(c.id), c);
  }
});
client.on('message', ({ subscriptionId, data }) => {
  const c = bySubscription.get(subscriptionId);
  try {
    const o = decoders.get(c.id)(new Uint8Array(data.buffer, data.byteOffset, data.byteLength));
    if (!decoded.has(c.topic)) decoded.set(c.topic, []);
    const list = decoded.get(c.topic);
    if (list.length < 50) list.push(o);
  } catch (e) { failures.push(`${c.topic}: ${e}`); }
});
await new Promise((r) => setTimeout(r, 4000));
client.close();

check('serverInfo received', info && /viscera-console/.test(info.name), info ? info.name : 'none');
const topics = [...channels.values()].map((c) => c.topic);
check('every stream advertised with a flatbuffer schema', channels.size >= 8 && [...channels.values()].every((c) => c.encoding === 'flatbuffer' && c.schemaEncoding === 'flatbuffer' && c.schema.length > 100),
      topics.join(', '));
const forces = decoded.get('viscera_force_feedback') || [];
const f = forces[forces.length - 1];
check('forces decoded', forces.length > 10 && f && typeof f.instrument_id === 'number' && f.force, f ? JSON.stringify({ instrument_id: f.instrument_id, force: f.force }, (k, v) => (typeof v === 'bigint' ? Number(v) : v)) : 'none');
const scene = (decoded.get('viscera_scene_state') || [])[0];
check('the scene state decoded (sent at subscribe)', scene && typeof scene.scene_name === 'string' && Array.isArray(scene.instruments), scene ? `scene ${scene.scene_name}, ${scene.instruments.length} instruments` : 'none');
const frames = decoded.get('viscera_mesh_frame') || [];
const topo = (decoded.get('viscera_surface_topology') || [])[0];
const frame = frames[frames.length - 1];
const nPositions = frame ? (frame.positions?.length ?? 0) : 0;
check('surface topology and frames decoded, sizes agreeing', topo && frame && nPositions === 3 * Number(topo.vertex_count),
      `${frames.length} frames, ${nPositions / 3} vertices per frame, topology ${topo ? topo.vertex_count : '?'} vertices`);
check('nothing failed to decode', failures.length === 0, failures.slice(0, 3).join('; ') || 'none');
console.log(JSON.stringify({ checks }));
process.exit(checks.every((c) => c.ok) ? 0 : 1);
