// Machine profiles and G-code presets in the page (issue 18, item 6): a profile exported by the
// page is the CLI's `--profile` file (the CLI reads it and prices the route as the page does),
// importing it gives back the same numbers, saved profiles survive a reload, and every
// post-processor preset's program exported by the page is read back by the project's reader.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { execFileSync } from 'node:child_process';
import { watchErrors, projectRoot, useApp, cliBinary } from './harness.mjs';

const app = useApp(before, after);
const sample = path.join(projectRoot, 'assets', 'samples', 'E1X_6_01.dbs.json');

/** The release CLI: the oracle outside the page. */
function cutroute(...args) {
  const binary = cliBinary();
  return JSON.parse(execFileSync(binary, args, { encoding: 'utf8', maxBuffer: 64 << 20 }));
}

async function freshPage() {
  const context = await app.browser.newContext({ viewport: { width: 1280, height: 800 }, acceptDownloads: true });
  const page = await context.newPage();
  const errors = watchErrors(page);
  await page.goto(app.baseUrl);
  await page.waitForFunction(() => document.querySelector('#file-name')?.textContent.includes('E1X_6_01'),
    null, { timeout: 20000 });
  const dir = fs.mkdtempSync(path.join(os.tmpdir(), 'cutroute-profiles-'));
  const download = async (button) => {
    const [file] = await Promise.all([page.waitForEvent('download'), page.click(button)]);
    const target = path.join(dir, file.suggestedFilename());
    await file.saveAs(target);
    return target;
  };
  return { context, page, errors, download };
}

async function setNumber(page, selector, value) {
  await page.fill(selector, String(value));
  await page.locator(selector).dispatchEvent('change');
}

const FIELDS = {
  'idle-speed': 'idle_speed', 'cut-speed': 'cut_speed', 'pierce-time': 'pierce_time',
  'idle-price': 'idle_price_per_metre', 'cut-price': 'cut_price_per_metre', 'pierce-price': 'pierce_price',
};

