// Starts a job's .pm request while the page's modules are still loading (a classic script in
// the page's head): viewer.js takes the response from window.parapmEarlyPm instead of asking
// again. Same URL as viewer.js's api(): /api/jobs/JOB/pm, with ?token= when the fragment has one.
(() => {
  const params = new URLSearchParams(location.hash.slice(1));
  const job = params.get('job'), token = params.get('token') || '';
  if (!job) return;
  const path = `/api/jobs/${encodeURIComponent(job)}/pm`;
  window.parapmEarlyPmAt = performance.now();
  window.parapmEarlyPm = fetch(token ? `${path}?token=${encodeURIComponent(token)}` : path);
})();
