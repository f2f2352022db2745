// Issue 8 in the app: segment cutting (sccp, gsccp) and common-edge AOE-chains on a real nest
// whose parts share edges (T-FLEX Nest01: five parts in a row touching along y = 0). Each result
// is a route of tool-on paths: drawn one element per path plus the links through scrap,
// numbered, priced, animated to its machine time, and exported as G-code that reads back with
// the same lengths and pierces. A hand-written program of open paths checks the same drawing
// without a solver.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { watchErrors, projectRoot, useApp, screenshot, cli, assertRounded } from './harness.mjs';

const app = useApp(before, after);

/** The themes the stylesheets define besides the base one, in the app's order. */
function themeSheets() {
  const order = ['dark', 'high-contrast', 'print'];
  const sheets = fs.readdirSync(path.join(projectRoot, 'style'))
    .filter((f) => f.startsWith('theme-')).map((f) => f.slice('theme-'.length, -'.css'.length));
  assert.deepEqual([...sheets].sort(), [...order].sort(), 'the theme stylesheets');
  return order;
}
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

async function freshPage() {
  const context = await app.browser.newContext({ viewport: { width: 1280, height: 800 }, acceptDownloads: true });
  const page = await context.newPage();
  const errors = watchErrors(page);
  await page.goto(app.baseUrl);
  await fileShown(page, 'E1X_6_01');
  return { page, errors, context };
}

/** Runs `solver` to its end; fails with the job's status if it does not finish. */
async function solve(page, solver, seconds = 3) {
  await page.selectOption('#solver', solver);
  await page.fill('#time-limit', String(seconds));
  await page.dispatchEvent('#time-limit', 'change');
  await page.click('#start');
  await page.waitForFunction(() => /^(finished|failed)/.test(document.querySelector('#job-status')?.textContent ?? ''),
    null, { timeout: 120000 });
  assert.equal(await page.textContent('#job-status'), 'finished', `${solver} finishes`);
}

/** The shown route's figures (unrounded attributes of the stats panel). */
async function figures(page) {
  return {
    idle: Number(await page.getAttribute('#idle-length', 'data-mm')),
    cut: Number(await page.getAttribute('#cut-length', 'data-mm')),
    pierces: Number(await page.textContent('#pierces')),
    time: Number(await page.getAttribute('#machine-time', 'data-s')),
    cost: Number(await page.getAttribute('#route-cost', 'data-value')),
  };
}

function downloader(page) {
  const dir = fs.mkdtempSync(path.join(os.tmpdir(), 'cutroute-segments-'));
  return async (button, name) => {
    const [file] = await Promise.all([page.waitForEvent('download'), page.click(button)]);
    const target = path.join(dir, name ?? file.suggestedFilename());
    await file.saveAs(target);
    return target;
  };
}

/**
 * The drawing of a route of tool-on paths: paths in six hues taken in turn (one element per hue),
 * pierce circles and order numbers per path, and the drawn tool-on length (paths + links,
 * measured by the browser) equal to the stats' cut length. Returns the drawn link length.
 */
async function checkPathDrawing(page, shown, what) {
  const drawn = await page.evaluate(() => {
    const paths = [...document.querySelectorAll('#nest-view .tool-on-paths path.tool-on-path')];
    const link = document.querySelector('#nest-view .route path.link');
    const length = (p) => (p && p.getAttribute('d') ? p.getTotalLength() : 0);
    return {
      count: paths.length,
      hues: [...new Set(paths.map((p) => [...p.classList].find((c) => c.startsWith('hue-'))))],
      perHue: paths.map((p) => Number(p.dataset.paths)),
      numbers: [...document.querySelectorAll('#nest-view .order text')].map((t) => Number(t.textContent)),
      pathLength: paths.reduce((sum, p) => sum + length(p), 0),
      linkLength: length(link),
      pierces: document.querySelectorAll('#nest-view .route circle.pierce').length,
      labels: document.querySelectorAll('#nest-view .order text').length,
      plainCut: document.querySelector('#nest-view .route path.cut:not(.tool-on-path)')?.getAttribute('d') ?? '',
    };
  });
  assert.equal(drawn.count, Math.min(6, shown.pierces), `${what}: one element per hue in use`);
  assert.equal(drawn.hues.length, drawn.count, `${what}: each element its own hue (${drawn.hues})`);
  assert.deepEqual(drawn.perHue, Array.from({ length: drawn.count },
    (_, h) => Math.floor((shown.pierces - 1 - h) / 6) + 1), `${what}: path k takes hue k mod 6`);
  // Numbers where they fit at their screen size: ascending, the first path's always.
  assert.equal(drawn.numbers[0], 1, `${what}: the first path numbered`);
  assert.ok(drawn.numbers.every((n, k) => n <= shown.pierces && (k === 0 || n > drawn.numbers[k - 1])),
    `${what}: numbered in order (${drawn.numbers})`);
  assert.equal(drawn.pierces, shown.pierces, `${what}: a pierce mark per path`);
  assert.ok(drawn.labels >= 1 && drawn.labels <= shown.pierces, `${what}: order numbers (${drawn.labels})`);
  assert.equal(drawn.plainCut, '', `${what}: no whole-contour cut path`);
  const tolerance = 1e-3 * shown.cut + 0.5;
  assert.ok(Math.abs(drawn.pathLength + drawn.linkLength - shown.cut) <= tolerance,
    `${what}: drawn tool-on ${drawn.pathLength} + links ${drawn.linkLength} vs cut length ${shown.cut}`);
  return drawn.linkLength;
}

