// SPDX-License-Identifier: Apache-2.0
// The instructor console's page: the organ's surface live (three.js), the force over the last 30 s
// (uPlot), health, instruments, events; session requests to the bridge. window.viscera holds what
// the page has received, for people debugging it and for the browser tests.
import * as THREE from 'three';
import { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';
import uPlot from 'uplot';
import 'uplot/dist/uPlot.min.css';
import './style.css';

const state = (window.viscera = {
  connected: false, stations: [], station: '', scene: null, telemetry: null, settings: { force_limit_n: 3 },
  topologyVertices: 0, topologyGeneration: 0, topologyTriangles: 0, topologyChecksum: 0, meshId: -1, framesReceived: 0, frame: -1, maxDisplacementM: 0, latenciesMs: [],
  forcePeakN: 0, forceSummaries: 0, events: [], replies: [], errors: [], held: [], tips: {},
});

const $ = (id) => document.getElementById(id);
let socket = null, nextId = 1, framesThisConnection = 0;
const pending = new Map();

// ---- the 3D view -------------------------------------------------------------------------------
const view = $('view');
const renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
renderer.setPixelRatio(window.devicePixelRatio);
view.prepend(renderer.domElement);
const scene3 = new THREE.Scene();
scene3.background = new THREE.Color(0x15181d);
const camera = new THREE.PerspectiveCamera(40, 1, 0.001, 100);
camera.up.set(0, 0, 1);
const controls = new OrbitControls(camera, renderer.domElement);
scene3.add(new THREE.HemisphereLight(0xffffff, 0x303040, 1.6));
const sun = new THREE.DirectionalLight(0xffffff, 1.8);
sun.position.set(1, -1, 2);
scene3.add(sun);
const organMaterial = new THREE.MeshStandardMaterial({ color: 0xb5544a, roughness: 0.55, metalness: 0.0, side: THREE.DoubleSide });
let organ = null, rest = null;
const tools = new Map();  // instrument id -> { group, arrow }
let dirty = true;

function resize() {
  const w = view.clientWidth, h = view.clientHeight;
  renderer.setSize(w, h, false);
  camera.aspect = w / Math.max(1, h);
  camera.updateProjectionMatrix();
  dirty = true;
}
new ResizeObserver(resize).observe(view);
controls.addEventListener('change', () => { dirty = true; });

function fitCamera(min, max) {
  const c = new THREE.Vector3((min[0] + max[0]) / 2, (min[1] + max[1]) / 2, (min[2] + max[2]) / 2);
  const size = Math.max(max[0] - min[0], max[1] - min[1], max[2] - min[2]) || 0.2;
  controls.target.copy(c);
  camera.position.set(c.x + 0.9 * size, c.y - 1.3 * size, c.z + 0.9 * size);
  camera.near = size / 100; camera.far = size * 100;
  camera.updateProjectionMatrix();
  controls.update();
  dirty = true;
}

function onTopology(buf) {
  const dv = new DataView(buf);
  const meshId = dv.getUint32(4, true), nv = dv.getUint32(8, true), nt = dv.getUint32(12, true);
  const generation = dv.getUint32(16, true);
  rest = new Float32Array(buf, 24, 3 * nv);
  const index = new Uint32Array(buf, 24 + 12 * nv, 3 * nt);
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', new THREE.BufferAttribute(new Float32Array(rest), 3));
  geometry.setIndex(new THREE.BufferAttribute(new Uint32Array(index), 1));
  geometry.computeVertexNormals();
  if (organ) { scene3.remove(organ); organ.geometry.dispose(); }
  organ = new THREE.Mesh(geometry, organMaterial);
  scene3.add(organ);
  state.topologyVertices = nv;
  state.topologyGeneration = generation;
  state.topologyTriangles = nt;
  // Which surface the page holds, beyond its counts: a cut whose crossings all snapped to existing
  // nodes re-triangulates the surface and may keep both counts.
  let checksum = 0;
  for (let i = 0; i < index.length; i++) checksum = (Math.imul(checksum, 31) + index[i]) >>> 0;
  state.topologyChecksum = checksum;
  state.maxDisplacementM = 0;
  // A cut (the same mesh, a later generation) keeps the view; another organ is framed anew.
  if (meshId !== state.meshId) {
    geometry.computeBoundingBox();
    const b = geometry.boundingBox;
    fitCamera(b.min.toArray(), b.max.toArray());
  }
  state.meshId = meshId;
}

function onFrame(buf) {
  if (!organ) return;
  const dv = new DataView(buf);
  const nv = dv.getUint32(8, true);
  if (nv !== state.topologyVertices || dv.getUint32(12, true) !== state.topologyGeneration) return;
  const positions = new Float32Array(buf, 40, 3 * nv);
  organ.geometry.attributes.position.array.set(positions);
  organ.geometry.attributes.position.needsUpdate = true;
  organ.geometry.computeVertexNormals();
  let max = 0;
  for (let i = 0; i < 3 * nv; i += 3) {
    const dx = positions[i] - rest[i], dy = positions[i + 1] - rest[i + 1], dz = positions[i + 2] - rest[i + 2];
    max = Math.max(max, dx * dx + dy * dy + dz * dz);
  }
  state.maxDisplacementM = Math.sqrt(max);
  state.framesReceived++;
  state.frame = dv.getFloat64(16, true);
  state.simTimeS = dv.getFloat64(24, true);
  // The delay from the server's frame to the page; not for the first frame of a connection, which
  // is the bridge's copy of the newest frame, possibly old. Both stamps from the wall clock (the
  // server's is DDS time, the system's real-time clock): performance.timeOrigin + now() is the
  // page's monotonic clock, which drifts from it by seconds (it showed -1,100 ms on one host).
  const delay = Date.now() - dv.getFloat64(32, true);
  if (framesThisConnection++ > 0) state.latenciesMs.push(delay);
  if (state.latenciesMs.length > 10000) state.latenciesMs.splice(0, 5000);
  dirty = true;
}

function toolFor(id, radius, kind) {
  let t = tools.get(id);
  if (t) return t;
  const group = new THREE.Group();
  const metal = new THREE.MeshStandardMaterial({ color: kind === 'grasper' ? 0x9fb7d0 : kind === 'scalpel' ? 0xe8c07a : 0xd0d4da, metalness: 0.6, roughness: 0.35 });
  const tip = new THREE.Mesh(new THREE.SphereGeometry(radius, 24, 16), metal);
  const shaft = new THREE.Mesh(new THREE.CylinderGeometry(radius * 0.45, radius * 0.45, 0.12, 16), metal);
  shaft.rotation.x = Math.PI / 2;
  shaft.position.z = 0.06 + radius;
  group.add(tip, shaft);
  group.visible = false;
  const arrow = new THREE.ArrowHelper(new THREE.Vector3(0, 0, 1), new THREE.Vector3(), 0.01, 0xffd24a, 0.008, 0.005);
  arrow.visible = false;
  scene3.add(group, arrow);
  t = { group, arrow, force: 0 };
  tools.set(id, t);
  return t;
}

function animate() {
  requestAnimationFrame(animate);
  if (!dirty) return;
  dirty = false;
  renderer.render(scene3, camera);
}
animate();

// ---- the force plot ----------------------------------------------------------------------------
const plotData = [[], [], []];
const plot = new uPlot({
  width: 376, height: 150, legend: { show: false },
  scales: { x: { time: false }, y: { range: (u, lo, hi) => [0, Math.max(hi, state.settings.force_limit_n * 1.2)] } },
  axes: [{ stroke: '#9aa5b1', grid: { stroke: '#2f3742' }, label: 'time [s]', labelSize: 18, size: 30 },
         { stroke: '#9aa5b1', grid: { stroke: '#2f3742' }, label: 'force [N]', labelSize: 18, size: 40 }],
  series: [{ label: 't [s]' }, { label: 'peak |F| [N]', stroke: '#4aa3ff', width: 2 },
           { label: 'safe limit [N]', stroke: '#ff6b5a', width: 1.5, dash: [6, 4], points: { show: false } }],
}, plotData, $('plot'));

function onForces(m) {
  let peak = 0, t = 0;
  for (const i of m.instruments) {
    peak = Math.max(peak, i.peak_n);
    t = Math.max(t, i.t_s);
    const tool = tools.get(i.id);
    if (tool) {
      tool.force = i.peak_n;
      if (i.tip) { tool.group.position.set(...i.tip); tool.group.visible = true; state.tips[i.id] = i.tip; }
      const f = new THREE.Vector3(...i.force), len = f.length();
      if (i.contact && len > 1e-3) {
        tool.arrow.position.set(...i.contact_point);
        tool.arrow.setDirection(f.clone().normalize());
        tool.arrow.setLength(Math.min(0.08, 0.015 * len), 0.008, 0.005);  // 1.5 cm per newton
        tool.arrow.visible = true;
      } else tool.arrow.visible = false;
    }
  }
  state.forceSummaries++;
  const t0 = plotData[0].length ? plotData[0][plotData[0].length - 1] : t;
  if (t < t0 - 1) { plotData[0].length = plotData[1].length = plotData[2].length = 0; }  // a new session's clock
  plotData[0].push(t); plotData[1].push(peak); plotData[2].push(state.settings.force_limit_n);
  while (plotData[0].length && plotData[0][0] < t - 30) { plotData[0].shift(); plotData[1].shift(); plotData[2].shift(); }
  state.forcePeakN = Math.max(...plotData[1]);
  dirty = true;
}
setInterval(() => {
  if (!plotData[0].length) return;
  const t1 = plotData[0][plotData[0].length - 1];
  plot.setData([plotData[0].map((t) => t - t1), plotData[1], plotData[2]]);
  renderInstruments();
}, 100);

// ---- panels ------------------------------------------------------------------------------------
function row(k, v, cls = '') { return `<tr class="${cls}"><td>${k}</td><td>${v}</td></tr>`; }
const esc = (s) => String(s).replace(/[&<>"]/g, (c) => ({ '&': '&amp;', '<': '&lt;', '>': '&gt;', '"': '&quot;' }[c]));

function percentile(a, p) {
  if (!a.length) return NaN;
  const s = [...a].sort((x, y) => x - y);
  return s[Math.min(s.length - 1, Math.floor(p * s.length))];
}

let lastTelemetry = 0, previousMissed = null;
function onTelemetry(t) {
  const target = state.scene ? state.scene.physics_rate_hz : 1000;
  const missedNow = previousMissed === null ? 0 : t.missed_slots - previousMissed;
  previousMissed = t.missed_slots;
  state.telemetry = t;
  lastTelemetry = performance.now();
  // Behind: under 95% of the rate, or more than 1% of the slots of the last report missed.
  const behind = !state.scene?.paused && (t.physics_rate_hz < 0.95 * target || missedNow > 0.01 * target);
  const recent = state.latenciesMs.slice(-300);
  $('health').innerHTML =
    row('physics rate', `${t.physics_rate_hz.toFixed(0)} Hz of ${target.toFixed(0)}`, behind ? 'bad' : '') +
    row('step time p50 / p99', `${t.step_p50_us.toFixed(0)} / ${t.step_p99_us.toFixed(0)} µs`) +
    row('tick jitter p99', `${t.jitter_p99_us.toFixed(0)} µs`) +
    row('late ticks / missed slots', `${t.late_ticks} / ${t.missed_slots}`) +
    row('rejected messages', `${t.rejected_messages}`) +
    row('frame delay p50 / p99', recent.length ? `${percentile(recent, 0.5).toFixed(1)} / ${percentile(recent, 0.99).toFixed(1)} ms` : '–');
  warn(behind ? `The server is falling behind: ${t.physics_rate_hz.toFixed(0)} Hz of ${target.toFixed(0)}${missedNow > 0 ? `, ${missedNow} slots missed in the last second` : ''}.` : '');
}
setInterval(() => {
  if (state.connected && state.scene && performance.now() - lastTelemetry > 3000) warn('No health report from the server for 3 s: it may have stopped.');
}, 1000);

function warn(text) { const w = $('warning'); w.hidden = !text; w.textContent = text; }

// The rows are rebuilt only when an owner changes (a button under the pointer stays put); the
// force cells are updated in place.
let instrumentRows = '';
function renderInstruments() {
  if (!state.scene) return;
  const me = state.settings.client_id;
  const html = state.scene.instruments.map((i) => {
    const mine = i.owner === me && state.held.includes(i.id);
    const button = mine ? `<button data-hand-back="${i.id}" title="Give the instrument back to the trainee it was taken from">Hand back</button>`
      : `<button data-take-over="${i.id}" title="Take the instrument from its owner (no moment without one) and drive it from here">Take over</button>`;
    return `<tr><td>${i.id}</td><td>${i.kind}</td><td>${i.owner === me ? 'this console' : i.owner ? `client ${i.owner}` : '<span class="dim">free</span>'}</td>` +
      `<td data-force="${i.id}"></td><td>${button}</td></tr>`;
  }).join('');
  if (html !== instrumentRows) { $('instruments').tBodies[0].innerHTML = html; instrumentRows = html; }
  for (const cell of $('instruments').querySelectorAll('td[data-force]')) {
    const t = tools.get(Number(cell.dataset.force));
    cell.textContent = t ? `${t.force.toFixed(2)} N` : '–';
  }
  $('drive').hidden = state.held.length === 0;
  $('drive-id').textContent = state.held.join(', ');
}
$('instruments').onclick = async (e) => {
  const take = e.target.dataset.takeOver, back = e.target.dataset.handBack;
  if (take) {
    const r = await send({ type: 'take_over', instrument: Number(take) });
    if (r && r.ok && !state.held.includes(Number(take))) state.held.push(Number(take));
  } else if (back) {
    const r = await send({ type: 'hand_back', instrument: Number(back) });
    if (r && r.ok) state.held = state.held.filter((x) => x !== Number(back));
  }
  renderInstruments();
};
// Driving a taken-over instrument: steps add up and go to the bridge ten times a second.
const stepM = 0.002, pendingMove = [0, 0, 0];
function nudge(d) { for (let k = 0; k < 3; k++) pendingMove[k] += d[k] * stepM; }
setInterval(() => {
  if (!state.held.length || pendingMove.every((x) => x === 0) || !socket || socket.readyState !== WebSocket.OPEN) return;
  const delta = pendingMove.map((x) => Math.max(-0.01, Math.min(0.01, x)));
  pendingMove.fill(0);
  socket.send(JSON.stringify({ type: 'move', instrument: state.held[0], delta_m: delta }));
}, 100);
window.addEventListener('keydown', (e) => {
  if (!state.held.length || e.target.tagName === 'INPUT') return;
  const keys = { ArrowLeft: [-1, 0, 0], ArrowRight: [1, 0, 0], ArrowUp: [0, 1, 0], ArrowDown: [0, -1, 0], PageUp: [0, 0, 1], PageDown: [0, 0, -1] };
  if (keys[e.key]) { nudge(keys[e.key]); e.preventDefault(); }
});
document.querySelector('#drive .pad').onclick = (e) => { if (e.target.dataset.d) nudge(e.target.dataset.d.split(',').map(Number)); };

function onScene(s) {
  const first = !state.scene || state.scene.generation !== s.generation;
  state.scene = s;
  $('scene-name').textContent = `${s.name}: E ${s.material.youngs_modulus_pa ? (s.material.youngs_modulus_pa / 1000).toPrecision(3) + ' kPa' : 'anisotropic'}${s.material.shear_q ? `, shear Q ${s.material.shear_q}` : ''}`;
  $('scene-name').title = s.material.name;
  const badge = $('state');
  badge.textContent = s.paused ? 'paused' : 'live';
  badge.className = 'badge ' + (s.paused ? 'paused' : 'live');
  for (const i of s.instruments) toolFor(i.id, i.tip_radius_m, i.kind);
  // An instrument no longer this console's (its lease lost, a scene loaded) is no longer driven.
  state.held = state.held.filter((id) => s.instruments.some((i) => i.id === id && i.owner === state.settings.client_id));
  if (first) {
    const list = $('scene-list');
    list.innerHTML = s.available_scenes.map((n) => `<option${n === s.name ? ' selected' : ''}>${esc(n)}</option>`).join('');
    const f = $('material');
    f['youngs-modulus-pa'].value = s.material.youngs_modulus_pa || '';
    f['poisson-ratio'].value = s.material.poisson_ratio || '';
    f['shear-q'].value = s.material.shear_q || '';
    f['damping-per-s'].value = s.material.damping_per_s;
  }
  renderInstruments();
  if (s.preparing) status(`The server is preparing ${s.preparing}…`);
}

function onEvent(e) {
  state.events.push(e);
  if (state.events.length > 1000) state.events.shift();
  const li = document.createElement('li');
  const bookmark = e.kind === 'annotation' && e.text.startsWith('bookmark');
  li.className = bookmark ? 'bookmark' : e.kind === 'annotation' ? 'annotation' : e.kind === 'request_refused' ? 'refused' : '';
  const who = e.source_client_id ? `client ${e.source_client_id}` : 'server';
  // Clients' annotations carry no simulated time (the server's events do).
  li.textContent = `${e.source_client_id ? '' : `${e.sim_time_s.toFixed(2)} s  `}${bookmark ? '★ ' : ''}${e.kind.replace(/_/g, ' ')}${e.instrument_id ? ` (instrument ${e.instrument_id})` : ''}` +
    `${e.text ? ': ' + e.text : ''} — ${who}`;
  const list = $('events');
  list.append(li);
  while (list.children.length > 200) list.firstChild.remove();
  list.scrollTop = list.scrollHeight;
}

function status(text, error = false) { const s = $('status'); s.textContent = text; s.className = error ? 'error' : ''; }

// ---- the connection ----------------------------------------------------------------------------
function send(request) {
  if (!socket || socket.readyState !== WebSocket.OPEN) { status('Not connected to the console bridge.', true); return Promise.resolve(null); }
  const id = nextId++;
  socket.send(JSON.stringify({ ...request, id }));
  status(`${request.type}: sent…`);
  return new Promise((resolve) => pending.set(id, resolve));
}

function connect(delayMs = 500) {
  const token = new URLSearchParams(location.search).get('token');
  const url = `${location.protocol === 'https:' ? 'wss' : 'ws'}://${location.host}/ws${token ? `?token=${encodeURIComponent(token)}` : ''}`;
  socket = new WebSocket(url);
  socket.binaryType = 'arraybuffer';
  socket.onopen = () => { state.connected = true; framesThisConnection = 0; delayMs = 500; status('Connected.'); };
  socket.onclose = () => {
    state.connected = false;
    const badge = $('state'); badge.textContent = 'bridge lost'; badge.className = 'badge lost';
    status(`Connection to the console bridge lost; trying again in ${(delayMs / 1000).toFixed(1)} s.`, true);
    setTimeout(() => connect(Math.min(10000, delayMs * 2)), delayMs);
  };
  socket.onmessage = (msg) => {
    if (typeof msg.data !== 'string') {
      const kind = new Uint8Array(msg.data, 0, 1)[0];
      if (kind === 1) onTopology(msg.data); else if (kind === 2) onFrame(msg.data);
      return;
    }
    const m = JSON.parse(msg.data);
    switch (m.type) {
      case 'hello':
        state.stations = m.stations; state.settings = { ...state.settings, ...m.settings }; state.recordings = m.recordings;
        if (!state.station || !m.stations.includes(state.station)) state.station = m.stations[0];
        renderStations();
        if (state.station !== m.stations[0]) send({ type: 'watch', station: state.station });
        break;
      case 'stations': state.stations = m.stations; renderStations(); break;
      case 'recordings': {
        state.recordings = m.files; renderStations();
        const resolve = pending.get(m.id);
        if (resolve) { pending.delete(m.id); resolve(m); }
        status('');
        break;
      }
      case 'scene': onScene(m); break;
      case 'telemetry': onTelemetry(m); break;
      case 'forces': onForces(m); break;
      case 'event': onEvent(m); break;
      case 'reply':
      case 'error': {
        (m.type === 'reply' ? state.replies : state.errors).push(m);
        const ok = m.type === 'reply' && m.ok;
        status(`${m.request || 'request'}: ${m.message}`, !ok);
        const resolve = pending.get(m.id);
        if (resolve) { pending.delete(m.id); resolve(m); }
        break;
      }
    }
  };
}
connect();

// ---- controls ----------------------------------------------------------------------------------
$('pause').onclick = () => send({ type: 'pause' });
$('resume').onclick = () => send({ type: 'resume' });
$('reset').onclick = () => {
  if (confirm('Reset the organ? It goes back to rest and every grasper lets go.')) send({ type: 'reset' });
};
$('load').onclick = () => {
  const name = $('scene-list').value;
  if (name && confirm(`Load scene "${name}"? Every instrument is released; trainees must claim theirs again.`)) send({ type: 'load_scene', scene: name });
};
$('bookmark').onclick = () => {
  const t = state.simTimeS !== undefined ? state.simTimeS.toFixed(2) : '?';
  send({ type: 'bookmark', label: `at ${t} s` });
};
// The station menu: the stations, then the recordings that can be opened for replay.
function renderStations() {
  const recordings = state.recordings || [];
  $('station').innerHTML = state.stations.map((n) => `<option value="${esc(n)}"${n === state.station ? ' selected' : ''}>${esc(n)}</option>`).join('') +
    (recordings.length ? `<optgroup label="Open a recording for replay">${recordings.map((f) => `<option value="recording:${esc(f)}">▶ ${esc(f)}</option>`).join('')}</optgroup>` : '');
}
function clearPlot() { plotData[0].length = plotData[1].length = plotData[2].length = 0; }
$('station').onfocus = () => send({ type: 'recordings' });
$('station').onchange = async (e) => {
  const v = e.target.value;
  if (v.startsWith('recording:')) {
    const file = v.slice('recording:'.length);
    renderStations();  // back to the station watched until the replay is there
    if (!confirm(`Open a replay of ${file}? It plays as a station of its own (the live stations go on).`)) return;
    const r = await send({ type: 'open_recording', file });
    if (r && r.ok) { state.station = r.station; clearPlot(); renderStations(); }
    return;
  }
  state.station = v;
  clearPlot();
  send({ type: 'watch', station: state.station });
};
$('material').onsubmit = (e) => {
  e.preventDefault();
  const request = { type: 'material' };
  const old = state.scene ? state.scene.material : {};
  const fields = { 'youngs-modulus-pa': 'youngs_modulus_pa', 'poisson-ratio': 'poisson_ratio', 'shear-q': 'shear_q', 'damping-per-s': 'damping_per_s' };
  for (const [name, key] of Object.entries(fields)) {
    const v = e.target[name].value;
    if (v !== '' && Number(v) !== old[key]) request[name] = Number(v);
  }
  if (Object.keys(request).length === 1) { status('material: nothing changed.'); return; }
  send(request);
};
$('material-file').onsubmit = async (e) => {
  e.preventDefault();
  const file = e.target.file.files[0];
  if (!file) { status('material file: choose one first.'); return; }
  if (file.size > 12 * 1024) { status(`material file: ${file.name} is ${file.size} bytes; the console sends at most 12 KiB (viscera-control material --file takes 64 KiB)`); return; }
  send({ type: 'material', 'file-name': file.name, 'file-text': await file.text() });
};
$('annotate').onsubmit = (e) => {
  e.preventDefault();
  const text = e.target.text.value.trim();
  if (text) send({ type: 'annotate', text }).then(() => { e.target.text.value = ''; });
};
