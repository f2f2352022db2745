// Issue 17 in the app: the full cutting route. The machine panel's kerf 2, d₁ 5, d₂ 1 and an
// arc lead-in go into the job request; the engine's kerf job returns the route with its leads.
// The drawing has one lead path per step, the equidistants and the pierce/switch-off marks;
// the animation travels the leads; the G-code export read back by the project's reader (the
// CLI's `inspect`) gives the page's pierce count and cut length (leads included), and the
// program's lead-in arcs add up to the lead-in length the page reports.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { watchErrors, useApp, screenshot, cli, cliError, projectRoot, runSolver, setNumber } from './harness.mjs';

const app = useApp(before, after);

/**
 * The lead-ins of a G-code program: the first feed move after each torch-on (a line, or an arc
 * with I/J) — the post-processor writes each lead-in as one move — their count, their summed
 * length and how many are arcs.
 */
function leadIns(program) {
  let [x, y] = [0, 0];
  let [total, count, arcs] = [0, 0, 0];
  let afterPierce = false;
  for (const raw of program.split('\n')) {
    const line = raw.replace(/\(.*?\)|;.*$/g, '').trim().toUpperCase();
    const word = (letter) => {
      const m = line.match(new RegExp(`${letter}(-?[\\d.]+)`));
      return m ? Number(m[1]) : undefined;
    };
    if (/^M0?3\b|^M07\b/.test(line)) afterPierce = true;
    const g = line.match(/^G0?([0-3])\b/);
    if (!g) continue;
    const [nx, ny] = [word('X') ?? x, word('Y') ?? y];
    if (afterPierce && g[1] !== '0') {
      if (g[1] === '1') {
        total += Math.hypot(nx - x, ny - y);
      } else {
        const [i, j] = [word('I') ?? 0, word('J') ?? 0];
        const [cx, cy] = [x + i, y + j];
        let sweep = Math.atan2(ny - cy, nx - cx) - Math.atan2(y - cy, x - cx);
        if (g[1] === '3' && sweep < 0) sweep += 2 * Math.PI;
        if (g[1] === '2' && sweep > 0) sweep -= 2 * Math.PI;
        total += Math.hypot(i, j) * Math.abs(sweep);
        arcs += 1;
      }
      count += 1;
      afterPierce = false;
    }
    [x, y] = [nx, ny];
  }
  return { total, count, arcs };
}

