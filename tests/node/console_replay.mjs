// SPDX-License-Identifier: Apache-2.0
// Opening a recording for replay from the console (tests/integration/console_test.sh): the bridge
// lists the recordings of its --recordings folder, starts viscera-replay in a partition of its own
// when a browser asks, and offers it as a new station that the browser then watches: the
// recorded scene and frames arrive from it, and pausing it stops its frames. Also the refusals:
// a name with a path, a file that is not there.
// Usage: node console_replay.mjs URL_WITH_TOKEN RECORDING_NAME   -> one JSON line; exit 0 when every check passed
import WebSocket from 'ws';

const [url, file] = process.argv.slice(2);
const checks = [];
const check = (name, ok, detail) => { checks.push({ name, ok: !!ok, detail }); console.error(`${ok ? 'PASS' : 'FAIL'} ${name}: ${detail}`); };
const sleep = (ms) => new Promise((r) => setTimeout(r, ms));
const ws = new WebSocket(url.replace(/^http/, 'ws').replace(/\/\?/, '/ws?'));
let hello = null, stations = null, frames = 0, scene = null;
const replies = new Map();
ws.on('message', (d, bin) => {
  if (bin) { if (d[0] === 2) frames++; return; }
  const j = JSON.parse(d.toString());
  if (j.type === 'hello') hello = j;
  if (j.type === 'stations') stations = j.stations;
  if (j.type === 'scene') scene = j;
  if (j.id) replies.set(j.id, j);
});
await new Promise((r) => ws.once('open', r));
await sleep(500);
check('the recordings are listed', hello && hello.recordings.includes(file), hello ? hello.recordings.join(', ') : 'no hello');
ws.send(JSON.stringify({ type: 'open_recording', file: '../secret.mcap', id: 1 }));
ws.send(JSON.stringify({ type: 'open_recording', file: 'absent.mcap', id: 2 }));
ws.send(JSON.stringify({ type: 'open_recording', file, id: 3 }));
await sleep(4000);
check('a path is refused', replies.get(1)?.type === 'error' && /not a recording's name/.test(replies.get(1).message), replies.get(1)?.message);
check('a missing file is refused', replies.get(2)?.type === 'error' && /no recording 'absent.mcap'/.test(replies.get(2).message), replies.get(2)?.message);
const opened = replies.get(3);
check('the replay opens as a new station', opened?.ok && stations && stations.includes(opened.station), `${opened?.message}; stations: ${stations}`);
const f0 = frames;
await sleep(2000);
const rate = (frames - f0) / 2;
check('the replay\'s frames and scene arrive', rate > 20 && scene && scene.station === opened?.station, `${rate.toFixed(0)} frames/s, scene ${scene?.name} from station ${scene?.station}`);
ws.send(JSON.stringify({ type: 'pause', id: 4 }));
await sleep(1500);
const f1 = frames;
await sleep(1000);
check('pausing the replay stops its frames', replies.get(4)?.ok && frames - f1 === 0, `${replies.get(4)?.message}; ${frames - f1} frames in 1 s after`);
ws.close();
console.log(JSON.stringify({ checks }));
process.exit(checks.every((c) => c.ok) ? 0 : 1);
