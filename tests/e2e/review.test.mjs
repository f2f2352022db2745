// Issue 7, review features: drawing layers, animation, certificates, presentation mode, exports,
// state across reloads and links, Continue, comparison, keyboard use and layout.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { watchErrors, projectRoot, useApp, screenshot, cli, assertRounded } from './harness.mjs';

const app = useApp(before, after);

async function fileShown(page, name) {
  await page.waitForFunction((n) => document.querySelector('#file-name')?.textContent.includes(n),
    name, { timeout: 20000 });
}

async function solve(page, solver, seconds = 2) {
  await page.selectOption('#solver', solver);
  await page.fill('#time-limit', String(seconds));
  await page.dispatchEvent('#time-limit', 'change');
  await page.click('#start');
  await page.waitForFunction(() => document.querySelector('#job-status')?.textContent === 'finished',
    null, { timeout: 60000 });
}

/** A fresh page with empty storage, the default sample open. */
async function freshPage(viewport = { width: 1280, height: 800 }, query = '') {
  const context = await app.browser.newContext({ viewport, acceptDownloads: true });
  const page = await context.newPage();
  const errors = watchErrors(page);
  await page.goto(app.baseUrl + query);
  return { page, errors, context };
}

const subpaths = (d) => (d?.match(/M/g) ?? []).length;

/**
 * How far the head of the oracle's route (a CLI report of whole contours, the idealised model:
 * each contour is cut from its pierce point round to it) has moved by machine time `t`, from
 * `home`. Each step's cut length comes from the report's own clock: the time between two pierces
 * is the dwell, the cut at cut speed and the idle move at idle speed; the last step's is what
 * the total cut length leaves.
 */
function travelledBy(report, home, t) {
  const { idle_speed: idle, cut_speed: cut, pierce_time: dwell } = report.machine;
  const steps = report.route;
  const cuts = steps.map((s, i) => (i + 1 < steps.length
    ? (steps[i + 1].t - s.t - dwell - Math.hypot(steps[i + 1].pierce[0] - s.pierce[0], steps[i + 1].pierce[1] - s.pierce[1]) / idle) * cut
    : 0));
  cuts[cuts.length - 1] = report.cut_length - cuts.slice(0, -1).reduce((a, b) => a + b, 0);
  let distance = 0;
  let at = home;
  let clock = 0;
  for (const [i, s] of steps.entries()) {
    const leg = Math.hypot(s.pierce[0] - at[0], s.pierce[1] - at[1]);
    if (t <= clock + leg / idle) return distance + (t - clock) * idle;
    distance += leg;
    clock = s.t + dwell;
    if (t <= clock) return distance;
    if (t <= clock + cuts[i] / cut) return distance + (t - clock) * cut;
    distance += cuts[i];
    clock += cuts[i] / cut;
    at = s.pierce;
  }
  return distance;
}