test('kerf and an arc lead-in: leads drawn and animated, G-code reads back with the same pierces and leads', async () => {
  const context = await app.browser.newContext({ viewport: { width: 1280, height: 800 }, acceptDownloads: true });
  const page = await context.newPage();
  const errors = watchErrors(page);
  await page.goto(`${app.baseUrl}?sample=nested.dbs`);
  await page.waitForFunction(() => (document.querySelector('#file-name')?.textContent ?? '').includes('nested'),
    null, { timeout: 20000 });

  await page.click('details.kerf summary');
  await setNumber(page, '#kerf-width', 2);
  // nested.dbs spaces its parts 10 mm apart and 10 mm from the sheet's edges: with d₁ = 5 the
  // pierce region round the first row is a line (5 mm from both sides), and the engine rightly
  // finds no room for the leads there. d₁ = 4 leaves a band 2 mm wide.
  await setNumber(page, '#kerf-d1', 4);
  await setNumber(page, '#kerf-d2', 1);
  await page.selectOption('#lead-in-shape', 'arc');
  await page.dispatchEvent('#lead-in-shape', 'change');
  // The settings ride the share link.
  const link = await page.inputValue('#share-link');
  assert.match(link, /kerf=2&d1=4&d2=1/);
  assert.match(link, /lead_in=arc&lead_out=none/);

  await runSolver(page, 'ccp', 3);
  assert.match(await page.textContent('#phase'), /leads/, 'the job says it fitted leads');
  const steps = await page.locator('#nest-view .route circle.pierce').count();
  assert.ok(steps > 0);
  const pierces = Number(await page.textContent('#pierces'));
  assert.equal(pierces, steps, 'one pierce per step (no tabs, no links)');
  // One lead path per step, in the lead class, with path data.
  const leads = page.locator('#nest-view .leads path.lead');
  assert.equal(await leads.count(), steps);
  // Each path starts at the pierce point with a move: the asked arc, or where no arc fits (parts
  // in holes), the fitter's shorter or turned line.
  const ds = await leads.evaluateAll((ps) => ps.map((p) => p.getAttribute('d')));
  for (const d of ds) assert.match(d, /^M[-\d.]+ [-\d.]+[AL]/, d);
  const drawnArcs = ds.filter((d) => /^M[-\d.]+ [-\d.]+A/.test(d)).length;
  assert.ok(drawnArcs > 0, 'arc lead-ins drawn');
  assert.ok((await page.getAttribute('#nest-view path.equidistants', 'd')).length > 0, 'equidistants drawn');
  // The outlines of the pierce region G_M (d₁ = 5) and the switch-off region G_M* (d₂ = 1): at
  // most one closed subpath per step (a contour's offset; holes too small for one draw none),
  // each in a style of its own, toggled like the other layers.
  const subpaths = (d) => (d.match(/M/g) ?? []).length;
  const regionPierce = await page.getAttribute('#nest-view g.regions path.region-pierce', 'd');
  const regionSwitchOff = await page.getAttribute('#nest-view g.regions path.region-switch-off', 'd');
  assert.ok(subpaths(regionPierce) > 0 && subpaths(regionPierce) <= steps, 'G_M outlines drawn');
  assert.ok(subpaths(regionSwitchOff) > 0 && subpaths(regionSwitchOff) <= steps, 'G_M* outlines drawn');
  const strokeOf = (selector) => page.evaluate((s) => getComputedStyle(document.querySelector(s)).stroke, selector);
  const strokes = new Set([await strokeOf('#nest-view path.region-pierce'), await strokeOf('#nest-view path.region-switch-off'),
    await strokeOf('#nest-view path.equidistants'), await strokeOf('#nest-view path.lead')]);
  assert.equal(strokes.size, 4, 'regions, equidistants and leads each in their own colour');
  const regionsDisplay = () => page.evaluate(() => getComputedStyle(document.querySelector('#nest-view g.regions')).display);
  assert.notEqual(await regionsDisplay(), 'none');
  await page.uncheck('#layer-regions');
  assert.equal(await regionsDisplay(), 'none', 'the regions layer hides');
  await page.check('#layer-regions');
  assert.notEqual(await regionsDisplay(), 'none');
  assert.equal(await page.locator('#nest-view .pierce-regions circle.pierce-m').count(), steps);
  assert.equal(await page.locator('#nest-view .pierce-regions rect.switch-off-m').count(), steps);
  // Leads are drawn in a style of their own.
  const [leadStroke, cutStroke] = await page.evaluate(() => [
    getComputedStyle(document.querySelector('#nest-view path.lead')).stroke,
    getComputedStyle(document.querySelector('#nest-view path.cut')).stroke,
  ]);
  assert.notEqual(leadStroke, cutStroke);

  const leadIn = Number(await page.getAttribute('#lead-in-length', 'data-mm'));
  const leadOut = Number(await page.getAttribute('#lead-out-length', 'data-mm'));
  const cut = Number(await page.getAttribute('#cut-length', 'data-mm'));
  const idle = Number(await page.getAttribute('#idle-length', 'data-mm'));
  assert.ok(leadIn > 0, 'arc lead-ins have length');
  assert.equal(leadOut, 0, 'no lead-out asked for');

  // The animation travels idle moves, leads and cuts: its route is idle + cut (leads in it).
  const travelled = Number(await page.getAttribute('#anim-done', 'pathLength'));
  assert.ok(Math.abs(travelled - (idle + cut)) <= 1e-3 * (idle + cut), `animation ${travelled} vs ${idle} + ${cut}`);
  await page.locator('#anim-scrub').fill('1');
  await page.locator('#tool-head').waitFor({ timeout: 10000 });

  // G-code export, read back by the project's reader.
  const dir = fs.mkdtempSync(path.join(os.tmpdir(), 'cutroute-kerf-'));
  await page.click('.export summary');
  const [download] = await Promise.all([page.waitForEvent('download'), page.click('#export-gcode')]);
  const file = path.join(dir, download.suggestedFilename());
  await download.saveAs(file);
  const read = cli('inspect', file, '--json');
  assert.equal(read.route_pierces, pierces, 'pierce count read back');
  assert.ok(Math.abs(read.route_cut_length - cut) < 1e-2, `cut length read back ${read.route_cut_length} vs ${cut}`);
  const read_ins = leadIns(fs.readFileSync(file, 'utf8'));
  assert.equal(read_ins.count, pierces, 'a lead-in after every pierce');
  assert.equal(read_ins.arcs, drawnArcs, 'the arc lead-ins drawn are the program\'s');
  assert.ok(Math.abs(read_ins.total - leadIn) < 1e-2 * pierces, `lead-ins read back ${read_ins.total} vs ${leadIn}`);
  fs.rmSync(dir, { recursive: true, force: true });

  await screenshot(page, 'kerf.png');

  // A path solver cuts on the equidistants with leads at each path's ends: sccp on nested.dbs
  // (its parts apart, so one path per contour) draws every path's leads and M/M* points.
  await runSolver(page, 'sccp', 3);
  assert.match(await page.textContent('#phase'), /leads/, 'the sccp job says it fitted leads');
  assert.equal(Number(await page.textContent('#pierces')), steps, 'one pierce per contour');
  assert.equal(await page.locator('#nest-view .leads path.lead').count(), steps);
  assert.equal(await page.locator('#nest-view .pierce-regions circle.pierce-m').count(), steps);
  assert.equal(await page.locator('#nest-view .pierce-regions rect.switch-off-m').count(), steps);
  assert.deepEqual(errors, []);
  await context.close();
});

