// The viewer in a real browser against a real service: `parapm up` (a coordinator with its
// viewer and a worker, on loopback, with a token), a real mesh submitted, its page opened in
// headless Chromium (Debian's, WebGL through SwiftShader) with playwright-core. The page
// streams the PM to the full mesh, its slider's levels are `parapm lod`'s, the silhouette it
// draws is that level's, and a wrong job or token shows an error, not a blank page.
// PARAPM_BIN: the parapm program (default: build/bin/parapm); CHROMIUM: the browser (default
// /usr/bin/chromium). Skipped, saying so, when the browser is missing.
import {test, before, after} from 'node:test';
import assert from 'node:assert/strict';
import {spawn, execFileSync} from 'node:child_process';
import {existsSync, mkdtempSync, rmSync, writeFileSync} from 'node:fs';
import {tmpdir} from 'node:os';
import {join} from 'node:path';

import {parapm, readPly, testMesh} from './support.mjs';

const chromiumPath = process.env.CHROMIUM || '/usr/bin/chromium';
const haveBrowser = existsSync(chromiumPath);
const mesh = testMesh('stratocaster-9k.ply');
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

// A mask of the pixels (bottom row first, as WebGL reads them) whose centres lie inside a
// face of `mesh` projected by the column-major matrix `m`.
function rasterise(mesh, m, width, height) {
  const mask = new Uint8Array(width * height);
  const screen = mesh.positions.map(([x, y, z]) => {
    const w = m[3] * x + m[7] * y + m[11] * z + m[15];
    return [((m[0] * x + m[4] * y + m[8] * z + m[12]) / w + 1) * width / 2,
      ((m[1] * x + m[5] * y + m[9] * z + m[13]) / w + 1) * height / 2];
  });
  for (const [a, b, c] of mesh.triangles) {
    const p = screen[a], q = screen[b], r = screen[c];
    const area = (q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0]);
    if (area === 0) continue;
    const x0 = Math.max(0, Math.floor(Math.min(p[0], q[0], r[0]))), x1 = Math.min(width - 1, Math.ceil(Math.max(p[0], q[0], r[0])));
    const y0 = Math.max(0, Math.floor(Math.min(p[1], q[1], r[1]))), y1 = Math.min(height - 1, Math.ceil(Math.max(p[1], q[1], r[1])));
    for (let y = y0; y <= y1; y++)
      for (let x = x0; x <= x1; x++) {
        const px = x + 0.5, py = y + 0.5;
        const e0 = (q[0] - p[0]) * (py - p[1]) - (q[1] - p[1]) * (px - p[0]);
        const e1 = (r[0] - q[0]) * (py - q[1]) - (r[1] - q[1]) * (px - q[0]);
        const e2 = (p[0] - r[0]) * (py - r[1]) - (p[1] - r[1]) * (px - r[0]);
        if (area > 0 ? e0 >= 0 && e1 >= 0 && e2 >= 0 : e0 <= 0 && e1 <= 0 && e2 <= 0) mask[y * width + x] = 1;
      }
  }
  return mask;
}

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
  // The silhouette drawn is the level's: the page's pixels against the faces `parapm lod`
  // writes for that level, rasterised here with the page's camera (pixel centres inside a
  // projected face), as intersection over union.
  execFileSync(parapm, ['lod', join(dir, 'x.pm'), '--faces', '5000', '--ascii', '-o', join(dir, 'l.ply')]);
  const ply = readPly(join(dir, 'l.ply'));
  const lod = {positions: ply.vertices.map((values) => values.slice(0, 3)), triangles: []};
  for (let c = 0; c < ply.faces.length; c += 3) lod.triangles.push(ply.faces.slice(c, c + 3));
  const drawn = await page.evaluate(() => {
    const viewer = window.parapmViewer;
    viewer.setFaces(5000);
    viewer.zoom(0.6);
    const pixels = viewer.snapshot(true), view = viewer.view();
    const mask = new Array(pixels.length / 4);
    // Covered: more than half white (antialiased edges blend with the background).
    for (let i = 0; i < mask.length; i++) mask[i] = pixels[4 * i] > 141 ? 1 : 0;
    return {mask, ...view};
  });
  const reference = rasterise(lod, drawn.viewProjection, drawn.width, drawn.height);
  let both = 0, either = 0;
  for (let i = 0; i < reference.length; i++) {
    both += reference[i] & drawn.mask[i];
    either += reference[i] | drawn.mask[i];
  }
  console.log(`silhouette at 5000 faces: IoU ${(both / either).toFixed(4)} over ${either} pixels`);
  assert.ok(either > 5000, 'a silhouette of some size');
  assert.ok(both / either >= 0.98, `silhouette IoU ${both / either}`);
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