/** Plays the animation from near its end; the clock stops at the route's machine time. */
async function playToEnd(page, shown, what) {
  const total = Number(await page.getAttribute('#anim-clock', 'data-total'));
  assert.ok(Math.abs(total - shown.time) <= 1e-3 + 1e-6 * shown.time, `${what}: clock ${total} vs stats time ${shown.time}`);
  await page.locator('#anim-scrub').fill(String(Math.max(0, total - 20)));
  await page.selectOption('#anim-speed', '100');
  await page.click('#anim-play');
  await page.waitForFunction(() => {
    const c = document.querySelector('#anim-clock');
    return Number(c.dataset.total) > 0 && c.dataset.time === c.dataset.total;
  }, null, { timeout: 30000 });
  assert.equal(await page.getAttribute('#tool-head', 'data-machine-time'), total.toFixed(3), `${what}: the head ends at the end`);
  assert.match(await page.textContent('#anim-contour'), new RegExp(`^path ${shown.pierces} of ${shown.pierces}$`));
  assert.equal(await page.getAttribute('#anim-play', 'aria-label'), 'Play', `${what}: stopped at the end`);
}

/** Exports G-code, reopens it in the app: the same lengths and pierces, drawn as paths. */
async function gcodeReadsBack(page, shown, name, what) {
  await page.click('.export summary');
  const program = await downloader(page)('#export-gcode', name);
  assert.match(fs.readFileSync(program, 'utf8'), /path 1 of \d+/, `${what}: paths numbered in comments`);
  await page.setInputFiles('#file-input', program);
  await fileShown(page, `${name} (G-code)`);
  const back = await figures(page);
  assert.equal(back.pierces, shown.pierces, `${what}: pierces read back`);
  assert.ok(Math.abs(back.idle - shown.idle) <= 0.01, `${what}: idle ${back.idle} vs ${shown.idle}`);
  assert.ok(Math.abs(back.cut - shown.cut) <= 0.01, `${what}: cut ${back.cut} vs ${shown.cut}`);
  await page.click('.export summary');
  return back;
}

const TWO_SQUARES_OPEN = [
  // Two squares sharing the edge x = 10: the outline of both, then the common edge once,
  // running on through scrap to a third square's top edge and round it.
  'G21', 'G90', 'G00 X0 Y0', 'M03', 'G04 P0.5',
  'G01 X0 Y10 F6000', 'G01 X10 Y10', 'G01 X20 Y10', 'G01 X20 Y0', 'G01 X10 Y0', 'G01 X0 Y0', 'M05',
  'G00 X10 Y0', 'M03', 'G04 P0.5',
  'G01 X10 Y10', 'G01 X10 Y20', 'G01 X35 Y20', 'G01 X35 Y10',
  'G01 X30 Y10', 'G01 X30 Y0', 'G01 X40 Y0', 'G01 X40 Y10', 'G01 X35 Y10', 'M05',
  'G00 X0 Y0', 'M30', '',
].join('\n');

