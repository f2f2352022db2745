// Opening local files (picker), errors in plain words, and the hand-written pan/zoom.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { watchErrors, projectRoot, useApp, screenshot, cli, assertRounded } from './harness.mjs';

const shared = path.resolve(projectRoot, 'data', 'nests');
const app = useApp(before, after);

async function fileShown(page, name) {
  await page.waitForFunction((n) => document.querySelector('#file-name')?.textContent.includes(n),
    name, { timeout: 20000 });
}

test('opens DBS, DXF and T-FLEX files from the picker; a broken file shows a located error', async () => {
  const page = await app.browser.newPage({ viewport: { width: 1024, height: 700 } });
  const errors = watchErrors(page);
  await page.goto(app.baseUrl);
  await fileShown(page, 'E1X_6_01');

  for (const [file, parts] of [['dbs/nested.dbs', 56], ['dxf/propeller.dxf', 1], ['tflex/Nest02.tfnesting', 406]]) {
    const full = path.join(shared, file);
    assert.ok(fs.existsSync(full), `missing test file ${full}`);
    await page.setInputFiles('#file-input', full);
    await fileShown(page, path.basename(file));
    assert.equal(await page.locator('#nest-view path.part').count(), parts, file);
  }

  const broken = path.join(os.tmpdir(), `broken-${process.pid}.dbs`);
  fs.writeFileSync(broken, fs.readFileSync(path.join(shared, 'dbs/nested.dbs')).subarray(0, 777));
  await page.setInputFiles('#file-input', broken);
  const alert = page.locator('.error[role=alert]');
  await alert.waitFor({ timeout: 10000 });
  const message = await alert.textContent();
  assert.match(message, /broken-\d+\.dbs/);
  assert.match(message, /DBS/);
  // Still usable: the previous nest stays, and a solver runs on it.
  await page.selectOption('#solver', 'nearest');
  await page.click('#start');
  await page.waitForFunction(() => document.querySelector('#job-status')?.textContent === 'finished',
    null, { timeout: 20000 });
  await screenshot(page, 'open-error.png');
  assert.deepEqual(errors, []);
});

test('wheel zooms around the cursor, drag pans, 0 fits again', async () => {
  const page = await app.browser.newPage({ viewport: { width: 1280, height: 800 } });
  await page.goto(app.baseUrl);
  await fileShown(page, 'E1X_6_01');
  const view = page.locator('#nest-view');
  const box = async () => (await view.getAttribute('viewBox')).split(' ').map(Number);
  const fitted = await box();
  const rect = await view.boundingBox();
  // A whole pixel near the middle (mouse events carry whole-pixel client coordinates).
  const [px, py] = [Math.round(rect.x + rect.width / 2), Math.round(rect.y + rect.height / 2)];
  await page.mouse.move(px, py);
  await page.mouse.wheel(0, -400);
  await page.waitForFunction((w) => Number(document.querySelector('#nest-view').getAttribute('viewBox').split(' ')[2]) < w,
    fitted[2]);
  const zoomed = await box();
  // The wheel zooms by exp(0.0015 per pixel of deltaY) about the drawing point under the
  // cursor (src/pan_zoom.rs); at the view's centre that is the view box's centre.
  const close = (a, b, what) => assert.ok(Math.abs(a - b) <= 1e-6 * Math.max(1, Math.abs(b)), `${what}: ${a} vs ${b}`);
  close(zoomed[2], fitted[2] * Math.exp(-400 * 0.0015), 'wheel zoom width');
  close(zoomed[3], fitted[3] * Math.exp(-400 * 0.0015), 'wheel zoom height');
  // The view-box point under the cursor stays under it (the box is fitted into the element,
  // centred: preserveAspectRatio "xMidYMid meet").
  const under = ([x, y, w, h]) => {
    const scale = Math.min(rect.width / w, rect.height / h);
    return [x + (px - rect.x - (rect.width - w * scale) / 2) / scale, y + (py - rect.y - (rect.height - h * scale) / 2) / scale];
  };
  close(under(zoomed)[0], under(fitted)[0], 'zoomed about the cursor (x)');
  close(under(zoomed)[1], under(fitted)[1], 'zoomed about the cursor (y)');

  await page.mouse.down();
  await page.mouse.move(px + 100, py + 50, { steps: 5 });
  await page.mouse.up();
  const panned = await box();
  // The drawing follows the pointer: 100 px right and 50 px down, at the view's scale (the
  // view box is fitted into the element, preserveAspectRatio "meet").
  const pixelsPerUnit = Math.min(rect.width / zoomed[2], rect.height / zoomed[3]);
  close(panned[0], zoomed[0] - 100 / pixelsPerUnit, 'dragging right moves the view left');
  close(panned[1], zoomed[1] - 50 / pixelsPerUnit, 'dragging down moves the view up');
  assert.equal(panned[2], zoomed[2], 'panning keeps the zoom');

  await view.focus();
  await page.keyboard.press('0');
  assert.deepEqual(await box(), fitted, '0 fits the sheet again');
  await page.keyboard.press('+');
  const keyed = await box();
  close(keyed[2], fitted[2] / 1.25, '+ zooms in by 1.25');
  close(keyed[0] + keyed[2] / 2, fitted[0] + fitted[2] / 2, '+ zooms about the centre');
});

