// node viewer/bench/viewer_bench.mjs URL JOB [TOKEN]: opens the job's page in headless
// Chromium (playwright-core; CHROMIUM, default /usr/bin/chromium) and prints one TSV row: the
// PM's faces and vsplits, bytes, the time to the first frame with the base mesh and to the
// whole PM (from the page's start), the seconds decoding and applying vsplits and the
// vsplits applied per second of applying, and the time of slider moves of 100k vsplits down
// and up again; view-dependent refinement at the default threshold against the full mesh in the
// same view (THRESHOLD: another threshold in pixels): its faces over the full mesh's, the
// fraction of pixels that differ, its time.
// bench/viewer.sh drives it.
import {chromium} from 'playwright-core';

const [url, job, token] = process.argv.slice(2);
const browser = await chromium.launch({executablePath: process.env.CHROMIUM || '/usr/bin/chromium',
  args: ['--use-angle=swiftshader', '--enable-unsafe-swiftshader']});
try {
  const page = await browser.newPage({viewport: {width: 800, height: 600}});
  await page.goto(`${url}#job=${job}${token ? `&token=${token}` : ''}`);
  await page.waitForFunction(() => ['done', 'error'].includes(window.parapmViewer?.state), null, {timeout: 600000});
  const v = await page.evaluate(() => ({...window.parapmViewer}));
  if (v.state !== 'done') throw new Error(v.error);
  const slider = await page.evaluate(() => {
    const viewer = window.parapmViewer, faces = viewer.faces, down = Math.max(0, faces - 200000);
    let t = performance.now();
    viewer.setFaces(down);  // about 100k vsplits undone
    const undone = performance.now() - t;
    t = performance.now();
    viewer.setFaces(faces);
    return [undone, performance.now() - t];
  });
  // View-dependent at the default threshold against the full mesh, same view: faces, and the
  // pixels whose colour differs by more than a few levels (antialiasing), over all pixels.
  const view = await page.evaluate((pixels) => {
    const viewer = window.parapmViewer;
    viewer.setFaces(1e12);
    const full = viewer.snapshot(), fullFaces = viewer.faces;
    const start = performance.now();
    viewer.setViewDependent(true, pixels ?? undefined);
    const refineMs = performance.now() - start;
    const shown = viewer.snapshot();
    let differ = 0;
    for (let i = 0; i < full.length; i += 4)
      if (Math.abs(full[i] - shown[i]) + Math.abs(full[i + 1] - shown[i + 1]) + Math.abs(full[i + 2] - shown[i + 2]) > 24) differ++;
    const faces = viewer.faces;
    viewer.setViewDependent(false);
    return {faces: faces / fullFaces, differ: differ / (full.length / 4), refineMs};
  }, process.env.THRESHOLD ? Number(process.env.THRESHOLD) : null);
  const t = v.timings;
  console.log(['faces', 'vsplits', 'bytes', 'first_frame_s', 'done_s', 'decode_s', 'apply_s', 'vsplits_per_s',
    'slider_down_100k_ms', 'slider_up_100k_ms', 'view_dependent_faces', 'view_dependent_pixels_differing',
    'view_dependent_refine_ms'].join('\t'));
  console.log([v.faces, v.totalVsplits, v.bytesReceived, (t.firstFrame / 1000).toFixed(3), (t.done / 1000).toFixed(3),
    t.decodeSeconds.toFixed(3), t.applySeconds.toFixed(3), Math.round(v.totalVsplits / t.applySeconds),
    slider[0].toFixed(1), slider[1].toFixed(1), view.faces.toFixed(3), view.differ.toFixed(4),
    view.refineMs.toFixed(0)].join('\t'));
} finally {
  await browser.close();
}