test('a G-code program of open tool-on paths opens as paths: drawn apart, priced, animated, re-exported', async () => {
  const { page, errors, context } = await freshPage();
  const dir = fs.mkdtempSync(path.join(os.tmpdir(), 'cutroute-open-paths-'));
  const file = path.join(dir, 'open-paths.nc');
  fs.writeFileSync(file, TWO_SQUARES_OPEN);
  await page.setInputFiles('#file-input', file);
  await fileShown(page, 'open-paths.nc (G-code)');
  await page.locator('#open-notes').waitFor();
  assert.match(await page.textContent('#open-notes'), /open tool-on paths.*shown as its 2 paths/);
  const shown = await figures(page);
  // 60 outline + 10 common edge + 45 through scrap + 40 round the third square; idle 10 in between, 35.36 home.
  assert.equal(shown.pierces, 2);
  assert.ok(Math.abs(shown.cut - 155) <= 1e-3, `cut ${shown.cut}`);
  assert.ok(Math.abs(shown.idle - (10 + Math.hypot(35, 10))) <= 1e-3, `idle ${shown.idle}`);
  const links = await checkPathDrawing(page, shown, 'open paths');
  // Links are the tool-on pieces on no contour of the nest the program's closed loops trace
  // (the 20 × 10 outline and the third square): the common edge x = 10 (10 mm; the loops trace
  // the outline, not the two squares) and the piece through scrap (up, across, down: 10 + 25 + 10).
  assert.ok(Math.abs(links - 55) <= 1e-3, `the common edge and the piece through scrap (55 mm) are links: ${links}`);
  await playToEnd(page, shown, 'open paths');
  const back = await gcodeReadsBack(page, shown, 'open-paths-again.nc', 'open paths');
  assert.ok(Math.abs(back.time - shown.time) <= 1e-3, `time ${back.time} vs ${shown.time}`);
  await screenshot(page, 'open-paths.png');
  assert.deepEqual(errors, []);
  await context.close();
});

for (const solver of ['sccp', 'gsccp', 'aoe']) {
  test(`${solver} on a nest with common edges: paths and links drawn, priced, animated, G-code read back`, async () => {
    const { page, errors, context } = await freshPage();
    await page.setInputFiles('#file-input', shared('tflex/Nest01.tfnesting'));
    await fileShown(page, 'Nest01');
    await page.selectOption('#objective', 'time');
    await solve(page, solver);
    assert.match(await page.textContent('#solver-uses'), /objective/);
    const shown = await figures(page);
    // The oracle: the CLI's run of the same solver on the same file, objective, seed and limit
    // (the engine's path-route jobs converge on this small nest well within the limit).
    const oracle = cli('solve', 'data/nests/tflex/Nest01.tfnesting', '--solver', solver, '--objective', 'time',
      '--time-limit', '3', '--json');
    assert.equal(shown.pierces, oracle.pierces, `${solver}: pierces`);
    assertRounded(shown.cut, oracle.cut_length, 3, `${solver}: cut length`);
    assertRounded(shown.idle, oracle.idle_length, 3, `${solver}: idle length`);
    assertRounded(shown.time, oracle.time_s, 3, `${solver}: machine time`);
    assertRounded(shown.cost, oracle.cost, 3, `${solver}: cost`);
    // The bound is the objective's value, and the chart says so.
    const upper = Number(await page.textContent('#upper-bound'));
    assert.ok(Math.abs(upper - shown.time) <= 0.051, `${solver}: bound ${upper} is the machine time ${shown.time}`);
    assert.match(await page.textContent('#chart-y-label'), /^s \(machine time\)$/);
    await checkPathDrawing(page, shown, solver);
    // The candidates the solver weighed (GSCCP: every ensemble and the CCP route that seeded
    // them; the others report their one route): exactly one chosen, the route shown.
    const rows = await page.locator('#alternatives tbody tr').evaluateAll((trs) => trs.map((tr) => ({
      name: tr.dataset.name, chosen: tr.dataset.chosen === 'true',
      time: Number(tr.querySelector('.alt-time')?.dataset.s ?? NaN),
      pierces: Number(tr.querySelector('.alt-pierces')?.textContent ?? NaN),
    })));
    // SCCP and GSCCP list every ensemble the CLI reports plus the CCP route that seeded them;
    // AOE lists its one route.
    const expectedRows = solver === 'aoe' ? 1 : oracle.ensembles.length + 1;
    assert.equal(rows.length, expectedRows, `${solver}: candidates ${JSON.stringify(rows)}`);
    const chosen = rows.filter((r) => r.chosen);
    assert.equal(chosen.length, 1, `one chosen row: ${JSON.stringify(rows)}`);
    assert.match(await page.locator('#alternatives tr.chosen td').first().textContent(), /chosen/);
    assert.equal(chosen[0].pierces, shown.pierces, 'the chosen row is the route shown');
    assertRounded(chosen[0].time, oracle.time_s, 3, `${solver}: the chosen row's time`);
    if (solver === 'gsccp') {
      for (const ensemble of oracle.ensembles.filter((e) => e.time_s !== null)) {
        const row = rows.find((r) => r.name === ensemble.kind);
        assert.ok(row, `${ensemble.kind} listed: ${JSON.stringify(rows)}`);
        assert.equal(row.pierces, ensemble.pierces, `${ensemble.kind}: pierces`);
        assertRounded(row.time, ensemble.time_s, 3, `${ensemble.kind}: time`);
      }
      const best = Math.min(...rows.filter((r) => Number.isFinite(r.time)).map((r) => r.time));
      assertRounded(chosen[0].time, best, 3, `chosen by machine time: ${JSON.stringify(rows)}`);
    }
    // Result JSON cannot hold tool-on paths: off, with the reason on the page.
    await page.click('.export summary');
    assert.equal(await page.isDisabled('#export-result'), true);
    assert.match(await page.textContent('#export-result-note'), /cannot hold tool-on paths/);
    // The standalone page animates the same route: its clock ends at the app's machine time,
    // one pierce mark per path.
    const html = fs.readFileSync(await downloader(page)('#export-html'), 'utf8');
    const data = html.match(/<script type="application\/json" id="route-data">([^<]*)<\/script>/);
    assert.ok(data, `${solver}: the page embeds its route data`);
    const samples = JSON.parse(data[1]);
    assert.ok(Math.abs(samples.at(-1)[0] - shown.time) <= 0.01, `${solver}: page's time ${samples.at(-1)[0]} vs ${shown.time}`);
    assert.equal([...html.matchAll(/<circle class="pierce"/g)].length, shown.pierces, `${solver}: the page's pierces`);
    await page.click('.export summary');
    await screenshot(page, `segments-${solver}.png`);
    await playToEnd(page, shown, solver);
    await gcodeReadsBack(page, shown, `Nest01-${solver}.nc`, solver);
    assert.deepEqual(errors, []);
    await context.close();
  });
}

