// Issue 15 on the page: hostile files (one per failure class of `data/hostile/`) get the located
// error the CLI gives for the same file and the open document stays; odd but valid files solve
// to checked routes; a worker that dies is restarted with a message and the page goes on.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { watchErrors, projectRoot, useApp, cli, cliError } from './harness.mjs';

const app = useApp(before, after);
const hostile = (name) => {
  const file = path.join(projectRoot, 'data', 'hostile', name);
  assert.ok(fs.existsSync(file), `missing test file ${file}`);
  return file;
};
const nest = (relative) => path.join(projectRoot, 'data', 'nests', relative);

async function fileShown(page, ...names) {
  await page.waitForFunction((ns) => {
    const shown = document.querySelector('#file-name')?.textContent ?? '';
    return ns.every((n) => shown.includes(n));
  }, names, { timeout: 30000 });
}

async function freshPage() {
  const context = await app.browser.newContext({ viewport: { width: 1280, height: 800 }, acceptDownloads: true });
  const page = await context.newPage();
  const errors = watchErrors(page);
  await page.goto(app.baseUrl);
  await fileShown(page, 'E1X_6_01');
  return { page, errors, context };
}

async function start(page, solver, seconds, seed = 1) {
  await page.selectOption('#solver', solver);
  for (const [id, value] of [['#time-limit', seconds], ['#seed', seed]]) {
    await page.fill(id, String(value));
    await page.dispatchEvent(id, 'change');
  }
  await page.click('#start');
}

const status = (page, wanted, timeout = 60000) => page.waitForFunction(
  (w) => new RegExp(w).test(document.querySelector('#job-status')?.textContent ?? ''), wanted.source, { timeout });

const alertText = (page) => page.locator('.error[role=alert]').textContent();

/** The page's route (result JSON export) through the CLI's independent checker. */
async function checkedRoute(page) {
  const dir = fs.mkdtempSync(path.join(os.tmpdir(), 'cutroute-hostile-'));
  if (!await page.locator('#export-result').isVisible()) await page.click('.export summary');
  const [download] = await Promise.all([page.waitForEvent('download'), page.click('#export-result')]);
  const file = path.join(dir, download.suggestedFilename());
  await download.saveAs(file);
  return cli('inspect', file, '--json');
}

// One file per failure class, each with the location its reader reports (the CLI's words are
// the oracle; the pattern says which location it must hold, so a location lost on both sides
// still fails).
const truncatedDbs = () => {
  const file = path.join(fs.mkdtempSync(path.join(os.tmpdir(), 'cutroute-dbs-')), 'nested_truncated.dbs');
  fs.writeFileSync(file, fs.readFileSync(nest('dbs/nested.dbs')).subarray(0, 700));
  return file;
};
const REFUSED = [
  ['truncated result JSON', () => hostile('result_json_truncated_no_location.result.json'), /\(JSON\): line 1 column 5693: /,
    /\(JSON\): ошибка в JSON: строка 1, столбец 5693: /],
  ['result JSON with NaN', () => hostile('result_json_nan_no_location.result.json'), /\(JSON\): line 1 column 116: /,
    /\(JSON\): ошибка в JSON: строка 1, столбец 116: /],
  ['truncated DBS', truncatedDbs, /\(DBS binary\): DBS truncated at byte 696: /,
    /\(DBS, двоичный\): файл не читается: байт 696: DBS truncated/],
  ['DXF whose only entity is rejected', () => hostile('dxf_only_entity_rejected_nothing_drawn.dxf'), /\(DXF\): .*line 5: closed contour starting with LWPOLYLINE crosses itself/,
    /\(DXF\): файл не читается: .*line 5: closed contour starting with LWPOLYLINE crosses itself/],
  ['DXF arc of radius 0', () => hostile('dxf_zero_radius_arc_nothing_drawn.dxf'), /\(DXF\): .*line 5: ARC with radius 0/,
    /\(DXF\): файл не читается: .*line 5: ARC with radius 0/],
  ['T-FLEX missing its last byte', () => hostile('tflex_truncated_location_1_1.tfnesting'), /\(T-FLEX nesting\): 349:10: /,
    /\(раскрой T-FLEX\): файл не читается: строка 349, столбец 10: /],
  ['coordinates of 1e308', () => hostile('huge_coords_null_lengths.dbs.json'), /\(geometry JSON\): JSON contour at \[1\]\.paths\[0\]: contour vertex 0: coordinate 1e308/,
    /\(JSON геометрии\): файл не читается: элемент JSON \[1\]\.paths\[0\]: /],
  ['a bulge of 1e300', () => hostile('huge_bulge_gcode_8000km_arcs.dbs.json'), /\(geometry JSON\): JSON contour at \[1\]\.paths\[0\]: contour vertex 0: bulge 1e300/,
    /\(JSON геометрии\): файл не читается: элемент JSON \[1\]\.paths\[0\]: /],
  ['a part at 1e200', () => hostile('panic_ccp_far_part_1e200.dbs.json'), /JSON contour at \[2\]\.paths\[0\]: contour vertex 0: coordinate 1e200/,
    /файл не читается: элемент JSON \[2\]\.paths\[0\]: /],
  ['a zero-size contour', () => hostile('zero_size_contour_accepted.dbs.json'), /JSON contour at \[1\]\.paths\[0\]: contour spans 0e0 mm/,
    /файл не читается: элемент JSON \[1\]\.paths\[0\]: /],
  ['a 1e-6 mm contour', () => hostile('path_solvers_drop_tiny_contour.dbs.json'), /JSON contour at \[1\]\.paths\[0\]: contour spans 9\.99/,
    /файл не читается: элемент JSON \[1\]\.paths\[0\]: /],
  ['PCGTSP weights near f64::MAX', () => hostile('pcgtsp_weights_1e308_bad_tour.pcglns'), /\(PCGTSP instance\): line 8: /,
    /\(задача PCGTSP\): файл не читается: строка 8: /],
];