test('the theme switch restyles the page and survives a reload', async () => {
  const page = await app.browser.newPage({ viewport: { width: 1024, height: 700 } });
  await page.goto(app.baseUrl);
  await fileShown(page, 'E1X_6_01');
  const background = () => page.evaluate(() => getComputedStyle(document.body).backgroundColor);
  const light = await background();
  await page.selectOption('#theme', 'dark');
  assert.equal(await page.evaluate(() => document.documentElement.dataset.theme), 'dark');
  const dark = await background();
  assert.notEqual(dark, light, 'dark theme changes the background');
  await screenshot(page, 'theme-dark.png');
  await page.reload();
  await fileShown(page, 'E1X_6_01');
  assert.equal(await page.evaluate(() => document.documentElement.dataset.theme), 'dark', 'remembered');
  assert.equal(await page.locator('#theme').inputValue(), 'dark');
  // Every theme offered applies and tells cut and idle moves apart (by colour, or by dashes
  // where print is black only).
  const themes = await page.locator('#theme option').evaluateAll((options) => options.map((o) => o.value));
  assert.deepEqual(themes, ['light', 'dark', 'high-contrast', 'print'], 'one theme per stylesheet');
  await page.selectOption('#solver', 'nearest');
  await page.click('#start');
  await page.waitForFunction(() => document.querySelector('#job-status')?.textContent === 'finished');
  for (const theme of themes) {
    await page.selectOption('#theme', theme);
    assert.equal(await page.evaluate(() => document.documentElement.dataset.theme), theme);
    const [cut, idle] = await page.evaluate(() => ['path.cut', 'path.idle'].map((s) => {
      const style = getComputedStyle(document.querySelector(`#nest-view .route ${s}`));
      return `${style.stroke} dashes ${style.strokeDasharray}`;
    }));
    assert.notEqual(cut, idle, `${theme}: cut ${cut} vs idle ${idle}`);
    await screenshot(page, `theme-${theme}.png`);
  }
});

test('the exact solver proves the optimum of E1X_6_01, and the chart draws both bounds', async () => {
  const page = await app.browser.newPage({ viewport: { width: 1280, height: 800 } });
  const errors = watchErrors(page);
  await page.goto(app.baseUrl);
  await fileShown(page, 'E1X_6_01');
  await page.selectOption('#solver', 'exact');
  await page.fill('#time-limit', '20');
  await page.dispatchEvent('#time-limit', 'change');
  await page.click('#start');
  await page.waitForFunction(() => /^(finished|cancelled|failed)/.test(document.querySelector('#job-status')?.textContent ?? ''),
    null, { timeout: 60000 });
  assert.equal(await page.locator('#job-status').textContent(), 'finished');
  // Two oracles: the known optimum of the discretised nest (1005.6 at the default step), and the
  // CLI's exact solver on the same file with the same settings.
  const oracle = cli('solve', 'data/nests/dbs-json/E1X_6_01.dbs.json', '--solver', 'exact', '--time-limit', '20', '--json');
  assert.equal(oracle.proven_optimal, true, 'the CLI proves it');
  assertRounded(oracle.ub, 1005.6, 1, 'the CLI finds the known optimum');
  const upper = await page.locator('#upper-bound').textContent();
  assert.equal(upper, '1005.6');
  assertRounded(upper, oracle.ub, 1, 'upper bound');
  assertRounded(await page.locator('#lower-bound').textContent(), oracle.ub, 1, 'lower bound meets it');
  assert.equal(await page.locator('#gap').textContent(), '0.00 % · proven optimal');
  assert.ok((await page.locator('.chart-ub').getAttribute('d')).startsWith('M'), 'upper bound drawn');
  assert.ok((await page.locator('.chart-lb').getAttribute('d')).startsWith('M'), 'lower bound drawn');
  assert.equal(await page.locator('#nest-view .route circle.pierce').count(), 16);
  await screenshot(page, 'exact-bounds.png');
  assert.deepEqual(errors, []);
});

test('ccp on nested.dbs reports a certified lower bound: the chart draws both bounds, the stats the gap', async () => {
  const page = await app.browser.newPage({ viewport: { width: 1280, height: 800 } });
  const errors = watchErrors(page);
  await page.goto(app.baseUrl);
  await fileShown(page, 'E1X_6_01');
  await page.selectOption('#sample', 'nested.dbs');
  await fileShown(page, 'nested.dbs');
  await page.selectOption('#solver', 'ccp');
  await page.fill('#time-limit', '6');
  await page.dispatchEvent('#time-limit', 'change');
  await page.click('#start');
  await page.waitForFunction(() => /^(finished|cancelled|failed)/.test(document.querySelector('#job-status')?.textContent ?? ''),
    null, { timeout: 60000 });
  assert.equal(await page.locator('#job-status').textContent(), 'finished');
  const upper = Number(await page.locator('#upper-bound').textContent());
  const lower = Number(await page.locator('#lower-bound').textContent());
  // Sound: never above the route shown, nor above the best route the CLI's ccp finds.
  const oracle = cli('solve', 'data/nests/dbs/nested.dbs', '--solver', 'ccp', '--time-limit', '3', '--json');
  assert.ok(lower > 0 && lower <= upper + 0.05 && lower <= oracle.idle_length + 0.05,
    `0 < LB ${lower} <= UB ${upper} and <= the CLI's route ${oracle.idle_length}`);
  // The upper bound is the route's idle length, and the gap is the one the two bounds make.
  assertRounded(upper, Number(await page.getAttribute('#idle-length', 'data-mm')), 1, 'UB is the route shown');
  // (from the rounded bounds: within a tenth of a percent)
  assertRounded(await page.locator('#gap').textContent(), ((upper - lower) / upper) * 100, 1, 'gap');
  assert.ok((await page.locator('.chart-ub').getAttribute('d')).startsWith('M'), 'upper bound drawn');
  assert.ok((await page.locator('.chart-lb').getAttribute('d')).startsWith('M'), 'lower bound drawn');
  assert.deepEqual(errors, []);
});