test('a profile round trip: export, the CLI reads it, import gives the same numbers, saved ones survive a reload', async () => {
  const { context, page, errors, download } = await freshPage();
  await page.locator('details.machine:has(#cut-speed) > summary').click();
  const numbers = { 'idle-speed': 400, 'cut-speed': 25, 'pierce-time': 0.8, 'idle-price': 0.05, 'cut-price': 1.2, 'pierce-price': 0.3 };
  for (const [id, value] of Object.entries(numbers)) await setNumber(page, `#${id}`, value);
  await page.locator('details.export summary').click();
  await page.selectOption('#gcode-preset', 'qtplasmac');
  assert.equal(await page.inputValue('#gcode-torch-on'), 'M03 $0 S1', 'the preset fills the fields');
  await page.fill('#gcode-footer', 'M30\n%');
  await page.locator('#gcode-footer').dispatchEvent('change');
  await page.locator('#profiles summary').click();
  await page.fill('#profile-name', 'Plasma 3');
  await page.locator('#profile-name').dispatchEvent('change');
  const file = await download('#profile-export');
  const profile = JSON.parse(fs.readFileSync(file, 'utf8'));
  assert.equal(profile.name, 'Plasma 3');
  for (const [id, key] of Object.entries(FIELDS)) assert.equal(profile.machine[key], numbers[id], key);
  assert.equal(profile.gcode_preset, 'qtplasmac');
  assert.deepEqual(profile.gcode_footer, ['M30', '%']);
  assert.equal(profile.gcode_header, null, "the preset's own header is not repeated");

  // The CLI reads the page's file and prices the same route as the page.
  await page.selectOption('#solver', 'nearest');
  await page.click('#start');
  await page.waitForFunction(() => document.querySelector('#job-status')?.textContent === 'finished', null, { timeout: 20000 });
  const report = cutroute('solve', sample, '--solver', 'nearest', '--json', '--profile', file);
  for (const [id, key] of Object.entries(FIELDS)) assert.equal(report.machine[key], numbers[id], `CLI ${key}`);
  const pageCost = Number(await page.getAttribute('#route-cost', 'data-value'));
  assert.ok(Math.abs(pageCost - report.cost) < 1e-3, `cost: page ${pageCost}, CLI ${report.cost}`);
  // The CLI writes the profile's dialect with its footer.
  const program = path.join(path.dirname(file), 'cli.nc');
  execFileSync(cliBinary(),
    ['convert', sample, program, '--solver', 'nearest', '--profile', file]);
  const text = fs.readFileSync(program, 'utf8');
  assert.match(text, /M03 \$0 S1/);
  assert.match(text.trimEnd(), /M30\n%$/);

  // Other numbers, then the import: the profile's numbers and dialect come back.
  for (const id of Object.keys(numbers)) await setNumber(page, `#${id}`, 9);
  await page.selectOption('#gcode-preset', 'fanuc');
  await page.setInputFiles('#profile-import', file);
  await page.waitForFunction(() => document.querySelector('#profile-status')?.textContent.includes('Plasma 3'));
  for (const [id, value] of Object.entries(numbers)) assert.equal(Number(await page.inputValue(`#${id}`)), value, id);
  assert.equal(await page.inputValue('#gcode-preset'), 'qtplasmac');
  assert.equal(await page.inputValue('#gcode-footer'), 'M30\n%');
  // The import exported again is the same file.
  const again = JSON.parse(fs.readFileSync(await download('#profile-export'), 'utf8'));
  assert.deepEqual(again, profile);

  // Saved profiles are remembered: after a reload the list offers it and picking it applies it.
  await page.click('#profile-save');
  await page.reload();
  await page.waitForFunction(() => document.querySelector('#file-name')?.textContent.includes('E1X_6_01'), null, { timeout: 20000 });
  await page.locator('details.machine:has(#cut-speed) > summary').click();
  await setNumber(page, '#cut-speed', 11);
  await page.locator('#profiles summary').click();
  await page.selectOption('#profile-select', 'Plasma 3');
  assert.equal(Number(await page.inputValue('#cut-speed')), 25);

  // A file the CLI would refuse is refused here too, in its words.
  const bad = path.join(path.dirname(file), 'bad.profile.json');
  fs.writeFileSync(bad, JSON.stringify({ ...profile, gcode_presset: 'fanuc' }));
  await page.setInputFiles('#profile-import', bad);
  await page.waitForFunction(() => document.querySelector('#profile-status')?.textContent.includes('gcode_presset'));
  assert.deepEqual(errors, []);
  await context.close();
});

test("every preset's G-code exported by the page is read back by the project's reader", async () => {
  const { context, page, errors, download } = await freshPage();
  await page.selectOption('#solver', 'nearest');
  await page.click('#start');
  await page.waitForFunction(() => document.querySelector('#job-status')?.textContent === 'finished', null, { timeout: 20000 });
  const pierces = Number(await page.textContent('#pierces'));
  assert.ok(pierces > 0);
  await page.locator('details.export summary').click();
  const presets = await page.locator('#gcode-preset option').evaluateAll((o) => o.map((e) => e.value));
  assert.deepEqual(presets, ['generic', 'grbl-laser', 'qtplasmac', 'mach3-plasma', 'fanuc', 'kometa-2p32m']);
  for (const preset of presets) {
    await page.selectOption('#gcode-preset', preset);
    const file = await download('#export-gcode');
    // Read in the preset's own dialect (its torch codes: «Комета» switches with M71/M74).
    const back = cutroute('inspect', file, '--json', '--preset', preset);
    assert.equal(back.format, 'G-code', preset);
    assert.equal(back.route_pierces, pierces, `${preset}: pierces read back`);
    assert.deepEqual(back.route_problems ?? [], [], preset);
  }
  assert.deepEqual(errors, []);
  await context.close();
});