test('every hostile file gets the CLI\'s located error; the open document stays, and a normal file still solves', async () => {
  const { page, errors, context } = await freshPage();
  await page.setInputFiles('#file-input', nest('dbs/nested.dbs'));
  await fileShown(page, 'nested.dbs (DBS binary)');
  const parts = await page.locator('#nest-view path.part').count();
  // One drawn path per part of nested.dbs (the CLI counts its sheet as a part).
  assert.equal(parts, cli('inspect', nest('dbs/nested.dbs'), '--json').parts - 1);
  for (const [what, make, location, russian] of REFUSED) {
    const file = make();
    const oracle = cliError(file, 'inspect', file);
    assert.equal(oracle.status, 1, `${what}: the CLI refuses it`);
    assert.match(oracle.message, location, `${what}: the CLI's error holds the location`);
    await page.setInputFiles('#file-input', file);
    await page.waitForFunction((m) => document.querySelector('.error[role=alert]')?.textContent === m,
      oracle.message, { timeout: 30000 }).catch(() => {});
    assert.equal(await alertText(page), oracle.message, `${what}: the page shows the CLI's error`);
    assert.match(await page.textContent('#file-name'), /^nested\.dbs \(DBS binary\)$/, `${what}: the document stays open`);
    assert.equal(await page.locator('#nest-view path.part').count(), parts, `${what}: the drawing stays`);
    // The same error in Russian: the kind and the location worded by the page, with the file's
    // name; back in English it is the CLI's text again.
    await page.selectOption('#language', 'ru');
    assert.match(await alertText(page), russian, `${what}: the Russian error holds the location`);
    assert.ok((await alertText(page)).startsWith(path.basename(file)), `${what}: the Russian error names the file`);
    await page.selectOption('#language', 'en');
    assert.equal(await alertText(page), oracle.message, `${what}: English again`);
  }
  // The page is still usable: a sample opens and solves.
  await page.selectOption('#sample', 'test1.dbs.json');
  await fileShown(page, 'test1');
  assert.equal(await page.locator('.error[role=alert]').count(), 0, 'a file that opens clears the error');
  await start(page, 'nearest', 1);
  await status(page, /^finished$/);
  assert.notEqual(await page.textContent('#upper-bound'), '—');
  assert.deepEqual(errors, []);
  await context.close();
});

