// SPDX-License-Identifier: Apache-2.0
// The console page in headless Chromium for D seconds (no screenshots, nothing else asked of it):
// the delay from the server's frame to the page having it, as the page records it.
// Usage (bench/console.sh, bench/station.sh): node bench_console_page_delay.mjs URL_WITH_TOKEN SECONDS [START_S]   -> one JSON line
// (START_S: how long the page may take to get its first frames, default 15 s)
import { chromium } from 'playwright-core';

const [url, seconds, startS] = [process.argv[2], Number(process.argv[3]), Number(process.argv[4] || 15)];
const browser = await chromium.launch({ executablePath: process.env.CHROMIUM || '/usr/bin/chromium', args: ['--no-sandbox'] });
const page = await (await browser.newContext({ viewport: { width: 1280, height: 720 } })).newPage();
await page.goto(url);
await page.waitForFunction(() => window.viscera.framesReceived > 10, null, { timeout: startS * 1000 });
await page.evaluate(() => { window.viscera.latenciesMs.length = 0; });
await new Promise((r) => setTimeout(r, seconds * 1000));
const lat = (await page.evaluate(() => window.viscera.latenciesMs)).sort((a, b) => a - b);
await browser.close();
const q = (p) => lat[Math.min(lat.length - 1, Math.floor(p * lat.length))];
console.log(JSON.stringify({ page: 'chromium', seconds, frames: lat.length, delay_ms: { p50: q(0.5), p99: q(0.99), max: lat[lat.length - 1] } }));
