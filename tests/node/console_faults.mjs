// SPDX-License-Identifier: Apache-2.0
// What the console let through before (issue 31), each checked against the running bridge:
//   1. a Foxglove session receives only the Foxglove protocol's messages (never the page's frames,
//      forces or scene, which its reference client took for garbage "time" and unknown opcodes);
//   2. a WebSocket from another site's page (its Origin) is refused, the console's own is not;
//   3. an instrument taken over while free can be handed back (it is free again), and one taken
//      over by a browser that then disconnects is handed back when it goes;
//   4. recordings that cannot be replayed (an empty file) are refused with the replayer's own error,
//      leave no zombie process and free their slot; a link out of the folder is never offered.
// Usage: node console_faults.mjs URL_WITH_TOKEN BRIDGE_PID FREE_INSTRUMENT
// Prints one JSON line; exit status 0 when every check passed.
import WebSocket from 'ws';
import { readdirSync, readFileSync } from 'node:fs';

const [url, pid, instrumentArg] = process.argv.slice(2);
const instrument = Number(instrumentArg);
const wsUrl = url.replace(/^http/, 'ws').replace(/\/\?/, '/ws?');
const host = new URL(url).host;
const checks = [];
const check = (name, ok, detail) => { checks.push({ name, ok: !!ok, detail }); console.error(`${ok ? 'PASS' : 'FAIL'} ${name}: ${detail}`); };
const sleep = (ms) => new Promise((r) => setTimeout(r, ms));
const open = (u = wsUrl, options = {}) => new Promise((resolve, reject) => {
  const ws = new WebSocket(u, options.protocols ?? [], options);
  ws.once('open', () => resolve(ws));
  ws.once('unexpected-response', (req, res) => reject(new Error(`HTTP ${res.statusCode}`)));
  ws.once('error', reject);
});
/// A page-protocol browser: its scene states, and its replies by id.
/// (Its handler is there before the handshake ends: the hello and the snapshot may come with it.)
async function page() {
  const ws = new WebSocket(wsUrl);
  const b = { ws, scene: null, replies: new Map(), send: (j) => ws.send(JSON.stringify(j)) };
  ws.on('message', (d, bin) => {
    if (bin) return;
    const j = JSON.parse(d.toString());
    if (j.type === 'scene') b.scene = j;
    if (j.id) b.replies.set(j.id, j);
  });
  await new Promise((resolve, reject) => { ws.once('open', resolve); ws.once('error', reject); });
  return b;
}
const owner = (b) => b.scene?.instruments.find((i) => i.id === instrument)?.owner;
const until = async (f, ms) => { for (let t = 0; t < ms && !f(); t += 50) await sleep(50); return f(); };

// 1. A Foxglove session that subscribes to nothing receives nothing but its protocol's own.
{
  const fox = new WebSocket(url.replace(/^http/, 'ws'), ['foxglove.websocket.v1']);
  const ops = new Map();
  let binary = 0;
  fox.on('message', (d, bin) => {
    if (bin) { binary++; return; }
    const op = JSON.parse(d.toString()).op ?? `(no op: ${d.toString().slice(0, 40)})`;
    ops.set(op, (ops.get(op) ?? 0) + 1);
  });
  await new Promise((resolve, reject) => { fox.once('open', resolve); fox.once('error', reject); });
  await sleep(2000);
  fox.close();
  const foreign = [...ops.keys()].filter((op) => !['serverInfo', 'advertise', 'status', 'removeStatus'].includes(op));
  check('a Foxglove session without subscriptions gets only its protocol\'s messages', binary === 0 && foreign.length === 0 && ops.get('serverInfo') === 1,
        `${binary} binary messages, ops ${JSON.stringify(Object.fromEntries(ops))}`);
}

// 2. Origins.
{
  let refused = '';
  try { (await open(wsUrl, { origin: 'http://evil.example' })).close(); } catch (e) { refused = e.message; }
  check('a page of another site cannot open a session', refused === 'HTTP 403', refused || 'opened');
  let own = 'opened';
  try { (await open(wsUrl, { origin: `http://${host}` })).close(); } catch (e) { own = e.message; }
  check('the console\'s own page can', own === 'opened', own);
}

// 3. Take-overs handed back.
{
  const a = await page();
  await until(() => a.scene, 3000);
  check('the instrument is free to begin with', owner(a) === 0, `owner ${owner(a)}`);
  a.send({ type: 'take_over', instrument, id: 1 });
  await until(() => a.replies.get(1), 8000);
  a.send({ type: 'hand_back', instrument, id: 2 });
  await until(() => a.replies.get(2), 8000);
  await until(() => owner(a) === 0, 3000);
  check('a free instrument taken over is handed back, free again',
        a.replies.get(1)?.ok && a.replies.get(2)?.ok && owner(a) === 0,
        `${a.replies.get(1)?.message} / ${a.replies.get(2)?.message}; owner ${owner(a)}`);
  const b = await page();
  b.send({ type: 'take_over', instrument, id: 3 });
  await until(() => b.replies.get(3), 8000);
  await until(() => owner(a) > 0, 3000);
  const held = owner(a);
  const t0 = Date.now();
  b.ws.terminate();  // the browser goes without a word
  await until(() => owner(a) === 0, 5000);
  check('an instrument taken over by a browser that disconnects is handed back when it goes', held > 0 && owner(a) === 0,
        `owner ${held} -> ${owner(a)} ${((Date.now() - t0) / 1000).toFixed(2)} s after the disconnect`);
  a.ws.close();
}

// 4. Recordings that cannot be replayed.
{
  const c = await page();
  await sleep(300);
  c.send({ type: 'recordings', id: 10 });
  await until(() => c.replies.get(10), 3000);
  const files = c.replies.get(10)?.files ?? [];
  check('a link out of the recordings folder is not offered', files.includes('empty.mcap') && !files.includes('passwd.mcap'), files.join(', '));
  c.send({ type: 'open_recording', file: 'passwd.mcap', id: 11 });
  for (let k = 0; k < 6; ++k) c.send({ type: 'open_recording', file: 'empty.mcap', id: 20 + k });
  await until(() => c.replies.has(25), 20000);
  const errors = [20, 21, 22, 23, 24, 25].map((id) => c.replies.get(id));
  check('the link is refused', c.replies.get(11)?.type === 'error' && /no recording/.test(c.replies.get(11).message), c.replies.get(11)?.message);
  check('an empty recording is refused each time with the replayer\'s own error (the slots are freed)',
        errors.every((r) => r?.type === 'error' && /empty\.mcap/.test(r.message) && /MCAP/.test(r.message) && !/replays are playing/.test(r.message)),
        errors.map((r) => r?.message).join(' | '));
  const children = readdirSync('/proc').filter((p) => /^\d+$/.test(p)).map((p) => {
    try { return readFileSync(`/proc/${p}/stat`, 'utf8'); } catch { return ''; }
  }).filter((s) => s.split(') ')[1]?.split(' ')[1] === pid);
  const zombies = children.filter((s) => s.split(') ')[1]?.startsWith('Z'));
  check('no zombie is left behind', zombies.length === 0, `${children.length} children, ${zombies.length} zombies`);
  c.ws.close();
}

console.log(JSON.stringify({ checks }));
process.exit(checks.every((c) => c.ok) ? 0 : 1);