test('an infeasible PCGTSP instance fails in the CLI\'s words; the 400 × 400 MINSERT opens', async () => {
  const { page, errors, context } = await freshPage();
  for (const solver of ['exact', 'heuristic']) {
    const file = hostile('pcgtsp_infeasible_precedence.pcglns');
    await page.setInputFiles('#file-input', file);
    await fileShown(page, 'pcgtsp_infeasible_precedence.pcglns (PCGTSP instance)');
    await start(page, solver, 1);
    await status(page, /^failed: /);
    const oracle = cliError(file, 'solve', file, '--solver', solver, '--time-limit', '1');
    assert.equal(oracle.status, 3, 'exit 3: no feasible tour');
    // The heuristic's message names its own elapsed time, which differs between runs.
    const shown = (await page.textContent('#job-status')).replace(/in [\d.]+ s/, 'in … s');
    assert.equal(shown, `failed: ${oracle.message.replace(/in [\d.]+ s/, 'in … s')}`);
    assert.equal(await page.textContent('#upper-bound'), '—', 'no tour is claimed');
  }
  // 224 bytes that expand to 160,000 circles: inside the sized expansion, so it opens.
  const minsert = hostile('hang_dxf_minsert_400x400.dxf');
  const summary = cli('inspect', minsert, '--json');
  await page.setInputFiles('#file-input', minsert);
  await fileShown(page, 'hang_dxf_minsert_400x400.dxf (DXF)');
  assert.equal(await page.locator('#nest-view path.part').count(), summary.parts);
  assert.deepEqual(errors, []);
  await context.close();
});

test('the spike file solves to a checked route with ccp and chain (the seeds and limits that once failed)', async () => {
  const { page, errors, context } = await freshPage();
  const spike = hostile('ccp_chain_invalid_route_spike.dbs');
  // Contours to cut (the sheet's apart): what the nearest neighbour pierces.
  const contours = cli('solve', spike, '--solver', 'nearest', '--json').pierces;
  await page.setInputFiles('#file-input', spike);
  await fileShown(page, 'ccp_chain_invalid_route_spike.dbs (DBS binary)');
  for (const [solver, seconds, seed] of [['ccp', 5, 2], ['chain', 2, 2]]) {
    await start(page, solver, seconds, seed);
    await status(page, /^finished$/);
    const checked = await checkedRoute(page);
    assert.deepEqual(checked.route_problems, [], `${solver}: the route passes the checker`);
    // ccp cuts whole contours, one pierce each (chain's links are checked by the checker above).
    if (solver === 'ccp') assert.equal(checked.route_pierces, contours, 'ccp: one pierce per contour');
  }
  assert.deepEqual(errors, []);
  await context.close();
});

test('a worker that dies during a job is restarted with a message; the best route stays and a new job solves', async () => {
  const { page, errors, context } = await freshPage();
  await page.selectOption('#sample', 'seven.dbs');
  await fileShown(page, 'seven');
  await start(page, 'ccp', 30);
  await page.waitForFunction(() => document.querySelector('#upper-bound')?.textContent !== '—', null, { timeout: 30000 });
  const [worker] = page.workers();
  assert.ok(worker, 'the solver runs in a worker');
  const closed = new Promise((resolve) => worker.on('close', resolve));
  // An uncaught exception in the worker: its `error` event reaches the page, as a wasm trap's does.
  await worker.evaluate(() => { setTimeout(() => { throw new Error('boom'); }, 0); });
  await page.locator('#worker-notice').waitFor({ timeout: 10000 });
  assert.match(await page.textContent('#worker-notice'),
    /^The solver stopped unexpectedly \(.*boom.*\) and was restarted; the best route received before is kept/);
  assert.equal(await page.textContent('#job-status'), 'failed: the solver stopped unexpectedly');
  const kept = await page.textContent('#upper-bound');
  assert.notEqual(kept, '—', 'the best route received is kept');
  assert.equal(await page.locator('#nest-view .route circle.pierce').count(), Number(await page.textContent('#pierces')),
    'and drawn, a mark per pierce');
  await closed; // the dead worker is terminated, not left running
  // A fresh worker answers: Continue from the kept route, then a new job.
  await page.click('#continue');
  await status(page, /^running$/);
  await page.click('#stop');
  await status(page, /^(cancelled|finished)$/);
  assert.ok(Number(await page.textContent('#upper-bound')) <= Number(kept) + 1e-9, 'never worse than kept');
  await start(page, 'nearest', 1);
  await status(page, /^finished$/);
  assert.equal(await page.locator('#worker-notice').count(), 0, 'the notice goes with the next job');
  // Unhandled: the worker's own report of the exception (its console), nothing of the page.
  assert.deepEqual(errors.filter((e) => !/boom/.test(e)), []);
  await context.close();
});

