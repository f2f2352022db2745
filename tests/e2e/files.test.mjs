// Issue 7, files in and out: PCGTSP instances with PCGLNS results (checked tours, drawn on the
// nest when a task places their nodes), G-code and the standalone HTML page read back, the
// chain solver and a solve on a bare PCGTSP instance.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { watchErrors, projectRoot, useApp, screenshot, cli, assertRounded } from './harness.mjs';

const app = useApp(before, after);
const nests = path.resolve(projectRoot, 'data', 'nests');

/** A file of `data/nests`; fails loudly when it is missing. */
function shared(relative) {
  const file = path.join(nests, relative);
  assert.ok(fs.existsSync(file), `missing test file ${file}`);
  return file;
}

async function fileShown(page, ...names) {
  await page.waitForFunction((ns) => {
    const shown = document.querySelector('#file-name')?.textContent ?? '';
    return ns.every((n) => shown.includes(n));
  }, names, { timeout: 20000 });
}

async function solve(page, solver, seconds = 2) {
  await page.selectOption('#solver', solver);
  await page.fill('#time-limit', String(seconds));
  await page.dispatchEvent('#time-limit', 'change');
  await page.click('#start');
  await page.waitForFunction(() => document.querySelector('#job-status')?.textContent === 'finished',
    null, { timeout: 60000 });
}

async function freshPage() {
  const context = await app.browser.newContext({ viewport: { width: 1280, height: 800 }, acceptDownloads: true });
  const page = await context.newPage();
  const errors = watchErrors(page);
  await page.goto(app.baseUrl);
  await fileShown(page, 'E1X_6_01');
  return { page, errors, context };
}

/** The shown route's figures: lengths to 0.001 mm, pierces, machine time. */
async function figures(page) {
  return {
    idle: Number(await page.getAttribute('#idle-length', 'data-mm')),
    cut: Number(await page.getAttribute('#cut-length', 'data-mm')),
    pierces: Number(await page.textContent('#pierces')),
    time: Number(await page.getAttribute('#anim-clock', 'data-total')),
  };
}

function downloader(page) {
  const dir = fs.mkdtempSync(path.join(os.tmpdir(), 'cutroute-files-'));
  return async (button) => {
    const [file] = await Promise.all([page.waitForEvent('download'), page.click(button)]);
    const target = path.join(dir, file.suggestedFilename());
    await file.saveAs(target);
    return target;
  };
}

const alert = (page) => page.locator('.error[role=alert]');
const notes = (page) => page.locator('#open-notes').textContent();

