// Links (issue 18, item 3): `?file=URL` opens a hosted nest, the address bar follows the page's
// state, a copied link reopens the same state in a fresh browser, and the lecture gallery
// (the bundled list, and another list by `?lecture=URL`) opens its nests with their settings.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import http from 'node:http';
import os from 'node:os';
import path from 'node:path';
import { execFileSync } from 'node:child_process';
import { watchErrors, projectRoot, distDir, useApp, screenshot, cliBinary } from './harness.mjs';

const app = useApp(before, after);
const nests = path.join(projectRoot, 'data', 'nests');

/** Another origin serving `root`, with CORS allowed or not. */
async function otherHost(root, cors) {
  const server = http.createServer((req, res) => {
    const file = path.join(root, decodeURIComponent(new URL(req.url, 'http://x').pathname));
    if (!file.startsWith(root) || !fs.existsSync(file) || fs.statSync(file).isDirectory()) {
      res.writeHead(404, cors ? { 'access-control-allow-origin': '*' } : {});
      res.end('not found');
      return;
    }
    res.writeHead(200, cors ? { 'access-control-allow-origin': '*' } : {});
    res.end(fs.readFileSync(file));
  });
  await new Promise((resolve) => server.listen(0, '127.0.0.1', resolve));
  return { server, url: `http://127.0.0.1:${server.address().port}/` };
}

/** The oracle: the project's reader on the same file, through the CLI. */
function inspect(file) {
  const binary = cliBinary();
  return JSON.parse(execFileSync(binary, ['inspect', file, '--json'], { encoding: 'utf8' }));
}

async function fileShown(page, name) {
  await page.waitForFunction((n) => document.querySelector('#file-name')?.textContent.includes(n),
    name, { timeout: 20000 });
}

test('?file= opens a nest hosted next to the app and one on another host that allows it', async () => {
  const cors = await otherHost(nests, true);
  const closed = await otherHost(nests, false);
  try {
    const context = await app.browser.newContext({ viewport: { width: 1280, height: 800 } });
    const page = await context.newPage();
    const errors = watchErrors(page);
    // Next to the app: a path relative to the page.
    await page.goto(`${app.baseUrl}?file=assets/samples/seven.dbs`);
    await fileShown(page, 'seven.dbs');
    const seven = inspect(path.join(projectRoot, 'assets', 'samples', 'seven.dbs'));
    const sheet = seven.parts - await page.locator('#nest-view path.part').count();
    assert.ok(sheet === 0 || sheet === 1, 'the page draws the parts the reader reads');
    assert.match(new URL(page.url()).search, /file=assets%2Fsamples%2Fseven\.dbs/, 'the address keeps the file');
    assert.doesNotMatch(new URL(page.url()).search, /sample=/);

    // Another host that allows it (CORS).
    const hosted = `${cors.url}dxf/propeller.dxf`;
    await page.goto(`${app.baseUrl}?file=${encodeURIComponent(hosted)}&solver=ccp`);
    await fileShown(page, 'propeller.dxf');
    assert.equal(await page.locator('#nest-view path.part').count(),
      inspect(path.join(nests, 'dxf', 'propeller.dxf')).parts);
    assert.equal(await page.inputValue('#solver'), 'ccp');
    assert.equal(new URL(page.url()).searchParams.get('file'), hosted);
    assert.deepEqual(errors, []);

    // What cannot be fetched is said, as a dropped file's error is: a missing file, and a host
    // that does not allow it.
    const missing = await context.newPage();
    await missing.goto(`${app.baseUrl}?file=${encodeURIComponent(`${cors.url}no-such.dbs`)}`);
    await missing.locator('.error[role=alert]').waitFor({ timeout: 10000 });
    assert.match(await missing.locator('.error[role=alert]').textContent(), /no-such\.dbs: HTTP 404/);
    const refused = await context.newPage();
    await refused.goto(`${app.baseUrl}?file=${encodeURIComponent(`${closed.url}dbs/nested.dbs`)}`);
    await refused.locator('.error[role=alert]').waitFor({ timeout: 10000 });
    assert.match(await refused.locator('.error[role=alert]').textContent(), /nested\.dbs/);
    // A file that is not a nest: the worker's reader refuses it, located, as for a dropped file.
    const broken = await context.newPage();
    await broken.goto(`${app.baseUrl}?file=${encodeURIComponent(`${cors.url}schemas/dbs.json`)}`);
    await broken.locator('.error[role=alert]').waitFor({ timeout: 10000 });
    assert.match(await broken.locator('.error[role=alert]').textContent(), /dbs\.json/);
    await context.close();
  } finally {
    cors.server.close();
    closed.server.close();
  }
});

