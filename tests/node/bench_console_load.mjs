// SPDX-License-Identifier: Apache-2.0
// Load on viscera-console: N WebSocket clients that take everything a page gets (binary frames,
// forces, telemetry, events) for D seconds. Measures, in one run: the delay from the server's
// frame to each client (the frame header's server stamp; one host, one clock), bytes per second
// per client (the bridge's /stats), the bridge's CPU (/proc/PID/stat) and the DDS leg alone (the
// bridge's own measurement of server -> bridge).
// Usage (bench/console.sh): node bench_console_load.mjs URL_WITH_TOKEN BRIDGE_PID CLIENTS SECONDS   -> one JSON line
import WebSocket from 'ws';
import { readFileSync } from 'node:fs';

const [url, pid, nClients, seconds] = [process.argv[2], process.argv[3], Number(process.argv[4]), Number(process.argv[5])];
const wsUrl = url.replace(/^http/, 'ws').replace(/\/\?/, '/ws?');
const statsUrl = url.replace(/\/\?/, '/stats?');
const ticks = () => { const f = readFileSync(`/proc/${pid}/stat`, 'utf8').split(') ')[1].split(' '); return Number(f[11]) + Number(f[12]); };
const delays = [];
const clients = await Promise.all(Array.from({ length: nClients }, () => new Promise((resolve) => {
  const ws = new WebSocket(wsUrl);
  let first = true;
  ws.on('message', (data, binary) => {
    if (!binary || data[0] !== 2) return;
    const stamp = data.readDoubleLE(32);
    if (!first) delays.push(performance.timeOrigin + performance.now() - stamp);
    first = false;
  });
  ws.once('open', () => resolve(ws));
})));
await new Promise((r) => setTimeout(r, 1000));  // settle
delays.length = 0;
const t0 = performance.now(), c0 = ticks();
await new Promise((r) => setTimeout(r, seconds * 1000));
const cpu = (ticks() - c0) / 100 / ((performance.now() - t0) / 1000);  // USER_HZ = 100
const stats = await (await fetch(statsUrl)).json();
for (const ws of clients) ws.close();
delays.sort((a, b) => a - b);
const q = (p) => delays[Math.min(delays.length - 1, Math.floor(p * delays.length))];
const rates = stats.browsers.map((b) => b.bytes_per_s);
console.log(JSON.stringify({
  clients: nClients, seconds, frames: delays.length, delay_ms: { p50: q(0.5), p99: q(0.99), max: delays[delays.length - 1] },
  dds_leg_ms: stats.stations[0].frame_delay_ms, bridge_cpu_fraction_of_one_core: cpu,
  bytes_per_s_per_client: rates.reduce((a, b) => a + b, 0) / Math.max(1, rates.length),
  frames_skipped: stats.browsers.reduce((a, b) => a + b.frames_skipped, 0),
}));
