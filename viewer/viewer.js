// The viewer page: the coordinator's job list at /, a job's Progressive Mesh at /#job=JOB
// (with #token=TOKEN where the coordinator needs one). The job's .pm streams in
// (GET /api/jobs/JOB/pm); its base mesh is drawn as soon as it has arrived, then refined
// split by split as the records arrive; the slider moves through the levels without
// re-fetching. For scripts and tests, window.parapmViewer holds the state (docs/VIEWER.md).
import {PmDecoder} from './pm_decoder.js';
import {PmMesh} from './pm_mesh.js';
import {Renderer} from './renderer.js';
import {SplitRegions} from './split_regions.js';

const viewer = {
  state: 'loading', // "loading", "streaming", "done", "error"
  faces: 0,
  vsplitsApplied: 0,
  totalVsplits: 0,
  bytesReceived: 0,
  error: '',
  setFaces: (n) => setFaces(n), // with the geomorph toggle on, a geomorph to that level
  morphing: false,
  // View-dependent refinement (a selective refinement with view criteria): refine where what a
  // split changes (its descendants' reach, SplitRegions) projects to more than
  // `thresholdPixels` on screen, inside the view.
  viewDependent: false,
  thresholdPixels: 2,
  setViewDependent: (on, pixels) => setViewDependent(on, pixels),
  zoom: (factor) => zoom(factor),
  coverage: () => (renderer ? (upload(), renderer.coverage()) : 0), // the canvas's fraction the mesh covers
  // The canvas drawn now, RGBA, bottom row first (silhouette: every face white, unlit).
  snapshot: (silhouette = false) => (renderer ? (upload(), renderer.snapshot(silhouette)) : null),
  // The camera: its view-projection matrix (column major) and the canvas's size in pixels.
  view: () => {
    const v = renderer.view();
    return {viewProjection: Array.from(v.viewProjection), width: renderer.canvas.width, height: renderer.canvas.height};
  },
  // Milliseconds since the page's start (performance.now()) of the .pm's request, of its base
  // mesh decoded, of the first frame with the base mesh and of the stream's end, and the
  // seconds spent decoding and applying vsplits.
  timings: {request: 0, base: 0, firstFrame: 0, done: 0, decodeSeconds: 0, applySeconds: 0},
};
window.parapmViewer = viewer;

const params = new URLSearchParams(location.hash.slice(1));
const token = params.get('token') || '';
const jobId = params.get('job');

function api(path) {
  return token ? `${path}?token=${encodeURIComponent(token)}` : path;
}

async function errorOf(response) {
  try {
    return (await response.json()).error || `HTTP ${response.status}`;
  } catch {
    return `HTTP ${response.status} ${response.statusText}`;
  }
}

function fail(message) {
  viewer.state = 'error';
  viewer.error = message;
  document.getElementById(jobId ? 'message' : 'jobs-message').textContent = message;
}

// --- the job list ----------------------------------------------------------------------------
async function showJobs() {
  const response = await fetch(api('/api/jobs'));
  if (!response.ok) return fail(await errorOf(response));
  const {jobs} = await response.json();
  const body = document.querySelector('#job-table tbody');
  for (const job of jobs) {
    const row = body.insertRow();
    const link = document.createElement('a');
    link.textContent = job.job_id;
    link.href = `#job=${encodeURIComponent(job.job_id)}${token ? `&token=${encodeURIComponent(token)}` : ''}`;
    row.insertCell().append(link);
    for (const value of [job.state, job.input_faces, job.base_faces, job.vsplits, job.options?.metric ?? ''])
      row.insertCell().textContent = String(value);
  }
  if (jobs.length === 0) document.getElementById('jobs-message').textContent = 'No jobs yet: parapm submit MESH';
  viewer.state = 'done';
}

// --- a job's PM ------------------------------------------------------------------------------
let decoder = null, mesh = null, renderer = null;
let follow = true; // the level follows the stream while the slider is at its end
let startTime = 0, dirty = false;
const slider = document.getElementById('level');

function setFaces(n) {
  if (!mesh) return;
  follow = false;
  moveTo(mesh.levelForFaces(n));
}