test('the address bar follows the state and a copied link reopens it in a fresh browser', async () => {
  const context = await app.browser.newContext({ viewport: { width: 1280, height: 800 } });
  await context.grantPermissions(['clipboard-read', 'clipboard-write'], { origin: new URL(app.baseUrl).origin });
  const page = await context.newPage();
  const errors = watchErrors(page);
  await page.goto(app.baseUrl);
  await fileShown(page, 'E1X_6_01');
  await page.selectOption('#sample', 'nested.dbs');
  await fileShown(page, 'nested.dbs');
  await page.selectOption('#solver', 'ccp');
  await page.selectOption('#objective', 'cost');
  await page.fill('#time-limit', '2.5');
  await page.locator('#time-limit').dispatchEvent('change');
  await page.fill('#seed', '7');
  await page.locator('#seed').dispatchEvent('change');
  await page.locator('details.machine:has(#cut-speed) > summary').click();
  await page.fill('#cut-speed', '25');
  await page.locator('#cut-speed').dispatchEvent('change');
  await page.fill('#pierce-price', '0.3');
  await page.locator('#pierce-price').dispatchEvent('change');
  await page.waitForFunction(() => location.search.includes('cut_speed=25') && location.search.includes('pierce_price=0.3'));
  const address = page.url();
  assert.equal(await page.inputValue('#share-link'), address, 'the link field is the address');

  await page.click('#copy-link');
  await page.waitForFunction(() => document.querySelector('#copy-link-status')?.textContent.trim() !== '');
  const copied = await page.evaluate(() => navigator.clipboard.readText());
  assert.equal(copied, address);
  assert.deepEqual(errors, []);

  // A fresh browser (nothing remembered) opening the copied link shows the same state.
  const fresh = await app.browser.newContext({ viewport: { width: 1280, height: 800 } });
  const other = await fresh.newPage();
  const otherErrors = watchErrors(other);
  await other.goto(copied);
  await fileShown(other, 'nested.dbs');
  const state = async (p) => ({
    sample: await p.inputValue('#sample'),
    solver: await p.inputValue('#solver'),
    objective: await p.inputValue('#objective'),
    time: await p.inputValue('#time-limit'),
    seed: await p.inputValue('#seed'),
    cut: await p.inputValue('#cut-speed'),
    pierce: await p.inputValue('#pierce-price'),
    idle: await p.inputValue('#idle-speed'),
  });
  const expected = await state(page);
  assert.deepEqual(expected, {
    sample: 'nested.dbs', solver: 'ccp', objective: 'cost', time: '2.5', seed: '7', cut: '25',
    pierce: '0.3', idle: '500',
  });
  assert.deepEqual(await state(other), expected);
  assert.equal(other.url(), copied, 'the reopened page keeps the link');
  // The same machine gives the same route cost once both pages have run the same job (a
  // deterministic one: a time-limited ccp run depends on the machine's load).
  for (const p of [page, other]) {
    await p.selectOption('#solver', 'nearest');
    await p.click('#start');
    await p.waitForFunction(() => document.querySelector('#job-status')?.textContent === 'finished', null, { timeout: 30000 });
  }
  assert.equal(await other.getAttribute('#route-cost', 'data-value'), await page.getAttribute('#route-cost', 'data-value'));
  assert.deepEqual(otherErrors, []);
  await fresh.close();

  // Without clipboard permission the link's field is selected for Ctrl+C instead.
  const denied = await app.browser.newContext({ viewport: { width: 1280, height: 800 } });
  const plain = await denied.newPage();
  await plain.goto(app.baseUrl);
  await fileShown(plain, 'E1X_6_01');
  await plain.evaluate(() => Object.defineProperty(navigator, 'clipboard', { value: undefined }));
  await plain.click('#copy-link');
  await plain.waitForFunction(() => document.activeElement?.id === 'share-link');
  const selected = await plain.evaluate(() => {
    const e = document.activeElement;
    return e.value.slice(e.selectionStart, e.selectionEnd);
  });
  assert.equal(selected, plain.url());
  await denied.close();
  await context.close();
});