test('a PCGTSP instance with its PCGLNS result: the tour is checked; a bad tour is refused in plain words', async () => {
  const { page, errors, context } = await freshPage();
  const instance = shared('pcgtsp/E1X_6_01.pcgtsp');
  const result = shared('pcgtsp/E1X_6_01.pcglns.result.txt');

  // The instance alone opens and solves (the discrete heuristic works on it directly).
  await page.setInputFiles('#file-input', instance);
  await fileShown(page, 'E1X_6_01.pcgtsp (PCGTSP instance)');
  await solve(page, 'heuristic', 1);
  // The oracle: the CLI's exact solver proves this instance's optimum, which ALNS reaches on
  // these 16 clusters within the second.
  const optimum = cli('solve', 'data/nests/pcgtsp/E1X_6_01.pcgtsp', '--solver', 'exact', '--time-limit', '20', '--json');
  assert.equal(optimum.proven_optimal, true);
  assertRounded(await page.textContent('#upper-bound'), optimum.ub, 1, 'the heuristic\'s tour');

  // Together with the result: the checker recomputes the tour's cost on the instance's weights
  // (PCGLNS rounds them and reports 1514).
  await page.setInputFiles('#file-input', [instance, result]);
  await fileShown(page, 'E1X_6_01.pcgtsp', 'E1X_6_01.pcglns.result.txt', 'PCGTSP instance', 'PCGLNS result');
  assert.match(await notes(page),
    /E1X_6_01\.pcglns\.result\.txt: tour checked against E1X_6_01\.pcgtsp: feasible, cost 1518\.429 \(the file reports 1514\); nodes 1 161 138 80 67 27 14 /);

  // A tour that cuts a part before its hole: refused with the checker's reason, nothing else changes.
  const bad = path.join(fs.mkdtempSync(path.join(os.tmpdir(), 'cutroute-tour-')), 'bad.pcglns.result.txt');
  const text = fs.readFileSync(result, 'utf8');
  const swapped = text.replace('[1, 161, 138, 80, 67, 27, 14,', '[1, 161, 138, 80, 67, 14, 27,');
  assert.notEqual(swapped, text, 'the edit applies');
  fs.writeFileSync(bad, swapped);
  await page.setInputFiles('#file-input', [instance, bad]);
  await alert(page).waitFor({ timeout: 10000 });
  assert.match(await alert(page).textContent(), /^bad\.pcglns\.result\.txt: the tour is not feasible for E1X_6_01\.pcgtsp: arc \d+ -> \d+ is forbidden/);
  assert.match(await page.textContent('#file-name'), /E1X_6_01\.pcglns\.result\.txt/, 'the checked tour stays open');

  // Drag and drop works the same as the picker: the instance and its result dropped together.
  const dropped = await page.evaluateHandle(([a, b]) => {
    const transfer = new DataTransfer();
    transfer.items.add(new File([a.text], a.name));
    transfer.items.add(new File([b.text], b.name));
    return transfer;
  }, [instance, result].map((f) => ({ name: path.basename(f), text: fs.readFileSync(f, 'utf8') })));
  await page.setInputFiles('#file-input', instance);
  await fileShown(page, 'E1X_6_01.pcgtsp (PCGTSP instance)');
  await page.dispatchEvent('section.view', 'drop', { dataTransfer: dropped });
  await fileShown(page, 'E1X_6_01.pcgtsp + E1X_6_01.pcglns.result.txt (PCGTSP instance + PCGLNS result)');

  // A result alone says what it needs.
  await page.setInputFiles('#file-input', result);
  await page.waitForFunction(() => /holds only a tour/.test(document.querySelector('.error[role=alert]')?.textContent));
  assert.match(await alert(page).textContent(), /open it together with its instance/);
  assert.deepEqual(errors, []);
  await context.close();
});

test('a nest, its task and a PCGLNS result: the tour becomes a checked cutting route on the drawing', async () => {
  const { page, errors, context } = await freshPage();
  // E1X_6_01: the shipped instance's nodes are the task's pierce points, node 1 the start.
  await page.setInputFiles('#file-input', [shared('dbs-json/E1X_6_01.dbs.json'), shared('task-json/E1X_6_01.task.json'),
    shared('pcgtsp/E1X_6_01.pcgtsp'), shared('pcgtsp/E1X_6_01.pcglns.result.txt')]);
  await fileShown(page, 'E1X_6_01.dbs.json', 'E1X_6_01.task.json', 'E1X_6_01.pcgtsp', 'E1X_6_01.pcglns.result.txt');
  assert.equal(await page.locator('#nest-view path.part').count(), 8);
  assert.equal(await page.locator('#nest-view .route circle.pierce').count(), 16, 'one pierce per tour node');
  assert.match(await notes(page), /feasible, cost 1518\.429/);
  assert.match(await notes(page), /drawn as a cutting route of E1X_6_01\.dbs\.json/);
  // The instance's weights are the idle moves between pierce points: the route's idle length
  // (recomputed from the drawing, start and finish from the task) is the tour's checked cost.
  const e1x = await figures(page);
  assert.ok(Math.abs(e1x.idle - 1518.429) <= 0.01, `idle ${e1x.idle}`);
  assert.equal(e1x.pierces, 16);
  assert.equal(await page.inputValue('#idle-speed'), '500', 'the task\'s speeds');
  await screenshot(page, 'pcglns-route.png');

  // test1: no instance file; the task defines it (rounded idle lengths, as PCGLNS was given).
  await page.setInputFiles('#file-input', [shared('dbs-json/test1.dbs.json'), shared('task-json/test1.task.json'),
    shared('pcgtsp/test1.pcglns.result.txt')]);
  await fileShown(page, 'test1.dbs.json', 'test1.task.json', 'test1.pcglns.result.txt');
  assert.match(await notes(page), /test1\.pcglns\.result\.txt: tour checked against test1\.task\.json: feasible, cost 4662\.000 \(the file reports 4662\)/);
  assert.match(await notes(page), /test1\.task\.json does not list part \d+ contour 0, part \d+ contour 0 of test1\.dbs\.json: not cut/);
  assert.equal(await page.locator('#nest-view .route circle.pierce').count(), 23);
  assert.equal(await page.textContent('#pierces'), '23');
  // The route is animated like any other (from near its end: at ×100 the whole route of
  // test1 would take half a minute).
  // Its machine time, from the task's own speeds and pierce time (read here, not from the page)
  // applied to the route's lengths, is where the animation clock ends.
  const taskData = JSON.parse(fs.readFileSync(shared('task-json/test1.task.json'), 'utf8')).TaskData;
  const test1 = await figures(page);
  const expectedTime = test1.cut / taskData.ToolCutSpeed + test1.idle / taskData.ToolIdlingSpeed
    + 23 * taskData.PiercingDuration;
  const total = Number(await page.getAttribute('#anim-clock', 'data-total'));
  assertRounded(total.toFixed(3), expectedTime, 3, 'animation clock total');
  await page.locator('#anim-scrub').fill(String(total * 0.95));
  await page.selectOption('#anim-speed', '100');
  await page.click('#anim-play');
  await page.waitForFunction(() => {
    const c = document.querySelector('#anim-clock');
    return Number(c.dataset.total) > 0 && c.dataset.time === c.dataset.total;
  }, null, { timeout: 30000 });
  assert.deepEqual(errors, []);
  await context.close();
});

