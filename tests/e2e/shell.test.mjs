// The foundation's round trip: the release build, served from a sub-path, opens the bundled
// sample, runs a solver job in the Web Worker, draws the route, and cancels a running job.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { watchErrors, useApp, screenshot } from './harness.mjs';

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
  const upper = Number(await page.locator('#upper-bound').textContent());
  assert.ok(upper > 0, `upper bound shown (${upper})`);
  // Statistics of the shown route, recomputed from the geometry, follow the machine parameters.
  assert.equal(await page.locator('#pierces').textContent(), '16');
  assert.equal(Number((await page.locator('#idle-length').textContent()).replace(' mm', '')), upper);
  const timeBefore = await page.locator('#machine-time').textContent();
  await page.click('.machine summary');
  await page.fill('#cut-speed', '50');
  await page.dispatchEvent('#cut-speed', 'change');
  assert.notEqual(await page.locator('#machine-time').textContent(), timeBefore, 'faster cutting, shorter time');
  await screenshot(page, 'shell-route.png');

  // Second job: a long one, cancelled while it runs; the answer must come promptly.
  await page.selectOption('#solver', 'ccp');
  await page.fill('#time-limit', '60');
  await page.dispatchEvent('#time-limit', 'change');
  await page.click('#start');
  await page.waitForFunction(() => document.querySelector('#job-status')?.textContent === 'running');
  await page.waitForTimeout(500);
  const cancelAt = Date.now();
  await page.click('#stop');
  await page.waitForFunction(() => document.querySelector('#job-status')?.textContent === 'cancelled',
    null, { timeout: 5000 });
  const cancelMs = Date.now() - cancelAt;
  assert.ok(cancelMs < 1000, `cancel answered in ${cancelMs} ms`);
  await screenshot(page, 'shell-cancelled.png');
  assert.deepEqual(errors, [], 'no errors in the page');
});