test('a panic in the worker (a wasm trap) restarts it the same way', async () => {
  const { page, errors, context } = await freshPage();
  await page.selectOption('#sample', 'seven.dbs');
  await fileShown(page, 'seven');
  await start(page, 'ccp', 30);
  await page.waitForFunction(() => document.querySelector('#upper-bound')?.textContent !== '—', null, { timeout: 30000 });
  const [worker] = page.workers();
  // Bytes gloo-worker cannot decode: its registrar panics in Rust (`expect`), which traps the
  // wasm; the trap leaves the worker's message handler as an uncaught RuntimeError.
  await worker.evaluate(() => {
    setTimeout(() => self.onmessage(new MessageEvent('message', { data: new Uint8Array([9, 9, 9, 9, 9]) })), 0);
  });
  await page.locator('#worker-notice').waitFor({ timeout: 10000 });
  assert.match(await page.textContent('#worker-notice'),
    /^The solver stopped unexpectedly \(.*(unreachable|RuntimeError).*\) and was restarted; the best route received before is kept/);
  assert.equal(await page.textContent('#job-status'), 'failed: the solver stopped unexpectedly');
  assert.notEqual(await page.textContent('#upper-bound'), '—');
  await start(page, 'nearest', 1);
  await status(page, /^finished$/);
  // The worker's own report of its panic (its console) is expected; nothing else.
  assert.deepEqual(errors.filter((e) => !/panicked|unreachable|deserialize|RuntimeError/.test(e)), []);
  await context.close();
});

test('a worker that dies while opening a file: the open fails naming the file, the document stays', async () => {
  const { page, errors, context } = await freshPage();
  const [worker] = page.workers();
  // The next message never reaches gloo's handler: the worker's `onmessage` is replaced by one
  // that throws, so the open dies unanswered.
  await worker.evaluate(() => {
    self.onmessage = () => { throw new Error('died opening'); };
  });
  await page.setInputFiles('#file-input', nest('dbs/nested.dbs'));
  await page.locator('.error[role=alert]').waitFor({ timeout: 10000 });
  assert.match(await alertText(page),
    /^nested\.dbs: the solver stopped unexpectedly while opening this \(.*died opening.*\); it was restarted and the document shown before is still open$/);
  assert.match(await page.textContent('#worker-notice'), /^The solver stopped unexpectedly \(.*died opening.*\) and was restarted; nothing was lost\.$/);
  assert.match(await page.textContent('#file-name'), /^E1X_6_01/, 'the document shown before stays');
  // The fresh worker opens the same file.
  await page.setInputFiles('#file-input', nest('dbs/nested.dbs'));
  await fileShown(page, 'nested.dbs (DBS binary)');
  assert.deepEqual(errors.filter((e) => !/died opening/.test(e)), []);
  await context.close();
});

test('a worker that stops answering is restarted after the silence limit', async () => {
  const { page, errors, context } = await freshPage();
  await start(page, 'ccp', 120);
  await page.waitForFunction(() => document.querySelector('#upper-bound')?.textContent !== '—', null, { timeout: 30000 });
  const [worker] = page.workers();
  // The worker closes itself: no error event, only silence.
  await worker.evaluate(() => { setTimeout(() => self.close(), 0); });
  await page.locator('#worker-notice').waitFor({ timeout: 45000 });
  assert.match(await page.textContent('#worker-notice'),
    /^The solver stopped unexpectedly \(it did not answer for 30 s\) and was restarted/);
  await start(page, 'nearest', 1);
  await status(page, /^finished$/);
  assert.deepEqual(errors, []);
  await context.close();
});
