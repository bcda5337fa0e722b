// SPDX-License-Identifier: Apache-2.0
// The console over HTTPS and WSS, judged by clients that verify its certificate against the test
// CA, as a hospital's browsers and tools would (nothing here ignores a certificate error):
//   Node's TLS (OpenSSL) with the CA: the page and /stats are served, the cookie is Secure; without
//   the CA, or with another CA, the connection is refused by the client;
//   the `ws` client with the CA: the WebSocket (wss) says hello and surface frames arrive;
//   Debian's Chromium with the CA in its certificate store (certutil, in HOME/.pki/nssdb, made by
//   the calling script): the page loads over https, opens its socket over wss and shows the mesh;
//   the same Chromium without the CA refuses the page (ERR_CERT_AUTHORITY_INVALID).
// Usage: node console_tls.mjs HTTPS_URL_WITH_TOKEN CA_PEM OTHER_CA_PEM HOME_WITH_CA HOME_WITHOUT
// Prints one JSON line of results; exit status 0 when every check passed.
import https from 'node:https';
import { checkServerIdentity as tlsCheck } from 'node:tls';
import { readFileSync } from 'node:fs';
import WebSocket from 'ws';
import { chromium } from 'playwright-core';

const [url, caFile, otherCaFile, homeWithCa, homeWithout] = process.argv.slice(2);
const ca = readFileSync(caFile), otherCa = readFileSync(otherCaFile);
const checks = [];
const check = (name, ok, detail) => { checks.push({ name, ok: !!ok, detail }); console.error(`${ok ? 'PASS' : 'FAIL'} ${name}: ${detail}`); };

const get = (u, options) => new Promise((resolve) => {
  const req = https.get(u, { ...options, agent: false }, (res) => {  // a new connection each: every check makes its own handshake
    let body = '';
    const tls = res.socket.getProtocol();
    res.on('data', (d) => { body += d; });
    res.on('end', () => resolve({ status: res.statusCode, headers: res.headers, body, tls }));
  });
  req.on('error', (e) => resolve({ error: e.code || String(e) }));
  req.setTimeout(10000, () => req.destroy(new Error('timeout')));
});

// Node's OpenSSL, verifying against the test CA.
const page = await get(url, { ca });
check('the page over HTTPS, certificate verified against the test CA', page.status === 200 && /<html/i.test(page.body),
  `HTTP ${page.status ?? page.error}, ${page.tls}`);
const cookie = String(page.headers?.['set-cookie'] ?? '');
check('the token cookie is Secure and HttpOnly', /;\s*Secure/.test(cookie) && /HttpOnly/.test(cookie), cookie.replace(/=[0-9a-f]{32,}/, '=...'));
const stats = await get(url.replace('/?', '/stats?'), { ca });
let statsJson = {};
try { statsJson = JSON.parse(stats.body); } catch { /* judged below */ }
check('/stats says the console serves TLS', stats.status === 200 && statsJson.tls === true, `HTTP ${stats.status ?? stats.error}, tls ${statsJson.tls}`);
const noCa = await get(url, {});
check('refused by a client that does not trust the test CA', noCa.error === 'UNABLE_TO_VERIFY_LEAF_SIGNATURE' || noCa.error === 'SELF_SIGNED_CERT_IN_CHAIN',
  `error ${noCa.error ?? `none (HTTP ${noCa.status})`}`);
const wrongCa = await get(url, { ca: otherCa });
check('refused by a client that trusts another CA only', !!wrongCa.error && wrongCa.status === undefined, `error ${wrongCa.error}`);
const byName = await get(url.replace('127.0.0.1', 'localhost'), { ca });
check('the certificate names localhost too (subjectAltName)', byName.status === 200, `https://localhost: HTTP ${byName.status ?? byName.error}`);
// The client asked for console.elsewhere (a name the certificate does not hold), as a browser would check it.
const otherName = await get(url, { ca, checkServerIdentity: (_host, cert) => tlsCheck('console.elsewhere', cert) });
check('refused under a name the certificate does not hold', otherName.error === 'ERR_TLS_CERT_ALTNAME_INVALID', `error ${otherName.error ?? `none (HTTP ${otherName.status})`}`);

// The WebSocket over TLS, verified: hello, then the surface and its frames.
const wss = url.replace(/^https/, 'wss').replace(/\/\?/, '/ws?');
const ws = await new Promise((resolve) => {
  const r = { hello: null, binary: 0, error: null };
  const s = new WebSocket(wss, { ca });
  const done = () => { s.terminate(); resolve(r); };
  s.on('message', (data, isBinary) => {
    if (isBinary) r.binary++;
    else {
      const m = JSON.parse(data.toString());
      if (m.type === 'hello') r.hello = m;
    }
    if (r.hello && r.binary >= 5) done();
  });
  s.on('error', (e) => { r.error = e.code || String(e); done(); });
  setTimeout(done, 15000);
});
check('WSS with the test CA: hello and surface frames', ws.hello && ws.binary >= 5, `hello ${!!ws.hello}, ${ws.binary} binary messages, error ${ws.error}`);
const wsNoCa = await new Promise((resolve) => {
  const s = new WebSocket(wss, {});
  s.on('open', () => { s.terminate(); resolve('opened'); });
  s.on('error', (e) => resolve(e.code || String(e)));
});
check('WSS refused by a client that does not trust the test CA', wsNoCa !== 'opened', wsNoCa);

// Debian's Chromium, the test CA in its store (HOME/.pki/nssdb), no certificate flag at all.
const launch = (home) => chromium.launch({ executablePath: process.env.CHROMIUM || '/usr/bin/chromium', env: { ...process.env, HOME: home },
  args: ['--no-sandbox', '--use-angle=swiftshader', '--enable-unsafe-swiftshader'] });
const trusted = await launch(homeWithCa);
let browserResult = {};
try {
  const p = await (await trusted.newContext()).newPage();
  const r = await p.goto(url);
  const shown = await p.waitForFunction(() => window.viscera && window.viscera.topologyVertices > 0 && window.viscera.framesReceived > 5, null,
    { timeout: 20000, polling: 100 }).then(() => true, () => false);
  browserResult = await p.evaluate(() => ({ protocol: location.protocol, vertices: window.viscera.topologyVertices, frames: window.viscera.framesReceived }));
  const security = await p.evaluate(() => window.isSecureContext);
  check('Chromium trusting the test CA shows the live mesh over https and wss', r.status() === 200 && shown && browserResult.protocol === 'https:' && security,
    `HTTP ${r.status()}, ${browserResult.protocol}, secure context ${security}, ${browserResult.vertices} vertices, ${browserResult.frames} frames`);
} finally { await trusted.close(); }
const untrusted = await launch(homeWithout);
try {
  const p = await (await untrusted.newContext()).newPage();
  const outcome = await p.goto(url).then((r) => `HTTP ${r.status()}`, (e) => String(e.message).split('\n')[0]);
  check('Chromium without the test CA refuses the page', /ERR_CERT_AUTHORITY_INVALID/.test(outcome), outcome);
} finally { await untrusted.close(); }

const failed = checks.filter((c) => !c.ok);
console.log(JSON.stringify({ checks: checks.length, failed: failed.length, browser: browserResult }));
process.exit(failed.length === 0 ? 0 : 1);
