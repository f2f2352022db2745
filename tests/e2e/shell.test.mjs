// The foundation's round trip: the release build, served from a sub-path, opens the bundled
// sample, runs a solver job in the Web Worker, draws the route, and cancels a running job.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import path from 'node:path';
import { watchErrors, useApp, screenshot, cli, assertRounded, projectRoot } from './harness.mjs';

const app = useApp(before, after);

test('opens the default sample, solves in the worker, draws the route, cancels', async () => {
  const page = await app.browser.newPage({ viewport: { width: 1280, height: 800 } });
  const errors = watchErrors(page);
  await page.goto(app.baseUrl);

  // The default sample arrives through the worker (parsed off the UI thread).
  await page.waitForFunction(() => document.querySelector('#file-name')?.textContent.includes('E1X_6_01'),
    null, { timeout: 20000 });
  const parts = await page.locator('#nest-view path.part').count();
  assert.equal(parts, 8, 'E1X_6_01 has 8 parts besides the sheet');

  // First job: runs to its end; the route is drawn with one pierce per contour.
  await page.selectOption('#solver', 'nearest');
  await page.click('#start');
  await page.waitForFunction(() => document.querySelector('#job-status')?.textContent === 'finished',
    null, { timeout: 20000 });
  const pierces = await page.locator('#nest-view .route circle.pierce').count();
  assert.equal(pierces, 16, 'one pierce point per contour (16 contours)');
  const idle = await page.locator('#nest-view .route path.idle').getAttribute('d');
  assert.equal((idle.match(/L/g) ?? []).length, 16, 'idle path visits every pierce point');
  // The oracle: the CLI's nearest-neighbour route of the same nest (deterministic).
  const oracle = cli('solve', 'data/nests/dbs-json/E1X_6_01.dbs.json', '--solver', 'nearest', '--json');
  assertRounded(await page.locator('#upper-bound').textContent(), oracle.idle_length, 1, 'upper bound');
  // Statistics of the shown route, recomputed from the geometry, follow the machine parameters.
  assert.equal(await page.locator('#pierces').textContent(), String(oracle.pierces));
  assertRounded(await page.getAttribute('#idle-length', 'data-mm'), oracle.idle_length, 3, 'idle length');
  assertRounded(await page.getAttribute('#cut-length', 'data-mm'), oracle.cut_length, 3, 'cut length');
  assertRounded(await page.getAttribute('#machine-time', 'data-s'), oracle.time_s, 3, 'machine time');
  await page.click('.machine summary');
  await page.fill('#cut-speed', '50');
  await page.dispatchEvent('#cut-speed', 'change');
  const faster = cli('solve', 'data/nests/dbs-json/E1X_6_01.dbs.json', '--solver', 'nearest', '--json',
    '--speeds', `${oracle.machine.idle_speed},50,${oracle.machine.pierce_time}`);
  await page.waitForFunction((s) => document.querySelector('#machine-time')?.dataset.s === s,
    faster.time_s.toFixed(3), { timeout: 5000 }).catch(() => {});
  assertRounded(await page.getAttribute('#machine-time', 'data-s'), faster.time_s, 3, 'machine time at 50 mm/s');
  await screenshot(page, 'shell-route.png');

  // Second job: a long one, cancelled while it runs; the answer must come promptly.
  await page.selectOption('#solver', 'ccp');
  await page.fill('#time-limit', '60');
  await page.dispatchEvent('#time-limit', 'change');
  await page.click('#start');
  // Wait until the job has reported a route (a state, not a fixed sleep), then time Stop inside
  // the page: from the click to the status that says the worker answered.
  await page.waitForFunction(() => document.querySelector('#job-status')?.textContent === 'running'
    && Number.isFinite(Number(document.querySelector('#upper-bound')?.textContent)), null, { timeout: 20000 });
  const cancelMs = await page.evaluate(() => new Promise((resolve) => {
    const status = document.querySelector('#job-status');
    const clicked = performance.now();
    new MutationObserver((_, observer) => {
      if (status.textContent === 'cancelled') { observer.disconnect(); resolve(performance.now() - clicked); }
    }).observe(status, { childList: true, characterData: true, subtree: true });
    document.querySelector('#stop').click();
  }));
  assert.ok(cancelMs <= 200, `Stop took effect in ${cancelMs.toFixed(1)} ms (promise: 200 ms)`);
  // By the job's own cooperation: the page's safety net (a fresh worker after 150 ms) did not fire.
  assert.equal(await page.getAttribute('html', 'data-stop-fallback'), null, 'the job stopped itself');
  await screenshot(page, 'shell-cancelled.png');
  assert.deepEqual(errors, [], 'no errors in the page');
});

test('Stop reaches an exact job while it builds its model (nested.dbs at 25 mm)', async () => {
  const page = await app.browser.newPage({ viewport: { width: 1280, height: 800 } });
  const errors = watchErrors(page);
  await page.goto(app.baseUrl);
  await page.waitForFunction(() => document.querySelector('#file-name')?.textContent.includes('E1X_6_01'),
    null, { timeout: 20000 });
  await page.setInputFiles('#file-input', path.resolve(projectRoot, 'data', 'nests', 'dbs', 'nested.dbs'));
  await page.waitForFunction(() => document.querySelector('#file-name')?.textContent.includes('nested.dbs'),
    null, { timeout: 20000 });
  await page.selectOption('#solver', 'exact');
  for (const [id, value] of [['#step', '25'], ['#time-limit', '60']]) {
    await page.fill(id, value);
    await page.dispatchEvent(id, 'change');
  }
  await page.click('#start');
  // The job's first report names the build (the cost matrix is filled row by row in steps).
  await page.waitForFunction(() => document.querySelector('#job-status')?.textContent === 'running'
    && (document.querySelector('#phase')?.textContent ?? '').startsWith('building the model'), null, { timeout: 20000 });
  const cancelMs = await page.evaluate(() => new Promise((resolve) => {
    const status = document.querySelector('#job-status');
    const clicked = performance.now();
    new MutationObserver((_, observer) => {
      if (status.textContent === 'cancelled') { observer.disconnect(); resolve(performance.now() - clicked); }
    }).observe(status, { childList: true, characterData: true, subtree: true });
    document.querySelector('#stop').click();
  }));
  assert.ok(cancelMs <= 200, `Stop took effect in ${cancelMs.toFixed(1)} ms (promise: 200 ms)`);
  assert.equal(await page.getAttribute('html', 'data-stop-fallback'), null, 'the job stopped itself');
  assert.deepEqual(errors, [], 'no errors in the page');
});