test('the objective is chosen, remembered, used by GSCCP and by the comparison; paths read in every theme', async () => {
  const { page, errors, context } = await freshPage();
  await page.setInputFiles('#file-input', shared('tflex/Nest01.tfnesting'));
  await fileShown(page, 'Nest01');
  await page.selectOption('#objective', 'cost');
  await solve(page, 'gsccp');
  const shown = await figures(page);
  const upper = Number(await page.textContent('#upper-bound'));
  assert.ok(Math.abs(upper - shown.cost) <= 0.051, `bound ${upper} is the cost ${shown.cost}`);
  assert.match(await page.textContent('#chart-y-label'), /^cost$/);
  const costs = await page.locator('#alternatives tbody tr .alt-cost').evaluateAll((tds) => tds.map((td) => Number(td.dataset.value)));
  const chosenCost = Number(await page.getAttribute('#alternatives tr.chosen .alt-cost', 'data-value'));
  assert.equal(chosenCost, Math.min(...costs), `chosen by cost among ${costs}`);
  await page.click('#keep-result');
  await solve(page, 'aoe');
  await page.click('#keep-result');
  await solve(page, 'ccp', 1);
  await page.click('#keep-result');
  assert.match(await page.textContent('#compare-by'), /vs best \(cost\)/);
  const excess = await page.locator('#compare-table tbody tr td:nth-child(4)').allTextContents();
  assert.equal(excess.length, 3);
  assert.ok(excess.includes('+0.0 %'), `the cheapest is 0 % over the best: ${excess}`);
  // Tool-on paths of AOE: neighbouring paths differ, and links differ from paths and idle moves,
  // in every theme.
  await solve(page, 'aoe');
  const themes = await page.locator('#theme option').evaluateAll((os) => os.map((o) => o.value));
  // One theme per stylesheet: light (the base) and each theme-*.css.
  assert.deepEqual(themes, ['light', ...themeSheets()]);
  for (const theme of themes) {
    await page.selectOption('#theme', theme);
    const styles = await page.evaluate(() => {
      const look = (el) => {
        if (!el) return null;
        const s = getComputedStyle(el);
        return `${s.stroke} ${s.strokeWidth} ${s.strokeDasharray}`;
      };
      return {
        hue0: look(document.querySelector('#nest-view .tool-on-path.hue-0')),
        hue1: look(document.querySelector('#nest-view .tool-on-path.hue-1')),
        link: look(document.querySelector('#nest-view .route path.link')),
        idle: look(document.querySelector('#nest-view .route path.idle')),
      };
    });
    assert.ok(styles.hue0 && styles.hue1, `${theme}: AOE's 4 paths use at least two hues`);
    assert.notEqual(styles.hue0, styles.hue1, `${theme}: paths 1 and 2 look different`);
    assert.notEqual(styles.link, styles.idle, `${theme}: links vs idle moves`);
    assert.notEqual(styles.link, styles.hue0, `${theme}: links vs tool-on paths`);
    await screenshot(page, `segments-theme-${theme}.png`);
  }
  // Remembered across a reload, and carried by the share link.
  assert.match(await page.inputValue('#share-link'), /objective=cost/);
  await page.reload();
  await fileShown(page, 'E1X_6_01');
  assert.equal(await page.inputValue('#objective'), 'cost');
  assert.deepEqual(errors, []);
  await context.close();
});