test('G-code and standalone HTML exports read back: same pierces, lengths and machine time', async () => {
  const { page, errors, context } = await freshPage();
  await solve(page, 'nearest');
  const shown = await figures(page);
  const oracle = cli('solve', 'data/nests/dbs-json/E1X_6_01.dbs.json', '--solver', 'nearest', '--json');
  assert.equal(shown.pierces, oracle.pierces);
  assertRounded(shown.idle, oracle.idle_length, 3, 'idle length');
  assertRounded(shown.cut, oracle.cut_length, 3, 'cut length');
  assertRounded(shown.time, oracle.time_s, 3, 'machine time');
  await page.click('.export summary');
  const download = downloader(page);

  // The HTML page carries the head's path on the machine clock as JSON: it parses, ends at the
  // app's machine time, and passes through every pierce point the page draws.
  const html = fs.readFileSync(await download('#export-html'), 'utf8');
  const data = html.match(/<script type="application\/json" id="route-data">([^<]*)<\/script>/);
  assert.ok(data, 'the page embeds its route data');
  const samples = JSON.parse(data[1]);
  assert.ok(samples.every((s) => s.length === 3 && s.every(Number.isFinite)), 'samples [t, x, y]');
  assert.ok(samples.every((s, i) => i === 0 || s[0] >= samples[i - 1][0]), 'time never runs back');
  assert.ok(Math.abs(samples.at(-1)[0] - shown.time) <= 0.01, `page's machine time ${samples.at(-1)[0]} vs ${shown.time}`);
  const pierces = [...html.matchAll(/<circle class="pierce"[^>]* cx="([-\d.]+)" cy="([-\d.]+)"/g)].map((m) => [Number(m[1]), Number(m[2])]);
  assert.equal(pierces.length, 16, 'the page draws 16 pierces');
  for (const [x, y] of pierces) {
    assert.ok(samples.some((s) => Math.hypot(s[1] - x, s[2] - y) <= 0.002), `the head passes the pierce at (${x}, ${y})`);
  }

  // G-code in two dialects: absolute with I/J arcs, then incremental with R arcs. Each opens in
  // the app (parsed by cutroute-gcode's reader in the worker) as the same route.
  const programs = [await download('#export-gcode')];
  await page.selectOption('#gcode-distance', 'incremental');
  await page.selectOption('#gcode-arcs', 'r');
  const incremental = path.join(path.dirname(programs[0]), 'E1X_6_01-incremental.nc');
  fs.copyFileSync(await download('#export-gcode'), incremental);
  programs.push(incremental);
  assert.match(fs.readFileSync(incremental, 'utf8'), /^G91$/m);
  for (const program of programs) {
    await page.setInputFiles('#file-input', program);
    await fileShown(page, `${path.basename(program)} (G-code)`);
    const back = await figures(page);
    assert.equal(back.pierces, shown.pierces, `${program}: pierces`);
    assert.ok(Math.abs(back.idle - shown.idle) <= 0.01, `${program}: idle ${back.idle} vs ${shown.idle}`);
    assert.ok(Math.abs(back.cut - shown.cut) <= 0.01, `${program}: cut ${back.cut} vs ${shown.cut}`);
    assert.equal(await page.locator('#nest-view path.part').count(), 8, 'parts with their holes');
    assert.equal(await page.locator('#nest-view .route circle.pierce').count(), 16);
  }
  await screenshot(page, 'gcode-read-back.png');

  // A broken program: the reader's location, and the app stays usable.
  const broken = path.join(path.dirname(programs[0]), 'broken.nc');
  fs.writeFileSync(broken, 'G90\nG00 X0 Y0\nM03\nG01 X10 Y\n');
  await page.setInputFiles('#file-input', broken);
  await alert(page).waitFor({ timeout: 10000 });
  assert.match(await alert(page).textContent(), /^broken\.nc \(G-code\): .*line 4/);
  await solve(page, 'nearest');
  assert.deepEqual(errors, []);
  await context.close();
});

