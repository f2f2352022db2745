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

/** WCAG 2 contrast ratio of two computed CSS colours (`rgb(r, g, b)`). */
function contrast(a, b) {
  const luminance = (css) => {
    const [r, g, bl] = css.match(/[\d.]+/g).slice(0, 3).map((v) => {
      const c = Number(v) / 255;
      return c <= 0.03928 ? c / 12.92 : ((c + 0.055) / 1.055) ** 2.4;
    });
    return 0.2126 * r + 0.7152 * g + 0.0722 * bl;
  };
  const [hi, lo] = [luminance(a), luminance(b)].sort((x, y) => y - x);
  return (hi + 0.05) / (lo + 0.05);
}

test('every theme keeps cut against outline, idle and leads against part fill at 3:1 or more', async () => {
  const page = await app.browser.newPage({ viewport: { width: 1280, height: 720 } });
  await page.goto(app.baseUrl);
  await fileShown(page, 'E1X_6_01');
  const themes = await page.locator('#theme option').evaluateAll((options) => options.map((o) => o.value));
  for (const theme of themes) {
    await page.selectOption('#theme', theme);
    // The colours the drawing's own classes compute to, on elements of those classes.
    const colours = await page.evaluate(() => {
      const svg = document.querySelector('#nest-view');
      const probe = (tag, cls, property) => {
        const el = document.createElementNS('http://www.w3.org/2000/svg', tag);
        el.setAttribute('class', cls);
        svg.appendChild(el);
        const value = getComputedStyle(el)[property];
        el.remove();
        return value;
      };
      return {
        outline: probe('path', 'part', 'stroke'),
        fill: probe('rect', 'hatch-bg', 'fill'),
        cut: probe('path', 'cut', 'stroke'),
        idle: probe('path', 'idle', 'stroke'),
        lead: probe('path', 'lead', 'stroke'),
      };
    });
    for (const [a, b] of [['cut', 'outline'], ['idle', 'fill'], ['lead', 'fill']]) {
      const ratio = contrast(colours[a], colours[b]);
      assert.ok(ratio >= 3, `${theme}: ${a} ${colours[a]} against ${b} ${colours[b]}: ${ratio.toFixed(2)}:1`);
    }
  }
});

/** The order numbers drawn: their screen boxes and font size in CSS pixels. */
async function orderLabels(page) {
  return page.evaluate(() => [...document.querySelectorAll('#nest-view .order text')].map((t) => {
    const r = t.getBoundingClientRect();
    const scale = t.getScreenCTM().a;
    return { n: Number(t.textContent), box: [r.left, r.top, r.right, r.bottom],
      at: [Number(t.getAttribute('x')), Number(t.getAttribute('y'))],
      px: parseFloat(t.closest('g').getAttribute('font-size')) * scale };
  }));
}

