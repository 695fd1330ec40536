// The viewer in a real browser against a real service: `parapm up` (a coordinator with its
// viewer and a worker, on loopback, with a token), a real mesh submitted, its page opened in
// headless Chromium (Debian's, WebGL through SwiftShader) with playwright-core. The page
// streams the PM to the full mesh, its slider's levels are `parapm lod`'s, it draws something,
// and a wrong job or token shows an error, not a blank page.
// PARAPM_BIN: the parapm program (default: build/bin/parapm); CHROMIUM: the browser (default
// /usr/bin/chromium). Skipped, saying so, when the browser is missing.
import {test, before, after} from 'node:test';
import assert from 'node:assert/strict';
import {spawn, execFileSync} from 'node:child_process';
import {existsSync, mkdtempSync, rmSync, writeFileSync} from 'node:fs';
import {tmpdir} from 'node:os';
import {join, dirname} from 'node:path';
import {fileURLToPath} from 'node:url';

const root = join(dirname(fileURLToPath(import.meta.url)), '..', '..');
const parapm = process.env.PARAPM_BIN || join(root, 'build', 'bin', 'parapm');
const chromiumPath = process.env.CHROMIUM || '/usr/bin/chromium';
const haveBrowser = existsSync(chromiumPath);
const mesh = join(root, 'tests', 'data', 'stratocaster-9k.ply');
const TOKEN = 'viewer-test-token';

let dir, up, server, viewerUrl, browser, jobId;

// Resolves with the coordinator's and the viewer's addresses once `parapm up` printed both.
function startService() {
  return new Promise((resolve, reject) => {
    up = spawn(parapm, ['up', '--workers', '1', '--data', join(dir, 'data'), '--listen', '127.0.0.1:0',
      '--http', '127.0.0.1:0', '--token-file', join(dir, 'token'), '--log-level', 'warn']);
    let text = '';
    const timer = setTimeout(() => reject(new Error(`parapm up did not start:\n${text}`)), 30000);
    up.stderr.on('data', (chunk) => {
      text += chunk;
      const coordinator = text.match(/coordinator at (\S+)/), viewer = text.match(/viewer: (http:\S+)/);
      if (coordinator && viewer) {
        clearTimeout(timer);
        resolve([coordinator[1], viewer[1]]);
      }
    });
    up.on('exit', (code) => reject(new Error(`parapm up exited (${code}):\n${text}`)));
  });
}

before(async () => {
  if (!haveBrowser) return;
  dir = mkdtempSync(join(tmpdir(), 'parapm-viewer-'));
  writeFileSync(join(dir, 'token'), TOKEN + '\n');
  [server, viewerUrl] = await startService();
  const submitted = JSON.parse(execFileSync(parapm, ['submit', mesh, '--server', server, '--token-file',
    join(dir, 'token'), '-o', join(dir, 'x.pm'), '--json']).toString());
  jobId = submitted.job_id;
  let chromium;
  try {
    ({chromium} = await import('playwright-core'));
  } catch (e) {
    throw new Error(`playwright-core is not installed: npm ci in viewer/ (scripts/bootstrap.sh does): ${e.message}`);
  }
  browser = await chromium.launch({executablePath: chromiumPath,
    args: ['--use-angle=swiftshader', '--enable-unsafe-swiftshader']});
});

after(async () => {
  if (browser) await browser.close();
  if (up) {
    up.removeAllListeners('exit');
    up.kill('SIGTERM');
    await new Promise((resolve) => up.on('exit', resolve));
  }
  if (dir) rmSync(dir, {recursive: true, force: true});
});

async function open(fragment) {
  const page = await browser.newPage({viewport: {width: 640, height: 480}});
  const errors = [];
  page.on('pageerror', (e) => errors.push(e.message));
  await page.goto(`${viewerUrl}#${fragment}`);
  await page.waitForFunction(() => ['done', 'error'].includes(window.parapmViewer?.state), null, {timeout: 30000});
  return {page, errors, viewer: await page.evaluate(() => ({...window.parapmViewer}))};
}