test('the chain solver runs and its G-code (links included) reads back as the same route', async () => {
  const { page, errors, context } = await freshPage();
  await solve(page, 'chain', 2);
  const shown = await figures(page);
  // The oracle: the CLI's chain cutting of the same nest with the same seed and limit.
  const oracle = cli('solve', 'data/nests/dbs-json/E1X_6_01.dbs.json', '--solver', 'chain', '--time-limit', '2', '--json');
  assert.equal(shown.pierces, oracle.pierces, 'chain pierces');
  assertRounded(shown.idle, oracle.idle_length, 3, 'idle length');
  // Links included: the page's wasm build and the native CLI compute the same bits (one libm
  // for both, cutroute_geometry::float), so the same links.
  assertRounded(shown.cut, oracle.cut_length, 3, 'cut length (links included)');
  assertRounded(await page.textContent('#upper-bound'), oracle.ub, 1, 'upper bound');
  // Chain cutting's bounds are on the route's cost (what it minimises), the lower one
  // certified: below the route's cost and above the perimeters' cut at the default 1 per metre,
  // which every route pays (so it bounds the links, idle moves and pierces too).
  assert.equal(oracle.unit, 'Cost');
  const lower = Number(await page.textContent('#lower-bound'));
  const perimeters = (oracle.cut_length - oracle.link_length) * 1e-3;
  assert.ok(lower <= oracle.ub + 0.05 && lower > perimeters + 0.05,
    `chain LB ${lower} between the perimeters' ${perimeters} and the route's ${oracle.ub}`);
  await page.click('.export summary');
  const program = await downloader(page)('#export-gcode');
  await page.setInputFiles('#file-input', program);
  await fileShown(page, `${path.basename(program)} (G-code)`);
  const back = await figures(page);
  assert.equal(back.pierces, shown.pierces);
  assert.ok(Math.abs(back.idle - shown.idle) <= 0.01, `idle ${back.idle} vs ${shown.idle}`);
  assert.ok(Math.abs(back.cut - shown.cut) <= 0.01, `cut ${back.cut} vs ${shown.cut}`);
  await screenshot(page, 'chain.png');
  assert.deepEqual(errors, []);
  await context.close();
});

test('every bundled sample of the gallery opens and solves', async () => {
  const { page, errors, context } = await freshPage();
  const samples = await page.locator('#sample option').evaluateAll((options) => options.map((o) => o.value));
  const bundled = fs.readdirSync(path.join(projectRoot, 'assets', 'samples'));
  assert.deepEqual([...samples].sort(), [...bundled].sort(), 'the gallery offers every bundled sample');
  for (const sample of samples) {
    await page.selectOption('#sample', sample);
    await fileShown(page, sample);
    const facts = cli('inspect', `assets/samples/${sample}`, '--json');
    // Every part but the sheet is drawn as a part.
    assert.equal(await page.locator('#nest-view path.part').count(), facts.parts - 1, `${sample} draws its parts`);
    await solve(page, 'nearest');
    const oracle = cli('solve', `assets/samples/${sample}`, '--solver', 'nearest', '--json');
    assert.equal(Number(await page.textContent('#pierces')), oracle.pierces, `${sample}: pierces`);
    assertRounded(await page.getAttribute('#idle-length', 'data-mm'), oracle.idle_length, 3, `${sample}: idle`);
    const contours = await page.evaluate(() => (document.querySelector('#nest-view path.arrows')?.getAttribute('d')?.match(/M/g) ?? []).length);
    assert.equal(Number(await page.textContent('#pierces')), contours, `${sample}: one pierce per contour`);
  }
  assert.deepEqual(errors, []);
  await context.close();
});
