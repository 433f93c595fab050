// Drives Debian's Chromium (/usr/bin/chromium) headless through puppeteer-core for the viewer
// tests: WebGL2 on a machine without a GPU (SwiftShader, a CPU Vulkan driver, under ANGLE), the
// page's console errors and uncaught exceptions collected, and the browser and its temporary
// profile always removed afterwards. puppeteer-core is the pinned copy that scripts/setup
// installs into .tools/node_modules (never a global one, never a downloaded browser).
//
// API (ES module):
//   withPage(url, fn, {width = 1280, height = 720, timeoutMs = 60000, allowErrors = false})
//       Launches Chromium, opens a width x height page (device scale 1), navigates to url
//       (waits for 'load'), returns await fn(page, log). log = {errors: [string], console:
//       [string], timings: {launch_ms, goto_ms}}; errors gathers console.error messages,
//       uncaught page exceptions and failed requests. Unless allowErrors, a non-empty
//       log.errors after fn makes withPage throw (an error in the page fails the test).
//       The browser is closed and its profile deleted in every case.
//   startViewServer({outputs, root, port = 0})
//       Starts scripts/view_server.py (127.0.0.1, a free port unless given) serving root
//       (default viewer/) at /, outputs at /outputs/ and ktx-parse at /vendor/ktx-parse/;
//       resolves to {port, url, close()} once it listens. close() stops it (SIGTERM).
//   CHROMIUM, CHROMIUM_ARGS: the executable and the flags withPage adds.
//
// CLI (for the python tests):
//   node tests/viewer/browser.mjs (--url URL | --outputs DIR [--root DIR] [--path /x.html?q])
//        [--eval-file F] [--out result.json] [--screenshot shot.png]
//        [--width W] [--height H] [--timeout-ms N] [--allow-errors]
//   F is the body of an async function run in the page; what it returns (JSON-serialisable)
//   is written to --out as {url, result, errors, console, timings}. --outputs starts
//   view_server.py for the run. Exit 0, or 1 when the page reported errors or a step failed.

import {spawn} from 'node:child_process';
import fs from 'node:fs';
import {createRequire} from 'node:module';
import os from 'node:os';
import path from 'node:path';
import readline from 'node:readline';
import {fileURLToPath, pathToFileURL} from 'node:url';

export const REPO = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '..', '..');
export const CHROMIUM = '/usr/bin/chromium';

// WebGL2 without a GPU: ANGLE on its Vulkan back end with SwiftShader. Chromium >= 137 no
// longer falls back to SwiftShader silently for WebGL; --enable-unsafe-swiftshader opts in
// (acceptable: the pages are our own, served from 127.0.0.1). With these two flags Chromium 156
// reports "ANGLE (Google, Vulkan 1.3.0 (SwiftShader Device (Subzero) ...), SwiftShader driver)".
// Chromium refuses to start as root with its sandbox; as another user the sandbox works (user
// namespaces), so --no-sandbox is added for root only.
export const CHROMIUM_ARGS = [
  '--use-angle=swiftshader',
  '--enable-unsafe-swiftshader',
  ...(process.getuid && process.getuid() === 0 ? ['--no-sandbox'] : []),
];

function loadPuppeteer() {
  // Resolve from .tools/ so the pinned copy is used whatever the working directory.
  const require = createRequire(path.join(REPO, '.tools', 'package.json'));
  try {
    return require('puppeteer-core');
  } catch (e) {
    throw new Error(`puppeteer-core not found in ${path.join(REPO, '.tools', 'node_modules')} ` +
                    `(run scripts/setup): ${e.message}`);
  }
}

export async function withPage(url, fn,
                               {width = 1280, height = 720, timeoutMs = 60000,
                                allowErrors = false} = {}) {
  if (!fs.existsSync(CHROMIUM)) throw new Error(`${CHROMIUM} not found (run scripts/setup)`);
  const puppeteer = loadPuppeteer();
  // Our own profile folder (not puppeteer's) so that it is removed even when launch fails.
  const profile = fs.mkdtempSync(path.join(os.tmpdir(), 'skybake-chromium-'));
  const log = {errors: [], console: [], timings: {}};
  let browser;
  try {
    let t = performance.now();
    browser = await puppeteer.launch({
      executablePath: CHROMIUM,
      headless: true,  // the new headless mode (--headless=new), the full browser
      pipe: true,      // CDP over a pipe: no debugging port is opened at all
      userDataDir: profile,
      args: CHROMIUM_ARGS,
      defaultViewport: {width, height, deviceScaleFactor: 1},
      timeout: timeoutMs,
      protocolTimeout: Math.max(timeoutMs, 180000),
    });
    log.timings.launch_ms = performance.now() - t;
    const page = await browser.newPage();
    page.setDefaultTimeout(timeoutMs);
    page.on('console', m => {
      const {url: at, lineNumber: line} = m.location() ?? {};
      const where = at ? ` (${at}${line === undefined ? '' : `:${line + 1}`})` : '';
      log.console.push(`${m.type()}: ${m.text()}${where}`);
      if (m.type() === 'error') log.errors.push(`console.error: ${m.text()}${where}`);
    });
    page.on('pageerror', e => log.errors.push(`uncaught: ${e.message ?? e}`));
    page.on('requestfailed',
            r => log.errors.push(`request failed: ${r.url()}: ${r.failure()?.errorText}`));
    t = performance.now();
    const response = await page.goto(url, {waitUntil: 'load'});
    log.timings.goto_ms = performance.now() - t;
    if (response && !response.ok()) log.errors.push(`HTTP ${response.status()} for ${url}`);
    const result = await fn(page, log);
    if (log.errors.length && !allowErrors) {
      throw new Error(`page reported errors:\n  ${log.errors.join('\n  ')}`);
    }
    return result;
  } finally {
    if (browser) {
      // close() waits for the process; a wedged browser is killed after 10 s.
      const proc = browser.process();
      await Promise.race([browser.close().catch(() => {}),
                          new Promise(r => setTimeout(r, 10000).unref())]);
      if (proc && proc.exitCode === null && proc.signalCode === null) proc.kill('SIGKILL');
    }
    fs.rmSync(profile, {recursive: true, force: true, maxRetries: 5, retryDelay: 100});
  }
}

