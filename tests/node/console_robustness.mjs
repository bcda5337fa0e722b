// SPDX-License-Identifier: Apache-2.0
// The console bridge under browsers that misbehave (tests/integration/console_test.sh starts the
// bridge beside a server whose surface frames run at 60 Hz). One well-behaved browser watches
// throughout; it must keep receiving frames while
//   1. a slow browser reads nothing for 10 s (the bridge's memory stays bounded, its outbox for the
//      slow one within the budget, frames for it replaced rather than piled up);
//   2. malformed requests (not JSON, unknown types and fields, values out of range, binary) each
//      get an error frame and are counted;
//   3. an oversized message closes that connection (counted);
//   4. a flood of requests is answered with rate-limit errors and then closed (counted);
//   5. a handshake without the token is refused.
// Usage: node console_robustness.mjs URL_WITH_TOKEN BRIDGE_PID
// Prints one JSON line of measurements; exit status 0 when every check passed.
import WebSocket from 'ws';
import { readFileSync } from 'node:fs';

const [url, pid] = process.argv.slice(2);
const wsUrl = url.replace(/^http/, 'ws').replace(/\/\?/, '/ws?');
const statsUrl = url.replace(/\/\?/, '/stats?');
const checks = [];
const check = (name, ok, detail) => { checks.push({ name, ok: !!ok, detail }); console.error(`${ok ? 'PASS' : 'FAIL'} ${name}: ${detail}`); };
const sleep = (ms) => new Promise((r) => setTimeout(r, ms));
const rssKiB = () => Number(/VmRSS:\s+(\d+)/.exec(readFileSync(`/proc/${pid}/status`, 'utf8'))[1]);
const stats = async () => (await fetch(statsUrl)).json();
const open = (u = wsUrl) => new Promise((resolve, reject) => {
  const ws = new WebSocket(u, { maxPayload: 64 << 20 });
  ws.once('open', () => resolve(ws));
  ws.once('unexpected-response', (req, res) => reject(new Error(`HTTP ${res.statusCode}`)));
  ws.once('error', reject);
});

// The well-behaved browser: counts frames per second.
const watcher = await open();
let frames = 0;
watcher.on('message', (data, binary) => { if (binary && data[0] === 2) frames++; });
async function frameRate(ms) { const f0 = frames; await sleep(ms); return (frames - f0) / (ms / 1000); }
const baseline = await frameRate(2000);
check('the watching browser gets frames', baseline > 20, `${baseline.toFixed(1)} frames/s before anything else`);

// 1. A slow browser: connected, reading nothing for 10 s.
const rss0 = rssKiB();
const slow = await open();
slow._socket.pause();
const during = await frameRate(10000);
const s1 = await stats();
const slowStats = s1.browsers.reduce((a, b) => (b.frames_skipped > a.frames_skipped ? b : a), { frames_skipped: -1 });
const rss1 = rssKiB();
check('others keep being served while a browser reads nothing for 10 s', during > 0.8 * baseline, `${during.toFixed(1)} frames/s (before: ${baseline.toFixed(1)})`);
check('the slow browser\'s frames are replaced, not piled up', slowStats.frames_skipped > 100 && slowStats.queued_bytes <= 4 << 20,
      `${slowStats.frames_skipped} frames replaced, ${slowStats.queued_bytes} bytes waiting (budget ${4 << 20})`);
check('the bridge\'s memory stays bounded', rss1 - rss0 < 32 * 1024, `RSS ${rss0} -> ${rss1} KiB`);
slow._socket.resume();
slow.terminate();

// 2. Malformed requests: each answered with an error.
const rude = await open();
const errors = [];
rude.on('message', (data, binary) => { if (!binary) { const j = JSON.parse(data.toString()); if (j.type === 'error') errors.push(j.message); } });
const before = (await stats()).malformed_requests;
const bad = ['not json', '[1,2]', '{"type":"nuke"}', '{"type":"pause","extra":1}', '{"type":"material","youngs-modulus-pa":"soft"}',
             '{"type":"material","poisson-ratio":0.7}', '{"type":"load_scene","scene":"../../etc/passwd"}', '{"type":"annotate","text":""}'];
for (const m of bad) rude.send(m);
rude.send(Buffer.from([1, 2, 3]), { binary: true });
await sleep(1000);
const malformed = (await stats()).malformed_requests - before;
check('every malformed request gets an error frame', errors.length === bad.length + 1, `${errors.length} errors for ${bad.length + 1} messages: ${errors.slice(0, 9).join(' | ')}`);
check('malformed requests are counted', malformed === bad.length + 1, `${malformed} counted`);

// 3. An oversized message closes that connection.
const big = await open();
const closed = new Promise((resolve) => big.once('close', (code) => resolve(code)));
big.send('x'.repeat(100 * 1024));
const code = await Promise.race([closed, sleep(5000).then(() => 'still open')]);
check('an oversized message closes the connection', code === 1009, `close code ${code}`);
const s3 = await stats();
check('the oversized close is counted', s3.closed_oversized >= 1, `closed_oversized ${s3.closed_oversized}`);

// 4. A flood: rate-limit errors, then closed.
const flooder = await open();
let limited = 0;
flooder.on('message', (data, binary) => { if (!binary && /rate limit/.test(data.toString())) limited++; });
const floodClosed = new Promise((resolve) => flooder.once('close', () => resolve(true)));
const f0 = frames;
const t0 = Date.now();
for (let i = 0; i < 2000 && flooder.readyState === WebSocket.OPEN; i++) { flooder.send('{"type":"watch","station":"default"}'); if (i % 100 === 0) await sleep(10); }
const wasClosed = await Promise.race([floodClosed, sleep(5000).then(() => false)]);
const floodRate = (frames - f0) / ((Date.now() - t0) / 1000);
const s4 = await stats();
check('a flood is rate limited, then closed', limited > 0 && wasClosed && s4.closed_flood >= 1, `${limited} rate-limit errors received, closed: ${wasClosed}, ${s4.rate_limited_requests} refused in all`);
check('the watching browser is unaffected by the flood', floodRate > 0.8 * baseline, `${floodRate.toFixed(1)} frames/s during it`);

// 5. No token, no WebSocket.
const refused = await open(wsUrl.replace(/token=[^&]*/, 'token=wrong')).then(() => 'opened', (e) => e.message);
check('a handshake with a wrong token is refused', refused === 'HTTP 401', refused);

const after = await frameRate(2000);
check('the watching browser still gets frames at the end', after > 0.8 * baseline, `${after.toFixed(1)} frames/s`);
watcher.close(); rude.close();
console.log(JSON.stringify({ checks, baseline_fps: baseline, slow_fps: during, flood_fps: floodRate, rss_kib: [rss0, rss1] }));
process.exit(checks.every((c) => c.ok) ? 0 : 1);