// Parts closer than the kerf (T-FLEX Nest01: five parts touching in a row): the engine refuses
// the job before any solver runs, and the page words the refusal in its language, naming each
// pair of contours by part (from 1) and contour as the CLI's oracle does.
test('a nest whose parts touch is refused with kerf, the pairs named in Russian', async () => {
  const file = path.join(projectRoot, 'data', 'nests', 'tflex', 'Nest01.tfnesting');
  // The oracle: the CLI refuses the same nest and settings, naming the pairs.
  const oracle = cliError(file, 'solve', file, '--solver', 'ccp', '--time-limit', '1', '--kerf', '2',
    '--pierce-clearance', '5', '--switch-off-clearance', '1', '--lead-in', 'arc');
  assert.equal(oracle.status, 1);
  const named = oracle.message.match(/(\d+) pair\(s\) of contours: part 1 contour 0 and part 2 contour 0 touch/);
  assert.ok(named, oracle.message);

  const context = await app.browser.newContext({ locale: 'ru-RU', viewport: { width: 1280, height: 800 } });
  const page = await context.newPage();
  const errors = watchErrors(page);
  await page.goto(app.baseUrl);
  await page.setInputFiles('#file-input', file);
  await page.waitForFunction(() => (document.querySelector('#file-name')?.textContent ?? '').includes('Nest01'),
    null, { timeout: 30000 });
  await page.click('details.kerf summary');
  await setNumber(page, '#kerf-width', 2);
  await setNumber(page, '#kerf-d1', 5);
  await setNumber(page, '#kerf-d2', 1);
  await page.selectOption('#solver', 'ccp');
  await page.fill('#time-limit', '1');
  await page.dispatchEvent('#time-limit', 'change');
  await page.click('#start');
  await page.waitForFunction(() => /^ошибка/.test(document.querySelector('#job-status')?.textContent ?? ''),
    null, { timeout: 30000 });
  const status = await page.textContent('#job-status');
  assert.match(status, /детали ближе друг к другу, чем ширина реза 2 мм/, status);
  assert.match(status, new RegExp(`пар контуров: ${named[1]}: деталь 1 контур 0 и деталь 2 контур 0 касаются около`), status);
  assert.doesNotMatch(status, /[A-Za-z]{2,}/, 'no English word in the Russian refusal');
  assert.equal(await page.locator('#nest-view .leads path.lead').count(), 0, 'no route drawn');
  assert.deepEqual(errors, []);
  await context.close();
});

// Kerf piercing from a link: the switch is on, nearest (deterministic) on nested.dbs places as
// many pierces in a kerf cut before as the CLI does with the same settings, and the stats say so.
test('kerf piercing rides the link, and the page places the kerf pierces the CLI places', async () => {
  const file = path.join(projectRoot, 'data', 'nests', 'dbs', 'nested.dbs');
  const oracle = cli('solve', file, '--solver', 'nearest', '--json', '--kerf', '2', '--pierce-clearance', '5',
    '--switch-off-clearance', '1', '--lead-in', 'arc', '--lead-in-length', '8', '--lead-out', 'line',
    '--lead-out-length', '2', '--kerf-pierce');
  assert.ok(oracle.kerf_pierces > 0, JSON.stringify(oracle.kerf_pierces));

  const context = await app.browser.newContext({ viewport: { width: 1280, height: 800 } });
  const page = await context.newPage();
  const errors = watchErrors(page);
  await page.goto(`${app.baseUrl}?sample=nested.dbs&kerf=2&d1=5&d2=1&lead_in_length=8&lead_out_length=2`
    + '&lead_in=arc&lead_out=line&tabs=0:0&kerf_pierce=1');
  await page.waitForFunction(() => (document.querySelector('#file-name')?.textContent ?? '').includes('nested'),
    null, { timeout: 20000 });
  assert.ok(await page.isChecked('#kerf-kerf-pierce'), 'the link turns kerf piercing on');
  assert.ok(!(await page.isChecked('#kerf-edge-pierce')));
  assert.match(await page.inputValue('#share-link'), /kerf_pierce=1/);
  await runSolver(page, 'nearest', 5);
  assert.equal(Number(await page.textContent('#kerf-pierces')), oracle.kerf_pierces, 'kerf pierces as the CLI');
  assert.equal(Number(await page.textContent('#edge-pierces')), 0);
  assert.equal(Number(await page.textContent('#pierces')), oracle.pierces);
  const idle = Number(await page.getAttribute('#idle-length', 'data-mm'));
  assert.ok(Math.abs(idle - oracle.idle_length) < 1e-6 * oracle.idle_length, `idle ${idle} vs ${oracle.idle_length}`);
  assert.deepEqual(errors, []);
  await context.close();
});