export function startViewServer({outputs, root, port = 0} = {}) {
  const args = [path.join(REPO, 'scripts', 'view_server.py'), '--port', String(port),
                '--print-port', '--quiet'];
  if (outputs) args.push('--outputs', outputs);
  if (root) args.push('--root', root);
  const proc = spawn('python3', args, {stdio: ['ignore', 'pipe', 'pipe']});
  const stopOnExit = () => proc.kill('SIGTERM');
  process.on('exit', stopOnExit);  // never leave a server behind a crashed test
  let stderr = '';
  proc.stderr.on('data', d => { stderr += d; });
  return new Promise((resolve, reject) => {
    const lines = readline.createInterface({input: proc.stdout});
    proc.on('exit', code => reject(new Error(`view_server.py exited (${code}): ${stderr.trim()}`)));
    lines.once('line', line => {
      const p = Number(line);
      if (!Number.isInteger(p) || p <= 0) {
        proc.kill('SIGTERM');
        reject(new Error(`view_server.py: expected a port, got '${line}'`));
        return;
      }
      resolve({
        port: p,
        url: `http://127.0.0.1:${p}/`,
        close: () => new Promise(done => {
          process.off('exit', stopOnExit);
          if (proc.exitCode !== null || proc.signalCode !== null) return done();
          proc.once('exit', () => done());
          proc.kill('SIGTERM');
        }),
      });
    });
  });
}

// ---- CLI ----------------------------------------------------------------------------------------

function parseCli(argv) {
  const opts = {width: 1280, height: 720, timeoutMs: 60000, allowErrors: false, path: '/'};
  const valued = {'--url': 'url', '--outputs': 'outputs', '--root': 'root', '--path': 'path',
                  '--eval-file': 'evalFile', '--out': 'out', '--screenshot': 'screenshot',
                  '--width': 'width', '--height': 'height', '--timeout-ms': 'timeoutMs'};
  for (let i = 0; i < argv.length; i++) {
    const a = argv[i];
    if (a === '--allow-errors') opts.allowErrors = true;
    else if (a in valued && i + 1 < argv.length) opts[valued[a]] = argv[++i];
    else throw new Error(`unknown or incomplete argument '${a}' (see the header of browser.mjs)`);
  }
  for (const k of ['width', 'height', 'timeoutMs']) {
    opts[k] = Number(opts[k]);
    if (!Number.isInteger(opts[k]) || opts[k] <= 0) throw new Error(`--${k}: expected a positive integer`);
  }
  if (!opts.url === !opts.outputs) throw new Error('give exactly one of --url and --outputs');
  return opts;
}

async function cli(argv) {
  const opts = parseCli(argv);
  const body = opts.evalFile ? fs.readFileSync(opts.evalFile, 'utf8') : 'return null;';
  const server = opts.outputs ? await startViewServer({outputs: opts.outputs, root: opts.root})
                              : null;
  const url = server ? new URL(opts.path, server.url).href : opts.url;
  const report = {url, result: null, errors: [], console: [], timings: {}};
  let failed = null;
  try {
    await withPage(url, async (page, log) => {
      report.errors = log.errors;
      report.console = log.console;
      report.timings = log.timings;
      const t = performance.now();
      report.result = await page.evaluate(`(async () => {\n${body}\n})()`);
      log.timings.eval_ms = performance.now() - t;
      if (opts.screenshot) await page.screenshot({path: opts.screenshot, type: 'png'});
    }, {width: opts.width, height: opts.height, timeoutMs: opts.timeoutMs,
        allowErrors: opts.allowErrors});
  } catch (e) {
    failed = e;
  } finally {
    if (server) await server.close();
  }
  if (failed) report.failure = String(failed.message ?? failed);
  if (opts.out) fs.writeFileSync(opts.out, JSON.stringify(report, null, 2) + '\n');
  else process.stdout.write(JSON.stringify(report, null, 2) + '\n');
  if (failed) {
    process.stderr.write(`browser.mjs: ${report.failure}\n`);
    return 1;
  }
  return 0;
}

if (process.argv[1] && import.meta.url === pathToFileURL(path.resolve(process.argv[1])).href) {
  cli(process.argv.slice(2)).then(code => { process.exitCode = code; }, e => {
    process.stderr.write(`browser.mjs: ${e.message ?? e}\n`);
    process.exitCode = 2;
  });
}