// To `level`: at once, or with the geomorph toggle on, by a geomorph of kGeomorphSeconds
// (vertices move, faces do not pop). viewer.morphing is true while one runs.
const kGeomorphSeconds = 0.5;
let morph = null;
function moveTo(level) {
  if (morph) finishMorph();
  if (!document.getElementById('geomorph').checked || level === mesh.level) return setLevel(level);
  const refining = level > mesh.level;
  const g = mesh.geomorph(level);
  morph = {
    target: level,
    from: refining ? g.coarsePositions : g.finePositions,
    to: refining ? g.finePositions : g.coarsePositions,
    // Attributes (null without): their values glide the same way.
    fromWedges: refining ? g.coarseWedgeValues : g.fineWedgeValues,
    toWedges: refining ? g.fineWedgeValues : g.coarseWedgeValues,
    fineWedges: g.fineWedgeValues,
    start: performance.now(),
  };
  viewer.morphing = true;
  report();
}

// --- view-dependent refinement ----------------------------------------------------------------
let selective = null, refineTimer = 0, regions = null;

function setViewDependent(on, pixels) {
  viewer.viewDependent = on;
  if (pixels !== undefined) viewer.thresholdPixels = pixels;
  document.getElementById('view-dependent').checked = on;
  document.getElementById('threshold').value = String(viewer.thresholdPixels);
  slider.disabled = on;
  if (on) refineForView();
  else if (mesh) {
    selective = null;
    dirty = true;
    report();
  }
}

// A selective refinement of what has arrived, for the camera now: split i where the region it
// refines (SplitRegions' sphere) meets the view and the surface there may be more than the
// threshold off the finest mesh on screen (its reach, projected at the region's nearest depth).
function refineForView() {
  if (!viewer.viewDependent || !renderer || !decoder) return;
  const {viewProjection: m, scale, height} = renderer.view();
  const pixelsPerUnit = (scale * height) / 2, threshold = viewer.thresholdPixels;
  if (regions?.splits !== decoder.splitCount) regions = new SplitRegions(decoder);
  const {center: c, radius: r, reach} = regions;
  // Clip x, y and w per model unit (the rows' lengths): a sphere of radius r spans r times them.
  const xScale = Math.hypot(m[0], m[4], m[8]), yScale = Math.hypot(m[1], m[5], m[9]);
  const wScale = Math.hypot(m[3], m[7], m[11]);
  const refined = new PmMesh(decoder);
  refined.refineSelectively((i) => {
    const px = c[3 * i], py = c[3 * i + 1], pz = c[3 * i + 2], ri = r[i];
    const w = m[3] * px + m[7] * py + m[11] * pz + m[15], wReach = wScale * ri;
    if (w + wReach <= 0) return false;  // behind the camera
    // Outside the view (clip x and y run from -w to w inside it).
    const cx = m[0] * px + m[4] * py + m[8] * pz + m[12], cy = m[1] * px + m[5] * py + m[9] * pz + m[13];
    if (Math.abs(cx) - xScale * ri > w + wReach || Math.abs(cy) - yScale * ri > w + wReach) return false;
    const nearest = Math.max(w - wReach, 1e-6 * (Math.abs(w) + wReach));
    return (reach[i] * pixelsPerUnit) / nearest > threshold;
  });
  selective = refined;
  dirty = true;
  report();
}

// Refined again once the camera rests (a refinement walks every split that has arrived).
function cameraChanged() {
  if (!viewer.viewDependent) return;
  clearTimeout(refineTimer);
  refineTimer = setTimeout(refineForView, 120);
}

function zoom(factor) {
  renderer.camera.distance *= factor;
  cameraChanged();
  if (viewer.viewDependent) refineForView();
}

function stepMorph() {
  const t = Math.min(1, (performance.now() - morph.start) / 1000 / kGeomorphSeconds);
  mesh.morphPositions(morph.from, morph.to, t);
  if (morph.fromWedges) mesh.morphWedgeValues(morph.fromWedges, morph.toWedges, t);
  dirty = true;
  if (t >= 1) finishMorph();
}

function finishMorph() {
  mesh.morphPositions(morph.from, morph.to, 1);
  // The fine level's own values back before any split is undone (undoing a split's wedge
  // changes subtracts its exact deltas from the fine values).
  if (morph.fineWedges) mesh.wedgeValues.set(morph.fineWedges);
  const target = morph.target;
  morph = null;
  viewer.morphing = false;
  setLevel(target);  // a coarsening morph ends by undoing its splits
}

