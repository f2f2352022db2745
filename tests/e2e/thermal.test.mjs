// Issue 19 in the app: the heat model and the shop rules. CCP-Relax with the heat penalty
// (σ 50 mm, τ 60 s, weight 100) and every rule checked, on a real nest (T-FLEX Nest01: the
// heated search converges in well under a second, so the page and the CLI reach the same
// route). Oracle: the native CLI on the same file and settings — its `heat` is the H the page
// must show (within the page's rounding), its `rule_violations` the counts the page must list.
// The heat map is switched on and must draw a field that changes with the animation's clock.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import path from 'node:path';
import {
  watchErrors, projectRoot, useApp, screenshot, cli, assertRounded, runSolver, setNumber, heatMapAt,
  expectedHeatField,
} from './harness.mjs';

const app = useApp(before, after);
const nest = path.join(projectRoot, 'data', 'nests', 'tflex', 'Nest01.tfnesting');

test('ccp with the heat penalty: H and the violations match the CLI, the heat map follows the animation', async () => {
  assert.ok(fs.existsSync(nest), `missing test file ${nest}`);
  const context = await app.browser.newContext({ viewport: { width: 1280, height: 800 } });
  const page = await context.newPage();
  const errors = watchErrors(page);
  await page.goto(app.baseUrl);
  await page.setInputFiles('#file-input', nest);
  await page.waitForFunction(() => (document.querySelector('#file-name')?.textContent ?? '').includes('Nest01'),
    null, { timeout: 20000 });

  // The machine/material panel's thermal settings.
  await page.click('details.thermal summary');
  await setNumber(page, '#thermal-sigma', 50);
  await setNumber(page, '#thermal-tau', 60);
  await setNumber(page, '#thermal-weight', 100);
  for (const rule of ['#rule-part', '#rule-sheet', '#rule-islands']) await page.check(rule);
  assert.equal(await page.isChecked('#rules-hard'), false);
  // The settings ride the share link.
  const link = await page.inputValue('#share-link');
  assert.match(link, /sigma=50&tau=60&heat_weight=100&rules=part,sheet,islands&hard=0/);

  await runSolver(page, 'ccp', 3);
  const oracle = cli('solve', 'data/nests/tflex/Nest01.tfnesting', '--solver', 'ccp', '--time-limit', '3',
    '--seed', '1', '--thermal-sigma', '50', '--thermal-tau', '60', '--thermal-weight', '100',
    '--rules', 'part,sheet,islands', '--json');
  // Same route: the comparisons below are about one route, not two close ones.
  assertRounded(await page.getAttribute('#idle-length', 'data-mm'), oracle.idle_length, 3, 'idle length');

  // H as shown (4 decimals) and unrounded.
  assertRounded(await page.textContent('#heat'), oracle.heat, 4, 'H');
  const exact = Number(await page.getAttribute('#heat', 'data-value'));
  // wasm's exp and the native one may differ in the last bits: 1e-6 relative, far below the display.
  assert.ok(Math.abs(exact - oracle.heat) <= 1e-6 * Math.max(oracle.heat, 1e-12), `H ${exact} vs ${oracle.heat}`);

  // The violations: counts per rule as the CLI reports them, one list item per violation.
  const counts = await page.evaluate(() => {
    const dd = document.querySelector('#rule-counts');
    return { part: Number(dd.dataset.part), sheet: Number(dd.dataset.sheet), islands: Number(dd.dataset.islands) };
  });
  assert.deepEqual(counts, oracle.rule_violations);
  const listed = await page.evaluate(() => {
    const by = { part: 0, sheet: 0, islands: 0 };
    for (const li of document.querySelectorAll('#violations li')) by[li.dataset.kind] += 1;
    return by;
  });
  assert.deepEqual(listed, oracle.rule_violations, 'the list has one item per counted violation');
  const total = Object.values(oracle.rule_violations).reduce((a, b) => a + b, 0);
  assert.ok(total > 0, 'the oracle reports violations, so the list is not vacuously equal');
  // Each listed violation is marked on the drawing, at its step.
  const marked = await page.evaluate(() => [...document.querySelectorAll('#nest-view .violations .violation')]
    .map((m) => Number(m.dataset.step)).sort((a, b) => a - b));
  const steps = await page.evaluate(() => [...document.querySelectorAll('#violations li')]
    .map((li) => Number(li.dataset.step)).sort((a, b) => a - b));
  assert.deepEqual(marked, steps);

  // The heat map: off by default, on from the layer panel, a field that follows the clock.
  assert.equal(await page.locator('#heat-map').count(), 0, 'off until asked for');
  await page.check('#layer-heat');
  const clockTotal = Number(await page.getAttribute('#anim-clock', 'data-total'));
  assertRounded(clockTotal.toFixed(3), oracle.time_s, 3, 'the animation lasts the route\'s machine time');
  // A second after the first pierce the sheet is hot at one spot; a second after the last, every
  // spot has been switched on and the early ones have cooled. The pierce times are the CLI's
  // per-step `t`, on the same machine clock as the animation.
  const times = oracle.route.map((step) => step.t);
  const early = await heatMapAt(page, times[0] + 1);
  const late = await heatMapAt(page, times[times.length - 1] + 1);
  // At both times the drawn field is the model's, recomputed here from the CLI's pierces and
  // times on the page's grid: its sum, its hottest cell and the cells of every colour level.
  for (const [frame, when] of [[early, 'a second after the first pierce'], [late, 'a second after the last']]) {
    const expected = expectedHeatField(oracle, frame, 50, 60);
    assertRounded(frame.sum, expected.sum, 6, `field sum ${when}`);
    assertRounded(frame.max, expected.max, 6, `hottest cell ${when}`);
    const drawn = new Array(frame.thresholds.length).fill(0);
    for (const [cls, count] of frame.levels) drawn[Number(cls.match(/heat-(\d+)/)[1])] = count;
    assert.deepEqual(drawn, expected.cells, `cells per colour level ${when}`);
  }
  // Playing the animation redraws the field as the clock runs.
  await page.locator('#anim-scrub').fill('0');
  await page.selectOption('#anim-speed', '100');
  await page.click('#anim-play');
  await page.waitForFunction(() => Number(document.querySelector('#heat-map')?.getAttribute('data-time')) > 5,
    null, { timeout: 20000 });
  await page.click('#anim-play');
  await screenshot(page, 'thermal-heat-map.png');

  // The comparison view: time, cost and H side by side.
  await page.click('#keep-result');
  const row = await page.evaluate(() => {
    const tr = document.querySelector('#compare-table tr.kept');
    return { time: tr.querySelector('.kept-time').dataset.s, cost: tr.querySelector('.kept-cost').textContent,
      heat: tr.querySelector('.kept-heat').textContent };
  });
  assertRounded(row.heat, oracle.heat, 4, 'kept H');
  assertRounded(row.time, oracle.time_s, 1, 'kept time');
  assertRounded(row.cost, oracle.cost, 2, 'kept cost');

  assert.deepEqual(errors, []);
  await context.close();
});