test('drawing layers: arrows, cuts, order, ends, candidates, hover text; each can be hidden', async () => {
  const { page, errors, context } = await freshPage();
  await fileShown(page, 'E1X_6_01');
  assert.equal(subpaths(await page.locator('#nest-view path.arrows').getAttribute('d')), 16, 'one arrow per contour');
  await solve(page, 'nearest');
  assert.equal(subpaths(await page.locator('#nest-view .route path.cut').getAttribute('d')), 16, 'one cut subpath per contour');
  // Order numbers where they fit at their screen size, in cutting order, the first always.
  const numbers = (await page.locator('#nest-view .order text').allTextContents()).map(Number);
  assert.equal(numbers[0], 1);
  assert.ok(numbers.every((n, k) => n <= 16 && (k === 0 || n > numbers[k - 1])), `numbers ${numbers}`);
  assert.equal(await page.locator('#nest-view .ends rect.start-marker').count(), 1);
  const hover = await page.locator('#nest-view circle.pierce title').first().textContent();
  assert.match(hover, /^cut 1 of 16: part \d+ .*contour \d+.*pierce at \(-?[\d.]+, -?[\d.]+\)$/);
  assert.match(await page.locator('#nest-view path.part title').first().textContent(), /^part 1 /);
  // Candidate pierce points appear for the discrete solvers only.
  assert.equal(await page.locator('#nest-view path.candidates').getAttribute('d') ?? '', '');
  await page.selectOption('#solver', 'heuristic');
  const step = await page.inputValue('#step');
  const { candidate_points: candidates } = cli('inspect', 'data/nests/dbs-json/E1X_6_01.dbs.json', '--json', '--step', step);
  assert.equal(subpaths(await page.locator('#nest-view path.candidates').getAttribute('d')), candidates,
    `the discretisation's candidate points at ${step} mm`);
  // Hatched parts use the pattern; switching the layer off falls back to a plain fill.
  const fill = () => page.evaluate(() => getComputedStyle(document.querySelector('#nest-view path.part')).fill);
  assert.match(await fill(), /url\(.*#hatch/);
  await page.uncheck('#layer-hatch');
  assert.doesNotMatch(await fill(), /url/);
  // Every other layer hides its own elements.
  for (const [layer, selector] of [['idle', 'path.idle'], ['cuts', 'path.cut'], ['arrows', 'path.arrows'],
    ['pierces', 'g.pierces'], ['order', 'g.order'], ['ends', 'g.ends'], ['candidates', 'path.candidates']]) {
    const display = () => page.evaluate((s) => getComputedStyle(document.querySelector(`#nest-view ${s}`)).display, selector);
    assert.notEqual(await display(), 'none', `${layer} shown`);
    await page.uncheck(`#layer-${layer}`);
    assert.equal(await display(), 'none', `${layer} hidden`);
    await page.check(`#layer-${layer}`);
  }
  await screenshot(page, 'layers.png');
  assert.deepEqual(errors, []);
  await context.close();
});

test('animation: play reaches the end on the machine clock; steps and scrub move the head', async () => {
  const { page, errors, context } = await freshPage();
  await fileShown(page, 'E1X_6_01');
  await solve(page, 'nearest');
  const clock = page.locator('#anim-clock');
  const total = Number(await clock.getAttribute('data-total'));
  const oracle = cli('solve', 'data/nests/dbs-json/E1X_6_01.dbs.json', '--solver', 'nearest', '--json');
  assertRounded(total.toFixed(3), oracle.time_s, 3, 'the animation lasts the route\'s machine time');
  // Steps land on contour starts, in order.
  await page.click('#anim-next');
  const first = Number(await clock.getAttribute('data-time'));
  await page.click('#anim-next');
  const second = Number(await clock.getAttribute('data-time'));
  // The first pierce starts after the idle move from the machine's home (the sheet's lower-left
  // corner) to the oracle's first pierce point; the second comes later.
  const home = cli('inspect', 'data/nests/dbs-json/E1X_6_01.dbs.json', '--json').sheet;
  const [x1, y1] = oracle.route[0].pierce;
  assertRounded(first, Math.hypot(x1 - home[0], y1 - home[1]) / oracle.machine.idle_speed, 3, 'first pierce starts');
  assertRounded(second, oracle.route[1].t, 3, 'second pierce starts');
  assert.match(await page.locator('#anim-contour').textContent(), /^contour 2 of 16$/);
  await page.click('#anim-prev');
  assert.equal(Number(await clock.getAttribute('data-time')), first);
  // Scrub to the middle: the head moves there and the travelled path is revealed up to it.
  await page.locator('#anim-scrub').fill(String(total / 2));
  await page.waitForFunction((t) => Math.abs(Number(document.querySelector('#tool-head').dataset.machineTime) - t) < 1e-2, total / 2);
  const length = Number(await page.locator('#anim-done').getAttribute('pathLength'));
  assertRounded(length, oracle.idle_length + oracle.cut_length, 6, 'the travelled path is the route');
  // The path revealed: the chunks fully travelled (#anim-done) and the travelled part of the
  // chunk under the head (#anim-current, when shown). It must be the distance the oracle's head
  // has moved by the head's machine time.
  const revealed = await page.evaluate(() => {
    const dash = (id) => {
      const e = document.getElementById(id);
      return e.getAttribute('visibility') === 'visible' ? Number(e.getAttribute('stroke-dasharray').split(' ')[0]) : 0;
    };
    return { done: dash('anim-done'), current: dash('anim-current'), t: Number(document.querySelector('#tool-head').dataset.machineTime) };
  });
  assertRounded((revealed.done + revealed.current).toFixed(6), travelledBy(oracle, home, revealed.t), 6,
    `path revealed at ${revealed.t} s`);
  // Play at ×100 from the middle to the end.
  await page.selectOption('#anim-speed', '100');
  await page.click('#anim-play');
  await screenshot(page, 'animation.png');
  await page.waitForFunction(() => {
    const c = document.querySelector('#anim-clock');
    return c.dataset.time === c.dataset.total;
  }, null, { timeout: 30000 });
  assert.equal(await page.locator('#anim-play').getAttribute('aria-label'), 'Play', 'stopped at the end');
  assert.equal(Number(await page.locator('#tool-head').getAttribute('data-machine-time')), total);
  const [shownNow, shownTotal] = (await clock.textContent()).split(' / ');
  assert.equal(shownNow, shownTotal, 'the clock reads the total');
  const endDash = Number((await page.locator('#anim-done').getAttribute('stroke-dasharray')).split(' ')[0]);
  assert.ok(Math.abs(endDash - length) < 1e-6 * length + 1e-6, 'whole route travelled');
  assert.deepEqual(errors, []);
  await context.close();
});

test('CCP certificates on the drawing; presentation mode by button and F key', async () => {
  const { page, errors, context } = await freshPage();
  await fileShown(page, 'E1X_6_01');
  await solve(page, 'ccp', 2);
  const [certified, of] = (await page.locator('#certified-count').textContent()).split(' of ').map(Number);
  assert.equal(of, 16, 'one certificate per contour');
  const yes = subpaths(await page.locator('#nest-view .certificates path.certified').getAttribute('d'));
  const no = subpaths(await page.locator('#nest-view .certificates path.uncertified').getAttribute('d'));
  assert.equal(yes, certified, 'certified contours marked');
  assert.equal(yes + no, 16, 'the others highlighted');
  await screenshot(page, 'certificates.png');

  const fontSize = () => page.evaluate(() => parseFloat(getComputedStyle(document.body).fontSize));
  const normal = await fontSize();
  await page.click('#present');
  assert.equal(await page.getAttribute('#present', 'aria-pressed'), 'true');
  // The presentation size of style/base.css (`:root[data-presentation]`), from the normal 15 px.
  assert.equal(normal, 15);
  assert.equal(await fontSize(), 22, 'large fonts');
  await screenshot(page, 'presentation.png');
  await page.locator('#nest-view').focus();
  await page.keyboard.press('f');
  assert.equal(await page.evaluate(() => document.documentElement.hasAttribute('data-presentation')), false, 'F leaves');
  await page.keyboard.press('F');
  assert.equal(await page.evaluate(() => document.documentElement.hasAttribute('data-presentation')), true, 'F enters');
  // Typing an F into a field does not toggle it.
  await page.locator('#share-link').focus();
  await page.keyboard.press('f');
  assert.equal(await page.evaluate(() => document.documentElement.hasAttribute('data-presentation')), true);
  assert.deepEqual(errors, []);
  await context.close();
});

test('every export downloads a file that our readers open again', async () => {
  const { page, errors, context } = await freshPage();
  await fileShown(page, 'E1X_6_01');
  await solve(page, 'nearest');
  const upper = await page.locator('#upper-bound').textContent();
  const dir = fs.mkdtempSync(path.join(os.tmpdir(), 'cutroute-export-'));
  await page.click('.export summary');
  const download = async (button) => {
    const [file] = await Promise.all([page.waitForEvent('download'), page.click(button)]);
    const target = path.join(dir, file.suggestedFilename());
    await file.saveAs(target);
    return target;
  };
  const svgFile = await download('#export-svg');
  const svg = fs.readFileSync(svgFile, 'utf8');
  assert.match(svg, /^<\?xml[^>]*>\n<svg[^>]*xmlns="http:\/\/www.w3.org\/2000\/svg"/);
  assert.equal((svg.match(/class="part"/g) ?? []).length, 8, 'the view\'s 8 parts');
  assert.match(svg, /<style>/);
  // The browser's XML parser reads it back (a parse error would show as <parsererror>) with
  // the drawing and the route the app showed.
  const svgViewer = await context.newPage();
  await svgViewer.goto(`file://${svgFile}`);
  const parsed = await svgViewer.evaluate(() => ({
    root: document.documentElement.localName,
    errors: document.getElementsByTagName('parsererror').length,
    parts: document.querySelectorAll('.part').length,
  }));
  assert.deepEqual(parsed, { root: 'svg', errors: 0, parts: 8 });
  await svgViewer.close();

  const files = {
    result: await download('#export-result'),
    geometry: await download('#export-geometry'),
    dbs: await download('#export-dbs'),
  };
  // Read back through the app's own Open path (the readers run in the worker).
  for (const [kind, format] of [['geometry', 'geometry JSON'], ['dbs', 'DBS binary'], ['result', 'result JSON']]) {
    await page.setInputFiles('#file-input', files[kind]);
    await fileShown(page, `${path.basename(files[kind])} (${format})`);
    assert.equal(await page.locator('#nest-view path.part').count(), 8, `${kind}: 8 parts back`);
  }
  // The result file carries the route: same pierces, same idle length.
  assert.equal(await page.locator('#nest-view .route circle.pierce').count(), 16);
  assert.equal(Number((await page.locator('#idle-length').textContent()).replace(' mm', '')), Number(upper));
  assert.deepEqual(errors, []);
  await context.close();
});

test('settings and layers survive a reload; a link opens a sample with solver settings', async () => {
  const { page, errors, context } = await freshPage();
  await fileShown(page, 'E1X_6_01');
  await page.selectOption('#sample', 'test1.dbs.json');
  await fileShown(page, 'test1');
  await page.selectOption('#solver', 'exact');
  for (const [id, value] of [['#time-limit', '7'], ['#seed', '3'], ['#step', '20']]) {
    await page.fill(id, value);
    await page.dispatchEvent(id, 'change');
  }
  await page.selectOption('#objective', 'cost');
  await page.uncheck('#layer-arrows');
  const link = await page.inputValue('#share-link');
  assert.match(link, /\?sample=test1\.dbs\.json&solver=exact&time=7&seed=3&step=20&objective=cost$/);
  await page.reload();
  await fileShown(page, 'test1');
  assert.equal(await page.inputValue('#sample'), 'test1.dbs.json');
  assert.equal(await page.inputValue('#solver'), 'exact');
  assert.equal(await page.inputValue('#time-limit'), '7');
  assert.equal(await page.inputValue('#seed'), '3');
  assert.equal(await page.inputValue('#step'), '20');
  assert.equal(await page.inputValue('#objective'), 'cost');
  assert.equal(await page.isChecked('#layer-arrows'), false);
  assert.match(await page.getAttribute('#nest-view', 'class'), /hide-arrows/);
  assert.equal(await page.locator('#last-file').count(), 0, 'a sample was open: nothing to remind');
  // A local file is remembered by name (browsers cannot reopen it alone).
  const local = path.resolve(projectRoot, 'data', 'nests', 'dbs', 'nested.dbs');
  assert.ok(fs.existsSync(local), `missing test file ${local}`);
  await page.setInputFiles('#file-input', local);
  await fileShown(page, 'nested.dbs (DBS binary)');
  await page.reload();
  await fileShown(page, 'test1');
  assert.match(await page.locator('#last-file').textContent(), /Last time nested\.dbs was open/);
  // A file the reader refuses is not "the file open last time": the note still names the
  // last file shown, after a reload too.
  const broken = path.join(os.tmpdir(), `refused-${process.pid}.dbs`);
  fs.writeFileSync(broken, fs.readFileSync(local).subarray(0, 777));
  await page.setInputFiles('#file-input', broken);
  await page.locator('.error[role=alert]').waitFor({ timeout: 10000 });
  assert.match(await page.locator('#last-file').textContent(), /Last time nested\.dbs was open/);
  await page.reload();
  await fileShown(page, 'test1');
  assert.match(await page.locator('#last-file').textContent(), /Last time nested\.dbs was open/);
  await page.selectOption('#sample', 'E1X_6_01.dbs.json');
  await fileShown(page, 'E1X_6_01');
  assert.equal(await page.locator('#last-file').count(), 0, 'choosing a sample forgets the file');
  await context.close();

  // A link in a fresh browser profile.
  const fresh = await freshPage({ width: 1280, height: 800 }, '?sample=nested.dbs&solver=ccp&time=4');
  await fileShown(fresh.page, 'nested.dbs');
  assert.equal(await fresh.page.inputValue('#solver'), 'ccp');
  assert.equal(await fresh.page.inputValue('#time-limit'), '4');
  assert.deepEqual([...errors, ...fresh.errors], []);
  await fresh.context.close();
});

test('Continue restarts from the best result; kept results are compared and overlaid', async () => {
  const { page, errors, context } = await freshPage();
  await fileShown(page, 'E1X_6_01');
  assert.equal(await page.isDisabled('#continue'), true, 'nothing to continue yet');
  await solve(page, 'nearest');
  await page.click('#keep-result');
  await solve(page, 'heuristic', 1);
  const first = Number(await page.locator('#upper-bound').textContent());
  const elapsed = parseFloat(await page.locator('#elapsed').textContent());
  await page.click('#continue');
  await page.waitForFunction(() => document.querySelector('#job-status')?.textContent === 'finished',
    null, { timeout: 30000 });
  const second = Number(await page.locator('#upper-bound').textContent());
  assert.ok(second <= first, `continued result ${second} is no worse than ${first}`);
  assert.ok(parseFloat(await page.locator('#elapsed').textContent()) > elapsed, 'time adds up');
  await page.click('#keep-result');
  const rows = page.locator('#compare-table tbody tr');
  assert.equal(await rows.count(), 2);
  assert.equal(await rows.nth(1).locator('td').nth(1).textContent(), 'Discrete heuristic (ALNS)');
  const idles = (await page.locator('#compare-table .kept-idle').allTextContents()).map(Number);
  const nearest = cli('solve', 'data/nests/dbs-json/E1X_6_01.dbs.json', '--solver', 'nearest', '--json');
  assertRounded(idles[0], nearest.idle_length, 1, 'the kept nearest-neighbour route');
  assert.equal(idles[1], second, 'the kept figure is the result shown');
  const excess = await page.locator('#compare-table tbody tr td:nth-child(4)').allTextContents();
  assert.ok(excess.includes('+0.0 %'), `the best result is 0 % over the best: ${excess}`);
  await page.locator('.kept-overlay').nth(0).check();
  await page.locator('.kept-overlay').nth(1).check();
  assert.equal(await page.locator('#nest-view path.compare-a').count(), 1);
  assert.equal(await page.locator('#nest-view path.compare-b').count(), 1);
  await screenshot(page, 'compare.png');
  assert.deepEqual(errors, []);
  await context.close();
});

for (const [width, height] of [[1024, 768], [1920, 1080], [3840, 2160]]) {
  test(`keyboard only and layout at ${width}×${height}`, async () => {
    const { page, errors, context } = await freshPage({ width, height });
    await fileShown(page, 'E1X_6_01');
    // No horizontal scroll.
    const scroll = await page.evaluate(() => [document.documentElement.scrollWidth, document.documentElement.clientWidth]);
    assert.equal(scroll[0], scroll[1], 'no horizontal scroll');
    // The drawing takes the room the screen gives it (a projector's too).
    // The drawing fills the whole rectangle left of the statistics panel (18rem of 15 px, 14rem
    // on screens up to 1100 px, style/base.css), below the toolbars and above the animation bar,
    // which ends at the bottom of the screen.
    const box = (selector) => page.locator(selector).boundingBox();
    const [drawing, panel, stats, bar] = await Promise.all(['#nest-view', '.solver-panel', '.stats', '.animation'].map(box));
    const near = (a, b, what) => assert.ok(Math.abs(a - b) < 0.5, `${what}: ${a} vs ${b} on ${width}×${height}`);
    near(stats.width, (width <= 1100 ? 14 : 18) * 15, 'statistics panel width');
    near(stats.x + stats.width, width, 'statistics panel at the right edge');
    near(drawing.x, 0, 'drawing at the left edge');
    near(drawing.width, width - stats.width, 'drawing width');
    near(drawing.y, panel.y + panel.height, 'drawing below the toolbars');
    near(drawing.y + drawing.height, bar.y, 'drawing above the animation bar');
    near(bar.y + bar.height, height, 'animation bar at the bottom');
    // Every control has a label (label element, aria-label, title or text).
    const unlabelled = await page.evaluate(() => [...document.querySelectorAll('input, select, button, textarea')]
      .filter((e) => !(e.labels?.length || e.getAttribute('aria-label') || e.title || e.textContent.trim()))
      .map((e) => e.outerHTML.slice(0, 80)));
    assert.deepEqual(unlabelled, []);
    // Enter on a focused button starts the job (the default solver is the baseline).
    await page.locator('#start').focus();
    await page.keyboard.press('Enter');
    await page.waitForFunction(() => document.querySelector('#job-status')?.textContent === 'finished', null, { timeout: 20000 });
    // Tab walks the controls in reading order and focus is visible.
    await page.locator('#sample').focus();
    const seen = ['sample'];
    for (let i = 0; i < 40; i++) {
      await page.keyboard.press('Tab');
      const info = await page.evaluate(() => {
        const e = document.activeElement;
        return { id: e.id, outline: getComputedStyle(e).outlineStyle };
      });
      if (info.id) seen.push(info.id);
      if (['start', 'nest-view', 'anim-play'].includes(info.id)) assert.notEqual(info.outline, 'none', `${info.id} shows focus`);
    }
    for (const id of ['theme', 'solver', 'time-limit', 'start', 'nest-view', 'anim-play', 'anim-speed']) {
      assert.ok(seen.includes(id), `Tab reaches #${id}: ${seen.join(' ')}`);
    }
    assert.ok(seen.indexOf('solver') < seen.indexOf('start') && seen.indexOf('start') < seen.indexOf('nest-view')
      && seen.indexOf('nest-view') < seen.indexOf('anim-play'), `reading order: ${seen.join(' ')}`);
    // Space plays and pauses the animation.
    await page.locator('#anim-play').focus();
    await page.keyboard.press('Space');
    await page.waitForFunction(() => Number(document.querySelector('#anim-clock').dataset.time) > 0);
    assert.equal(await page.locator('#anim-play').getAttribute('aria-label'), 'Pause');
    await page.keyboard.press('Space');
    await page.waitForFunction(() => document.querySelector('#anim-play').getAttribute('aria-label') === 'Play');
    await screenshot(page, `layout-${width}x${height}.png`);
    const after = await page.evaluate(() => [document.documentElement.scrollWidth, document.documentElement.clientWidth]);
    assert.equal(after[0], after[1], 'no horizontal scroll with a route');
    assert.deepEqual(errors, []);
    await context.close();
  });
}

test('several files at once: a task JSON is combined with its result file', async () => {
  const { page, errors, context } = await freshPage();
  await fileShown(page, 'E1X_6_01');
  const nests = path.resolve(projectRoot, 'data', 'nests');
  const task = path.join(nests, 'task-json', 'E1X_6_01.task.json');
  const result = path.join(nests, 'result-json', 'E1X_6_01.result.json');
  for (const f of [task, result]) assert.ok(fs.existsSync(f), `missing test file ${f}`);
  // The task's speeds replace edited ones.
  await page.click('.machine summary');
  await page.fill('#idle-speed', '123');
  await page.dispatchEvent('#idle-speed', 'change');
  await page.setInputFiles('#file-input', [task, result]);
  // One document from the batch, named for its files in the order given.
  await fileShown(page, 'E1X_6_01.task.json + E1X_6_01.result.json (task JSON + result JSON)');
  assert.equal(await page.inputValue('#idle-speed'), '500');
  assert.equal(await page.locator('#nest-view path.part').count(), 8);
  // The result's route is drawn: one pierce wherever the file's toolpath goes from air to cut.
  const moves = JSON.parse(fs.readFileSync(result, 'utf8')).results.toolpath.map((m) => m.mode);
  const filePierces = moves.filter((m, i) => m.startsWith('cut') && (i === 0 || moves[i - 1] === 'air')).length;
  assert.equal(await page.locator('#nest-view .route circle.pierce').count(), filePierces, 'the result\'s route is drawn');
  // The combined problem can be solved.
  await solve(page, 'nearest');
  assert.equal(await page.locator('#nest-view .route circle.pierce').count(), 16);
  // A task alone has no geometry: a plain error, and the app stays usable.
  await page.setInputFiles('#file-input', task);
  await page.locator('.error[role=alert]').waitFor({ timeout: 10000 });
  assert.match(await page.locator('.error[role=alert]').textContent(), /E1X_6_01\.task\.json/);
  assert.deepEqual(errors, []);
  await context.close();
});

test('standalone HTML and G-code exports; G-code options and preview', async () => {
  const { page, errors, context } = await freshPage();
  await fileShown(page, 'E1X_6_01');
  await solve(page, 'nearest');
  const dir = fs.mkdtempSync(path.join(os.tmpdir(), 'cutroute-export-'));
  await page.click('.export summary');
  const download = async (button) => {
    const [file] = await Promise.all([page.waitForEvent('download'), page.click(button)]);
    const target = path.join(dir, file.suggestedFilename());
    await file.saveAs(target);
    return target;
  };
  // The HTML page needs nothing but itself: no external script, style or image.
  const htmlFile = await download('#export-html');
  const html = fs.readFileSync(htmlFile, 'utf8');
  assert.match(html, /^<!DOCTYPE html>/i);
  assert.doesNotMatch(html, /(src|href)\s*=\s*["']?(https?:|\/\/)/i, 'standalone');
  const viewer = await context.newPage();
  const viewerErrors = watchErrors(viewer);
  await viewer.goto(`file://${htmlFile}`);
  assert.equal(await viewer.locator('svg path').count(), (html.match(/<path[\s>]/g) ?? []).length, 'the page draws every path it holds');
  assert.equal(await viewer.locator('svg path.part').count(), 8, 'the page draws the 8 parts');
  assert.match(await viewer.title(), /E1X_6_01/);
  assert.deepEqual(viewerErrors, []);
  await viewer.close();

  // Preview: the first lines of the program, absolute by default.
  await page.click('#gcode-preview-button');
  const preview = await page.locator('#gcode-preview').textContent();
  const lines = preview.split('\n');
  assert.ok(lines.includes('G90'), preview);
  // The preview is the first 12 lines of the very program the button writes.
  const absolute = fs.readFileSync(await download('#export-gcode'), 'utf8').split('\n');
  assert.deepEqual(lines, absolute.slice(0, 12), 'the preview shows the program\'s first lines');
  // Options reach the post-processor: incremental, R arcs, custom torch codes and dwell.
  await page.selectOption('#gcode-distance', 'incremental');
  await page.selectOption('#gcode-arcs', 'r');
  for (const [id, value] of [['#gcode-torch-on', 'M07'], ['#gcode-torch-off', 'M08'], ['#gcode-dwell', '2']]) {
    await page.fill(id, value);
    await page.dispatchEvent(id, 'change');
  }
  const gcode = fs.readFileSync(await download('#export-gcode'), 'utf8');
  const program = gcode.split('\n').map((l) => l.trim());
  assert.ok(program.includes('G91'), 'incremental');
  // The one absolute move positions the head at the route's start before G91.
  assert.ok(program.lastIndexOf('G90') < program.indexOf('G91'), 'absolute only before G91');
  assert.equal(program.filter((l) => l === 'M07').length, 16, 'torch on once per pierce');
  assert.equal(program.filter((l) => l === 'M08').length, 16, 'torch off after every contour');
  assert.equal(program.filter((l) => l === 'G04 P2.000').length, 16, 'pierce dwell');
  assert.ok(program.some((l) => /^G0[23] .*R[\d.]+/.test(l)), 'arcs with R');
  assert.ok(!program.some((l) => /^G0[23] .* I/.test(l)), 'no I/J arcs');
  assert.match(await page.locator('#gcode-preview').textContent(), /G91/, 'preview follows the options');
  assert.match(await page.locator('#export-status').textContent(), /saved E1X_6_01\.nc/);
  assert.deepEqual(errors, []);
  await context.close();
});