function setLevel(level) {
  const start = performance.now();
  mesh.setLevel(level);
  viewer.timings.applySeconds += (performance.now() - start) / 1000;
  slider.value = String(mesh.level);
  dirty = true;
  report();
}

function report() {
  if (!mesh) return;
  const shown = selective || mesh;
  viewer.faces = shown.faceCount;
  viewer.vsplitsApplied = mesh.level;
  const n = decoder.header.splits;
  const error = mesh.level < decoder.splitCount ? decoder.error[mesh.level] : 0;
  const seconds = (performance.now() - startTime) / 1000;
  document.getElementById('stats').textContent =
    `faces ${shown.faceCount}${selective ? ' (view-dependent)' : ''}  vsplits ${mesh.level} / ${n}` +
    `  received ${viewer.bytesReceived} bytes` +
    `  error bound ${error.toPrecision(3)}  ${Math.round(decoder.splitCount / Math.max(seconds, 1e-3))} vsplits/s`;
}

// The level shown into the renderer's buffers, when it changed.
function upload() {
  if (dirty && renderer) {
    renderer.update(selective || mesh);
    dirty = false;
  }
}

function frame() {
  if (morph) stepMorph();
  upload();
  if (renderer) {
    renderer.draw();
    if (!viewer.timings.firstFrame) viewer.timings.firstFrame = performance.now();
  }
  requestAnimationFrame(frame);
}

async function showJob() {
  document.getElementById('jobs').style.display = 'none';
  document.getElementById('view').style.display = 'block';
  document.getElementById('title').textContent = `job ${jobId}`;
  document.getElementById('back').href = token ? `#token=${encodeURIComponent(token)}` : '#';
  document.getElementById('back').onclick = () => setTimeout(() => location.reload());
  slider.oninput = () => {
    follow = Number(slider.value) === decoder.splitCount;
    moveTo(Number(slider.value));
  };
  document.getElementById('view-dependent').onchange = (e) => setViewDependent(e.target.checked);
  document.getElementById('threshold').oninput = (e) => {
    viewer.thresholdPixels = Number(e.target.value);
    cameraChanged();
  };
  document.getElementById('wireframe').onchange = (e) => {
    if (renderer) renderer.wireframe = e.target.checked;
    dirty = true;
  };
  // The request early_fetch.js started while the modules loaded, else one now.
  startTime = viewer.timings.request = window.parapmEarlyPmAt ?? performance.now();
  const response = await (window.parapmEarlyPm ?? fetch(api(`/api/jobs/${encodeURIComponent(jobId)}/pm`)));
  if (!response.ok) return fail(await errorOf(response));
  const reader = response.body.getReader();
  decoder = new PmDecoder();
  requestAnimationFrame(frame);
  for (;;) {
    const {done, value} = await reader.read();
    if (done) break;
    viewer.bytesReceived += value.length;
    const start = performance.now();
    decoder.push(value);
    viewer.timings.decodeSeconds += (performance.now() - start) / 1000;
    if (!mesh && decoder.base) {
      viewer.timings.base = performance.now();
      mesh = new PmMesh(decoder);
      viewer.totalVsplits = decoder.header.splits;
      slider.max = String(decoder.header.splits);
      renderer = new Renderer(document.getElementById('canvas'), decoder.header);
      renderer.onCameraChange = cameraChanged;
      viewer.state = 'streaming';
      dirty = true;
      // The base mesh on screen first (the next frame draws it), then the splits.
      await new Promise((resolve) => requestAnimationFrame(resolve));
    }
    if (mesh && follow && !morph) setLevel(decoder.splitCount);
    if (mesh) report();
  }
  if (!decoder.done) return fail(`the stream ended after ${viewer.bytesReceived} bytes, before the last vsplit`);
  if (morph) finishMorph();
  if (follow) setLevel(decoder.splitCount);
  if (viewer.viewDependent) refineForView();  // with every split
  viewer.timings.done = performance.now();
  viewer.state = 'done';
}

(jobId ? showJob() : showJobs()).catch((e) => fail(e.message || String(e)));
