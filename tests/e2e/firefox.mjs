// A small WebDriver BiDi client for the system's Firefox (Debian's firefox-esr), so the pages
// that must open in Firefox too are tested there. Playwright drives only its own patched
// Firefox, which it would download; BiDi is the standard protocol stock Firefox speaks.
import { spawn } from 'node:child_process';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import WebSocket from 'ws';

const FIREFOX = process.env.FIREFOX ?? 'firefox-esr';

/** Starts a headless Firefox with a fresh profile; resolves to a `FirefoxPage`. */
export async function launchFirefox() {
  const profile = fs.mkdtempSync(path.join(os.tmpdir(), 'cutroute-firefox-'));
  // English pages, as the tests read English texts, whatever the machine's locale.
  fs.writeFileSync(path.join(profile, 'user.js'), 'user_pref("intl.accept_languages", "en-US");\n');
  const child = spawn(FIREFOX, ['--headless', '--no-remote', '--profile', profile, '--remote-debugging-port=0'], {
    stdio: ['ignore', 'pipe', 'pipe'],
  });
  const url = await new Promise((resolve, reject) => {
    let out = '';
    const timer = setTimeout(() => reject(new Error(`${FIREFOX} did not offer WebDriver BiDi in 60 s:\n${out}`)), 60000);
    const read = (chunk) => {
      out += chunk;
      const m = out.match(/WebDriver BiDi listening on (ws:\/\/\S+)/);
      if (m) { clearTimeout(timer); resolve(m[1]); }
    };
    child.stdout.on('data', read);
    child.stderr.on('data', read);
    child.on('error', (e) => { clearTimeout(timer); reject(new Error(`cannot start ${FIREFOX} (scripts/setup.sh installs it): ${e.message}`)); });
    child.on('exit', (code) => { clearTimeout(timer); reject(new Error(`${FIREFOX} exited with ${code}:\n${out}`)); });
  });
  const socket = new WebSocket(`${url}/session`);
  await new Promise((resolve, reject) => { socket.once('open', resolve); socket.once('error', reject); });
  const page = new FirefoxPage(child, socket, profile);
  await page.send('session.new', { capabilities: {} });
  await page.send('session.subscribe', { events: ['log.entryAdded'] });
  const tree = await page.send('browsingContext.getTree', {});
  page.context = tree.contexts[0].context;
  return page;
}

export class FirefoxPage {
  constructor(child, socket, profile) {
    this.child = child;
    this.socket = socket;
    this.profile = profile;
    this.nextId = 0;
    this.pending = new Map();
    /** Console errors and uncaught exceptions of the page. */
    this.errors = [];
    socket.on('message', (data) => {
      const message = JSON.parse(data);
      if (message.id !== undefined && this.pending.has(message.id)) {
        const { resolve, reject, method } = this.pending.get(message.id);
        this.pending.delete(message.id);
        if (message.type === 'error') reject(new Error(`${method}: ${message.error}: ${message.message}`));
        else resolve(message.result);
      } else if (message.method === 'log.entryAdded' && message.params.level === 'error') {
        this.errors.push(message.params.text);
      }
    });
  }

  /** One BiDi command; resolves to its result. */
  send(method, params) {
    const id = ++this.nextId;
    return new Promise((resolve, reject) => {
      this.pending.set(id, { resolve, reject, method });
      this.socket.send(JSON.stringify({ id, method, params }));
    });
  }

  async goto(url) {
    await this.send('browsingContext.navigate', { context: this.context, url, wait: 'complete' });
  }

  /** The value of a JavaScript expression in the page (a promise is awaited). */
  async evaluate(expression) {
    const out = await this.send('script.evaluate', {
      expression, target: { context: this.context }, awaitPromise: true,
    });
    if (out.type === 'exception') throw new Error(`${expression}: ${out.exceptionDetails.text}`);
    return out.result.value;
  }

  /** Polls a boolean expression until it holds. */
  async waitFor(expression, timeoutMs = 30000) {
    const end = Date.now() + timeoutMs;
    for (;;) {
      if (await this.evaluate(`Boolean(${expression})`)) return;
      if (Date.now() > end) throw new Error(`timed out after ${timeoutMs} ms waiting for ${expression}`);
      await new Promise((r) => setTimeout(r, 100));
    }
  }

  /** Gives the file input `selector` these files, as the picker does. */
  async setFiles(selector, files) {
    const node = await this.send('script.evaluate', {
      expression: `document.querySelector(${JSON.stringify(selector)})`,
      target: { context: this.context }, awaitPromise: false, resultOwnership: 'root',
    });
    await this.send('input.setFiles', {
      context: this.context, element: { sharedId: node.result.sharedId }, files,
    });
  }

  async close() {
    try { await this.send('session.end', {}); } catch { /* the browser may be gone */ }
    this.socket.close();
    this.child.kill();
    await new Promise((r) => (this.child.exitCode !== null ? r() : this.child.once('exit', r)));
    fs.rmSync(this.profile, { recursive: true, force: true });
  }
}