test('order numbers on nested.dbs after ccp read from the back row and never overlap, normal and presentation mode', async () => {
  const context = await app.browser.newContext({ viewport: { width: 1280, height: 720 } });
  const page = await context.newPage();
  const errors = watchErrors(page);
  await page.goto(`${app.baseUrl}?sample=nested.dbs`);
  await fileShown(page, 'nested');
  await page.selectOption('#solver', 'ccp');
  await page.fill('#time-limit', '1');
  await page.dispatchEvent('#time-limit', 'change');
  await page.click('#start');
  await page.waitForFunction(() => /^(finished|cancelled)/.test(document.querySelector('#job-status')?.textContent ?? ''),
    null, { timeout: 30000 });
  const pierces = Number(await page.textContent('#pierces'));
  for (const mode of ['normal', 'presentation']) {
    if (mode === 'presentation') {
      await page.locator('#nest-view').focus();
      await page.keyboard.press('f');
      await page.waitForFunction(() => document.documentElement.hasAttribute('data-presentation'));
    }
    // The layout follows the drawing's new size.
    await page.waitForTimeout(300);
    const labels = await orderLabels(page);
    assert.ok(labels.length >= Math.min(10, pierces), `${mode}: ${labels.length} of ${pierces} numbers drawn`);
    assert.equal(labels[0].n, 1, `${mode}: the first cut is numbered`);
    for (const l of labels) assert.ok(l.px >= 18 - 1e-6, `${mode}: number ${l.n} is ${l.px.toFixed(1)} px`);
    let overlapping = 0;
    for (let i = 0; i < labels.length; i++) {
      for (let j = i + 1; j < labels.length; j++) {
        const [a, b] = [labels[i].box, labels[j].box];
        if (a[0] < b[2] && b[0] < a[2] && a[1] < b[3] && b[1] < a[3]) overlapping++;
      }
    }
    assert.equal(overlapping, 0, `${mode}: overlapping number pairs`);
    await screenshot(page, `order-labels-${mode}.png`);
  }
  // Zoomed in, the numbers keep their screen size and more of the contours in view get one.
  await page.keyboard.press('f');
  await page.waitForFunction(() => !document.documentElement.hasAttribute('data-presentation'));
  await page.waitForTimeout(300);
  const fitted = await orderLabels(page);
  await page.locator('#nest-view').focus();
  for (let k = 0; k < 6; k++) await page.keyboard.press('+');
  await page.waitForTimeout(300);
  const zoomed = await orderLabels(page);
  const [vx, vy, vw, vh] = (await page.getAttribute('#nest-view', 'viewBox')).split(' ').map(Number);
  const inView = ([x, y]) => x >= vx && x <= vx + vw && y >= vy && y <= vy + vh;
  const fittedInView = fitted.filter((l) => inView(l.at)).length;
  const piercesInView = await page.evaluate(([x0, y0, w, h]) => [...document.querySelectorAll('#nest-view .route circle.pierce')]
    .filter((c) => { const [x, y] = [Number(c.getAttribute('cx')), -Number(c.getAttribute('cy'))];
      return x >= x0 && x <= x0 + w && y >= y0 && y <= y0 + h; }).length, [vx, vy, vw, vh]);
  assert.ok(zoomed.every((l) => l.px >= 18 - 1e-6), 'zoomed: the same screen size');
  assert.ok(zoomed.length > fittedInView || fittedInView === piercesInView,
    `zoomed: ${zoomed.length} numbers, ${fittedInView} of the ${piercesInView} pierces in view had one fitted`);
  assert.deepEqual(errors, []);
  await context.close();
});

test('zoomed ×8, marks keep their screen size: a 5 mm lead-in is longer than 3 pierce-mark radii', async () => {
  const page = await app.browser.newPage({ viewport: { width: 1280, height: 720 } });
  await page.goto(app.baseUrl);
  await fileShown(page, 'E1X_6_01');
  await page.selectOption('#solver', 'nearest');
  await page.click('#start');
  await page.waitForFunction(() => document.querySelector('#job-status')?.textContent === 'finished');
  const radius = () => page.evaluate(() => document.querySelector('#nest-view .route circle.pierce').getBoundingClientRect().width / 2);
  const fitted = await radius();
  const view = page.locator('#nest-view');
  const width = async () => Number((await view.getAttribute('viewBox')).split(' ')[2]);
  const fittedWidth = await width();
  await view.focus();
  // 1.25⁹ ≈ 7.5, 1.25¹⁰ ≈ 9.3: ten key presses zoom past ×8.
  for (let k = 0; k < 10; k++) await page.keyboard.press('+');
  const zoom = fittedWidth / (await width());
  assert.ok(zoom >= 8, `zoom ×${zoom}`);
  const zoomed = await radius();
  assert.ok(Math.abs(zoomed - fitted) <= 0.05 * fitted + 0.5, `pierce mark radius ${fitted} px fitted, ${zoomed} px zoomed`);
  // A 5 mm lead-in on screen at this zoom, from the view box's scale ("meet" fitting).
  const pixelsPerMm = await page.evaluate(() => {
    const svg = document.querySelector('#nest-view');
    const [, , w, h] = svg.getAttribute('viewBox').split(' ').map(Number);
    return Math.min(svg.clientWidth / w, svg.clientHeight / h);
  });
  assert.ok(5 * pixelsPerMm > 3 * zoomed, `a 5 mm lead-in is ${(5 * pixelsPerMm).toFixed(1)} px, 3 mark radii ${(3 * zoomed).toFixed(1)} px`);
});
