// Offline use: after the first visit, the hosted app loads and solves with the network gone
// (web/sw.js, filled in by scripts/precache.py at the release build).
import { test } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import path from 'node:path';
import { startServer, launchBrowser, watchErrors, distDir, cli, assertRounded } from './harness.mjs';

/**
 * Every file of the release build but the service worker itself and the single-file page (the
 * same app for file://, which the hosted app never loads), as the cache names them.
 */
function buildFiles() {
  const walk = (dir) => fs.readdirSync(dir, { withFileTypes: true })
    .flatMap((e) => (e.isDirectory() ? walk(path.join(dir, e.name)) : [path.join(dir, e.name)]));
  return walk(distDir).map((f) => path.relative(distDir, f).split(path.sep).join('/')).filter((f) => f !== 'sw.js' && f !== 'cutroute.html');
}

test('after the first visit the app opens and solves with the server gone', async () => {
  const { server, baseUrl } = await startServer();
  const sockets = new Set();
  server.on('connection', (s) => { sockets.add(s); s.on('close', () => sockets.delete(s)); });
  const browser = await launchBrowser();
  try {
    const context = await browser.newContext();
    const page = await context.newPage();
    await page.goto(baseUrl);
    await page.waitForFunction(() => document.querySelector('#file-name')?.textContent.includes('E1X_6_01'), null, { timeout: 20000 });
    // The service worker is active and has cached the whole build (its install waits for that).
    const cached = await page.evaluate(async () => {
      await navigator.serviceWorker.ready;
      const name = (await caches.keys()).find((k) => k.startsWith('cutroute-'));
      const cache = await caches.open(name);
      return (await cache.keys()).map((r) => new URL(r.url).pathname);
    });
    const base = new URL(baseUrl).pathname;
    for (const file of ['', ...buildFiles()]) {
      assert.ok(cached.includes(base + file), `the offline copy holds ${base + file}`);
    }
    // The manifest names the app and its icon.
    const manifest = await page.evaluate(async () => (await fetch(document.querySelector('link[rel=manifest]').href)).json());
    assert.equal(manifest.short_name, 'cutroute');
    assert.equal(manifest.icons[0].src, 'icon.svg');

    // The network goes: the server stops and drops its connections.
    await new Promise((resolve) => { server.close(resolve); for (const s of sockets) s.destroy(); });
    const errors = watchErrors(page);
    await page.reload();
    await page.waitForFunction(() => document.querySelector('#file-name')?.textContent.includes('E1X_6_01'), null, { timeout: 20000 });
    // A sample not shown yet opens from the copy, and the solver worker runs.
    await page.selectOption('#sample', 'nested.dbs');
    await page.waitForFunction(() => document.querySelector('#file-name')?.textContent.includes('nested'), null, { timeout: 20000 });
    await page.selectOption('#solver', 'nearest');
    await page.click('#start');
    await page.waitForFunction(() => document.querySelector('#job-status')?.textContent === 'finished', null, { timeout: 30000 });
    const oracle = cli('solve', 'assets/samples/nested.dbs', '--solver', 'nearest', '--json');
    assert.equal(Number(await page.textContent('#pierces')), oracle.pierces);
    assertRounded(await page.getAttribute('#idle-length', 'data-mm'), oracle.idle_length, 3, 'idle length offline');
    assert.deepEqual(errors, []);
    await context.close();
  } finally {
    await browser.close();
    server.close();
  }
});