test('the lecture gallery opens the bundled samples with their settings, and ?lecture= another list', async () => {
  const dir = fs.mkdtempSync(path.join(os.tmpdir(), 'cutroute-lecture-'));
  fs.copyFileSync(path.join(nests, 'dbs', 'nested.dbs'), path.join(dir, 'holes.dbs'));
  fs.writeFileSync(path.join(dir, 'course.json'), JSON.stringify({
    title: 'Course 7',
    lectures: [{ title: 'Holes', file: 'holes.dbs', solver: 'exact', settings: { time: 4, step: 15, cut_speed: 30 } }],
  }));
  const host = await otherHost(dir, true);
  try {
    const context = await app.browser.newContext({ viewport: { width: 1280, height: 800 } });
    const page = await context.newPage();
    const errors = watchErrors(page);
    await page.goto(app.baseUrl);
    await fileShown(page, 'E1X_6_01');
    await page.locator('#gallery summary').click();
    const bundled = JSON.parse(fs.readFileSync(path.join(projectRoot, 'assets', 'lectures.json'), 'utf8'));
    assert.equal(await page.locator('#gallery button.lecture').count(), bundled.lectures.length);
    const exact = bundled.lectures.findIndex((l) => l.solver === 'exact');
    await page.click(`#lecture-${exact}`);
    await fileShown(page, path.basename(bundled.lectures[exact].file));
    assert.equal(await page.inputValue('#solver'), 'exact');
    assert.equal(Number(await page.inputValue('#step')), bundled.lectures[exact].settings.step);
    assert.equal(Number(await page.inputValue('#time-limit')), bundled.lectures[exact].settings.time);
    assert.match(page.url(), /sample=nested\.dbs/, 'a bundled sample stays a sample in the link');
    await screenshot(page, 'gallery.png');
    assert.deepEqual(errors, []);

    await page.goto(`${app.baseUrl}?lecture=${encodeURIComponent(`${host.url}course.json`)}`);
    await page.locator('#gallery summary').click();
    await page.waitForFunction(() => document.querySelector('#gallery-title')?.textContent === 'Course 7');
    await page.click('#lecture-0');
    await fileShown(page, 'holes.dbs');
    assert.equal(await page.inputValue('#solver'), 'exact');
    assert.equal(await page.inputValue('#step'), '15');
    await page.locator('details.machine:has(#cut-speed) > summary').click();
    assert.equal(await page.inputValue('#cut-speed'), '30');
    assert.equal(new URL(page.url()).searchParams.get('file'), `${host.url}holes.dbs`);
    assert.equal(await page.locator('#nest-view path.part').count(), 56);
    assert.deepEqual(errors, []);
    await context.close();
  } finally {
    host.server.close();
  }
});

test('the single-file page from file:// carries the bundled lecture list and opens its cards', async () => {
  const file = path.join(distDir, 'cutroute.html');
  assert.ok(fs.existsSync(file), `no ${file}: run scripts/build-release.sh`);
  const alone = fs.mkdtempSync(path.join(fs.realpathSync(os.tmpdir()), 'cutroute-usb-'));
  fs.copyFileSync(file, path.join(alone, 'cutroute.html'));
  const page = await app.browser.newPage({ viewport: { width: 1280, height: 800 } });
  const errors = watchErrors(page);
  await page.goto(`file://${path.join(alone, 'cutroute.html')}`);
  await fileShown(page, 'E1X_6_01');
  await page.locator('#gallery summary').click();
  const bundled = JSON.parse(fs.readFileSync(path.join(projectRoot, 'assets', 'lectures.json'), 'utf8'));
  await page.waitForFunction((n) => document.querySelectorAll('#gallery button.lecture').length === n, bundled.lectures.length);
  const seven = bundled.lectures.findIndex((l) => l.file.endsWith('seven.dbs'));
  await page.click(`#lecture-${seven}`);
  await fileShown(page, 'seven.dbs');
  assert.equal(await page.inputValue('#solver'), bundled.lectures[seven].solver);
  assert.deepEqual(errors, []);
  await page.close();
});

test('a hosted multi-sheet project: &sheet=N opens that sheet and the link follows the sheet picker', async () => {
  const host = await otherHost(nests, true);
  try {
    const file = path.join(nests, 'tflex-multi', 'two-sheets.tfnesting');
    const url = `${host.url}tflex-multi/two-sheets.tfnesting`;
    const context = await app.browser.newContext({ viewport: { width: 1280, height: 800 } });
    const page = await context.newPage();
    const errors = watchErrors(page);
    const parts = async () => (await page.locator('#nest-view path.part').count())
      + ((await page.getAttribute('#nest-view path.sheet', 'd'))?.length > 0 ? 1 : 0);
    // Sheets count from 1 in links, as the CLI's --sheet does.
    await page.goto(`${app.baseUrl}?file=${encodeURIComponent(url)}&sheet=2`);
    await fileShown(page, 'two-sheets');
    await page.waitForFunction(() => document.querySelector('#sheet')?.value === '1');
    assert.equal(await parts(), inspect2(file, '2').parts);
    assert.equal(new URL(page.url()).searchParams.get('sheet'), '2');
    await page.selectOption('#sheet', '0');
    await page.waitForFunction(() => !new URL(location.href).searchParams.has('sheet'));
    assert.equal(await parts(), inspect2(file, '1').parts);
    await page.selectOption('#sheet', '1');
    await page.waitForFunction(() => new URL(location.href).searchParams.get('sheet') === '2');
    assert.deepEqual(errors, []);
    await context.close();
  } finally {
    host.server.close();
  }
});

function inspect2(file, sheet) {
  const binary = cliBinary();
  return JSON.parse(execFileSync(binary, ['inspect', file, '--json', '--sheet', sheet], { encoding: 'utf8' }));
}