test('a job streams to its full mesh, and the slider gives parapm lod\'s levels', {skip: !haveBrowser && 'no Chromium'}, async () => {
  const {page, errors, viewer} = await open(`job=${jobId}&token=${TOKEN}`);
  assert.deepEqual(errors, []);
  assert.equal(viewer.state, 'done', viewer.error);
  const info = JSON.parse(execFileSync(parapm, ['info', join(dir, 'x.pm'), '--json']).toString());
  assert.equal(viewer.totalVsplits, info.vsplits ?? info.levels - 1);
  assert.equal(viewer.vsplitsApplied, viewer.totalVsplits);
  assert.equal(viewer.faces, 8660);  // the input's faces: stratocaster-9k needs no repair
  assert.ok(viewer.bytesReceived > 100000);
  for (const faces of [1000, 5000, 600]) {
    const level = JSON.parse(execFileSync(parapm, ['lod', join(dir, 'x.pm'), '--faces', String(faces), '-o',
      join(dir, 'l.ply'), '--json']).toString());
    const shown = await page.evaluate((n) => {
      window.parapmViewer.setFaces(n);
      return window.parapmViewer.faces;
    }, faces);
    assert.equal(shown, level.faces, `${faces} faces`);
  }
  // With the geomorph toggle on, a level change animates, then shows that level.
  await page.locator('#geomorph').check();
  const level = JSON.parse(execFileSync(parapm, ['lod', join(dir, 'x.pm'), '--faces', '3000', '-o',
    join(dir, 'l.ply'), '--json']).toString());
  assert.equal(await page.evaluate(() => {
    window.parapmViewer.setFaces(3000);
    return window.parapmViewer.morphing;
  }), true);
  await page.waitForFunction(() => !window.parapmViewer.morphing, null, {timeout: 5000});
  assert.equal(await page.evaluate(() => window.parapmViewer.faces), level.faces);
  // View-dependent: fewer faces than the full mesh where the view needs no more, and the face
  // count follows the view; the slider's levels come back when it is off.
  await page.locator('#geomorph').uncheck();
  const seen = await page.evaluate(() => {
    const viewer = window.parapmViewer;
    viewer.setFaces(1e9);
    viewer.setViewDependent(true, 2);
    const far = viewer.faces;
    viewer.setViewDependent(true, 50);
    const coarse = viewer.faces;
    viewer.setViewDependent(true, 0.5);
    const fine = viewer.faces;
    viewer.setViewDependent(false);
    return {far, coarse, fine, off: viewer.faces};
  });
  console.log('view-dependent faces at 2, 50 and 0.5 px, and off:', JSON.stringify(seen));
  assert.ok(seen.coarse < seen.far && seen.far < seen.fine, JSON.stringify(seen));
  assert.ok(seen.far < 8660 && seen.coarse >= 498, JSON.stringify(seen));
  assert.equal(seen.off, 8660);
  // Something is drawn: the canvas is not all background.
  await page.waitForTimeout(200);
  const shot = await page.locator('#canvas').screenshot({path: process.env.VIEWER_SHOT || undefined});
  assert.ok(shot.length > 2000, 'a screenshot with content');
  const lit = await page.evaluate(() => window.parapmViewer.coverage());
  assert.ok(lit > 0.01, `the mesh covers ${lit} of the canvas`);
  await page.close();
});

test('a wrong job id and a wrong token show an error', {skip: !haveBrowser && 'no Chromium'}, async () => {
  const wrongJob = await open(`job=job-0000000000000000&token=${TOKEN}`);
  assert.equal(wrongJob.viewer.state, 'error');
  assert.match(wrongJob.viewer.error, /no job/);
  assert.match(await wrongJob.page.locator('#message').textContent(), /no job/);
  const wrongToken = await open(`job=${jobId}&token=nope`);
  assert.equal(wrongToken.viewer.state, 'error');
  assert.match(wrongToken.viewer.error, /token/);
  const noToken = await open('');
  assert.equal(noToken.viewer.state, 'error');
  assert.match(await noToken.page.locator('#jobs-message').textContent(), /token/);
});