test('hard rules: the page repairs the route as the CLI does, and lists nothing left', async () => {
  const context = await app.browser.newContext({ viewport: { width: 1280, height: 800 } });
  const page = await context.newPage();
  const errors = watchErrors(page);
  // The settings from a link, as a shared link would carry them.
  await page.goto(`${app.baseUrl}?solver=ccp&time=3&seed=1&sigma=50&tau=60&heat_weight=100&rules=part,sheet,islands&hard=1`);
  await page.setInputFiles('#file-input', nest);
  await page.waitForFunction(() => (document.querySelector('#file-name')?.textContent ?? '').includes('Nest01'),
    null, { timeout: 20000 });
  await page.click('details.thermal summary');
  assert.equal(await page.isChecked('#rules-hard'), true, 'hard mode from the link');
  assert.equal(await page.inputValue('#thermal-weight'), '100');
  await runSolver(page, 'ccp', 3);
  const oracle = cli('solve', 'data/nests/tflex/Nest01.tfnesting', '--solver', 'ccp', '--time-limit', '3',
    '--seed', '1', '--thermal-sigma', '50', '--thermal-tau', '60', '--thermal-weight', '100',
    '--rules-hard', '--json');
  assert.deepEqual(oracle.rule_violations, { part: 0, sheet: 0, islands: 0 }, 'the CLI repairs every rule here');
  assertRounded(await page.getAttribute('#idle-length', 'data-mm'), oracle.idle_length, 3, 'idle length');
  assertRounded(await page.textContent('#heat'), oracle.heat, 4, 'H');
  const counts = await page.evaluate(() => {
    const dd = document.querySelector('#rule-counts');
    return { part: Number(dd.dataset.part), sheet: Number(dd.dataset.sheet), islands: Number(dd.dataset.islands) };
  });
  assert.deepEqual(counts, oracle.rule_violations);
  assert.equal(await page.locator('#violations li').count(), 0);
  assert.equal(await page.locator('#nest-view .violations .violation').count(), 0);
  assert.deepEqual(errors, []);
  await context.close();
});
