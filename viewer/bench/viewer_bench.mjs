// node viewer/bench/viewer_bench.mjs URL JOB [TOKEN]: opens the job's page in headless
// Chromium (playwright-core; CHROMIUM, default /usr/bin/chromium) and prints one TSV row: the
// PM's faces and vsplits, bytes, the time to the first frame with the base mesh and to the
// whole PM (from the page's start), the seconds decoding and applying vsplits and the
// vsplits applied per second of applying, and the time of slider moves of 100k vsplits down
// and up again. bench/viewer.sh drives it.
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
  const t = v.timings;
  console.log(['faces', 'vsplits', 'bytes', 'first_frame_s', 'done_s', 'decode_s', 'apply_s', 'vsplits_per_s',
    'slider_down_100k_ms', 'slider_up_100k_ms'].join('\t'));
  console.log([v.faces, v.totalVsplits, v.bytesReceived, (t.firstFrame / 1000).toFixed(3), (t.done / 1000).toFixed(3),
    t.decodeSeconds.toFixed(3), t.applySeconds.toFixed(3), Math.round(v.totalVsplits / t.applySeconds),
    slider[0].toFixed(1), slider[1].toFixed(1)].join('\t'));
} finally {
  await browser.close();
}
