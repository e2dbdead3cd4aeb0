// The Tessera dashboard: polls the coordinator's /api/v1 (docs/api.md) with the client token the
// user pasted, kept in sessionStorage so it lives as long as the tab and is never sent anywhere else.
'use strict';

(() => {
  const TOKEN_KEY = 'tessera.client_token';
  const POLL_MS = 1000;
  const HIDDEN_POLL_MS = 10000;  // a background tab needs no second-by-second progress
  const LIVE = new Set(['queued', 'running']);

  const $ = (id) => document.getElementById(id);

  const state = {
    token: sessionStorage.getItem(TOKEN_KEY) || '',
    selected: null,  // the job id in the detail panel
    // key: the shown image's job and samples; next: no fetch before (big images cost the server a PNG)
    // kind: 'raw', or 'denoised' for a job submitted with denoise (the toggle above the image)
    image: { job: null, key: '', url: null, busy: false, next: 0, kind: 'raw' },
    jobRows: new Map(),  // job id -> <tr>, updated in place so buttons survive each poll
    timer: null,
    running: false,
    again: false,
  };

  // ---- the API ------------------------------------------------------------------------------

  class ApiError extends Error {
    constructor(status, error, detail) {
      super(detail ? `${error}: ${detail}` : error);
      this.status = status;
      this.error = error;
      this.detail = detail;
    }
  }

  // Every call carries the token; an error body is the API's {"error", "detail"}.
  async function api(path, options = {}) {
    const headers = new Headers(options.headers || {});
    if (state.token) headers.set('Authorization', `Bearer ${state.token}`);
    const res = await fetch(path, { ...options, headers, cache: 'no-store' });
    if (res.ok) return res;
    let body = {};
    try {
      body = await res.json();
    } catch (_) {
      // not JSON (a proxy's page): the status says enough
    }
    throw new ApiError(res.status, body.error || `HTTP ${res.status}`, body.detail || res.statusText);
  }

  const apiJson = async (path, options) => (await api(path, options)).json();

  // ---- formatting ---------------------------------------------------------------------------

  const count = (n) => Number(n || 0).toLocaleString('en-US');
  const percent = (p) => (p >= 1 ? 100 : Math.floor(Math.max(0, p) * 100));

  function duration(s) {
    if (!(s > 0)) return '–';
    if (s < 60) return `${s.toFixed(1)} s`;
    const m = Math.floor(s / 60);
    if (m < 60) return `${m} min ${String(Math.round(s % 60)).padStart(2, '0')} s`;
    return `${Math.floor(m / 60)} h ${String(m % 60).padStart(2, '0')} min`;
  }

  function bytes(n) {
    const units = ['B', 'KiB', 'MiB', 'GiB'];
    let i = 0;
    for (n = Number(n || 0); n >= 1024 && i < units.length - 1; i++) n /= 1024;
    return `${i ? n.toFixed(1) : n} ${units[i]}`;
  }

  function rate(samplesPerSecond) {
    const r = Number(samplesPerSecond || 0);
    if (r <= 0) return '–';
    if (r >= 1e6) return `${(r / 1e6).toFixed(2)} M samples/s`;
    if (r >= 1e3) return `${(r / 1e3).toFixed(1)} k samples/s`;
    return `${r.toFixed(0)} samples/s`;
  }

  // ---- DOM helpers (text only: names come from users, nothing goes through innerHTML) -------

  function el(tag, props = {}, ...children) {
    const node = document.createElement(tag);
    for (const [k, v] of Object.entries(props)) {
      if (k === 'dataset') Object.assign(node.dataset, v);
      else if (k in node) node[k] = v;
      else node.setAttribute(k, v);
    }
    for (const c of children) node.append(c);
    return node;
  }

  const badge = (s) => el('span', { className: `badge state-${s}` }, s);

  function progressBar(p) {
    const pct = percent(p);
    const aria = { role: 'progressbar', 'aria-valuenow': pct, 'aria-valuemin': 0, 'aria-valuemax': 100 };
    return el('div', { className: 'bar', ...aria },
      el('div', { className: 'fill', style: `width: ${pct}%` }), el('span', { className: 'pct' }, `${pct}%`));
  }

  function facts(dl, pairs) {
    dl.replaceChildren(...pairs.filter(([, v]) => v !== undefined && v !== '')
      .flatMap(([k, v]) => [el('dt', {}, k), el('dd', {}, String(v))]));
  }

  // ---- the banner: refresh problems (401, unreachable) and failed actions --------------------

  function showBanner(kind, text) {
    const b = $('banner');
    b.textContent = text;
    b.dataset.kind = kind;
    b.className = `banner banner-${kind}`;
    b.hidden = false;
  }

  function clearBanner(...kinds) {
    const b = $('banner');
    if (!b.hidden && kinds.includes(b.dataset.kind)) b.hidden = true;
  }

  function unauthorized() {
    showBanner('auth', state.token
      ? '401 Unauthorized: the coordinator refused this token. Check it and paste the client token again.'
      : '401 Unauthorized: this farm needs the client token (tessera-server --client-token). Paste it above.');
    renderJobs([]);
    renderWorkers([]);
    clearDetail();
    $('jobs-empty').textContent = $('workers-empty').textContent = 'Enter the client token to see the farm.';
  }

  function reportRefreshError(e) {
    if (e instanceof ApiError && e.status === 401) unauthorized();
    else if (e instanceof ApiError) showBanner('error', `The coordinator answered ${e.status}: ${e.message}`);
    else showBanner('offline', 'Cannot reach the coordinator; retrying.');
  }

  // ---- jobs ---------------------------------------------------------------------------------

  function jobRow(job) {
    const cancel = el('button', { className: 'cancel secondary', type: 'button', title: 'Cancel this job' }, 'Cancel');
    cancel.addEventListener('click', (ev) => {
      ev.stopPropagation();  // not a click on the row
      cancelJob(job.id);
    });
    const row = el('tr', { dataset: { jobId: job.id } },
      el('td', { className: 'num' }, `#${job.id}`), el('td', { className: 'name' }), el('td', { className: 'state' }),
      el('td', { className: 'progress' }), el('td', { className: 'size' }), el('td', { className: 'spp num' }),
      el('td', { className: 'row-actions' }, cancel));
    row.addEventListener('click', () => select(job.id));
    return row;
  }

  function updateJobRow(row, job) {
    const q = (c) => row.querySelector(`.${c}`);
    if (row.dataset.state !== job.state) {
      row.dataset.state = job.state;
      q('state').replaceChildren(badge(job.state));
      q('cancel').hidden = !LIVE.has(job.state);
    }
    q('name').textContent = job.name || '(unnamed)';
    q('progress').replaceChildren(progressBar(job.progress));
    q('size').textContent = `${job.width}×${job.height}`;
    q('spp').textContent = job.spp;
    row.classList.toggle('selected', job.id === state.selected);
    if (job.error) row.title = job.error;
  }

  function renderJobs(jobs) {
    const tbody = $('jobs').tBodies[0];
    const sorted = [...jobs].sort((a, b) => b.id - a.id);  // newest first
    const seen = new Set();
    sorted.forEach((job, i) => {
      seen.add(job.id);
      let row = state.jobRows.get(job.id);
      if (!row) state.jobRows.set(job.id, (row = jobRow(job)));
      updateJobRow(row, job);
      if (tbody.children[i] !== row) tbody.insertBefore(row, tbody.children[i] || null);
    });
    for (const [id, row] of state.jobRows)
      if (!seen.has(id)) {
        row.remove();
        state.jobRows.delete(id);
      }
    $('jobs-empty').hidden = jobs.length > 0;
    $('jobs-empty').textContent = 'No jobs yet: submit a scene bundle below.';
  }

  async function cancelJob(id) {
    try {
      await api(`/api/v1/jobs/${id}`, { method: 'DELETE' });
      clearBanner('action');
    } catch (e) {
      if (e.status === 401) unauthorized();
      else showBanner('action', `Could not cancel job #${id}: ${e.message}`);
    }
    refreshSoon();
  }

  // ---- the selected job ---------------------------------------------------------------------

  function clearDetail() {
    state.selected = null;
    state.image.job = null;
    state.image.key = '';
    $('preview').removeAttribute('src');
    $('detail-title').textContent = 'Job';
    $('detail-body').hidden = true;
    $('detail-empty').hidden = false;
  }

  function select(id) {
    state.selected = id;
    for (const [jid, row] of state.jobRows) row.classList.toggle('selected', jid === id);
    refreshSoon();
  }

  function renderDetail(job) {
    $('detail-title').textContent = `Job #${job.id}${job.name ? ` · ${job.name}` : ''}`;
    $('detail-empty').hidden = true;
    $('detail-body').hidden = false;
    $('detail').dataset.state = job.state;
    const err = $('detail-error');
    err.hidden = !job.error;
    err.textContent = job.error ? `Error: ${job.error}` : '';
    facts($('detail-facts'), [
      ['State', job.state],
      ['Progress', `${percent(job.progress)}% (${count(job.samples_done)} of ${count(job.samples_total)} samples)`],
      ['Work units', `${count(job.units_done)} of ${count(job.units_total)}` +
        ` (${job.tiles} tiles × ${job.passes} passes)`],
      ['Size', `${job.width}×${job.height}, ${job.spp} spp`],
      ['Elapsed', duration(job.elapsed_seconds)],
      ['Speed', job.samples_per_second ? `${count(Math.round(job.samples_per_second))} samples/s` : undefined],
      ['Noise (est. relMSE)', typeof job.noise_estimate === 'number' ? job.noise_estimate.toPrecision(3) +
        (job.target_error ? ` (target ${job.target_error})` : '') : undefined],
      ['Stopped at target', job.stopped_at_target ? `yes, at ${job.spp_done} spp` : undefined],
      ['Remaining', LIVE.has(job.state) ? duration(job.eta_seconds) : undefined],
      ['Submitted', job.created > 1e9 ? new Date(job.created * 1000).toLocaleString() : undefined],
      ['Leases issued', job.leases_issued === undefined ? undefined : count(job.leases_issued)],
      ['Duplicate results', count(job.duplicate_results)],
      ['Result data', bytes(job.result_bytes)],
      ['NaN/Inf samples dropped', job.nonfinite_samples ? count(job.nonfinite_samples) : undefined],
    ]);
    const tbody = $('detail-workers').tBodies[0];
    tbody.replaceChildren(...(job.workers || []).map((w) => el('tr', {},
      el('td', {}, w.name ? `${w.name} (#${w.id})` : `#${w.id}`), el('td', { className: 'num' }, count(w.samples)),
      el('td', { className: 'num' }, `${(100 * (w.share || 0)).toFixed(1)}%`))));
    if (!tbody.children.length) tbody.append(el('tr', {}, el('td', { colSpan: 3, className: 'muted' }, 'none yet')));
    const s = { scene_file: job.scene_file, ...(job.settings || {}) };
    facts($('detail-settings'), Object.entries(s)
      .filter(([, v]) => v !== '' && v !== null && !(typeof v === 'object' && !Object.keys(v).length))
      .map(([k, v]) => [k, typeof v === 'object' ? JSON.stringify(v) : v]));
  }

  // The PNG is fetched (the <img> cannot send the token) only when the job has new samples, and
  // no more often than every five times its last download took.
  // A denoised job's image can be shown denoised: while it runs a denoised preview (202 while the
  // coordinator makes one), once done the final denoised image.
  async function refreshImage(job) {
    const denoise = Boolean(job.settings && job.settings.denoise);
    $('image-choice').hidden = !denoise;
    const kind = denoise ? state.image.kind : 'raw';
    const key = `${job.id}:${job.samples_done}:${job.state}:${kind}`;
    const img = $('preview');
    if (job.samples_done === 0 || key === state.image.key || state.image.busy) return;
    if (job.id === state.image.job && performance.now() < state.image.next) return;
    state.image.busy = true;
    const started = performance.now();
    try {
      const res = await api(`/api/v1/jobs/${job.id}/image?format=png${kind === 'denoised' ? '&denoised=1' : ''}`);
      if (state.selected !== job.id) return;  // the user moved on meanwhile
      if (res.status === 202) {  // being denoised: ask again in a second
        $('image-note').textContent = 'being denoised…';
        state.image.next = performance.now() + 1000;
        return;
      }
      $('image-note').textContent = '';
      const blob = await res.blob();
      const old = state.image.url;
      state.image.url = URL.createObjectURL(blob);
      state.image.job = job.id;
      state.image.key = key;
      state.image.next = performance.now() + 4 * (performance.now() - started);
      // For people and the browser test alike: which job's image is this, and is it the final one.
      img.onload = () => {
        if (old) URL.revokeObjectURL(old);
        img.dataset.jobId = job.id;
        img.dataset.kind = kind;
        img.dataset.complete = String(job.samples_done >= job.samples_total);
      };
      img.src = state.image.url;
    } catch (e) {
      if (e.status === 401) unauthorized();
      // else: keep the last image; the next poll tries again
    } finally {
      state.image.busy = false;
    }
  }

  async function refreshDetail() {
    const job = await apiJson(`/api/v1/jobs/${state.selected}`);
    if (job.id !== state.selected) return;
    if (job.id !== state.image.job) {
      const img = $('preview');
      img.removeAttribute('src');  // not another job's picture under this title
      delete img.dataset.jobId;
      delete img.dataset.complete;
      state.image.key = '';
    }
    renderDetail(job);
    await refreshImage(job);
  }

  // ---- workers ------------------------------------------------------------------------------

  function renderWorkers(workers) {
    const tbody = $('workers').tBodies[0];
    const row = (w) => el('tr', { dataset: { workerId: w.id, state: w.state } },
      el('td', { className: 'num' }, `#${w.id}`), el('td', {}, w.name), el('td', {}, badge(w.state)),
      el('td', { className: 'num' }, w.threads), el('td', { className: 'num' }, count(w.units_done)),
      el('td', { className: 'num' }, rate(w.samples_per_second)),
      el('td', { className: 'num', title: `${w.scenes_loaded || 0} scene(s) loaded, budget ${bytes(w.memory_budget_bytes)}` },
        bytes(w.scene_memory_bytes)));
    tbody.replaceChildren(...[...workers].sort((a, b) => a.id - b.id).map(row));
    $('workers-empty').hidden = workers.length > 0;
    $('workers-empty').textContent = 'No workers registered.';
  }

  // ---- polling ------------------------------------------------------------------------------

  async function refreshHealth() {
    try {
      const h = await (await fetch('/healthz', { cache: 'no-store' })).json();
      $('health').textContent = `tessera-server ${h.version} · up ${duration(h.uptime_seconds)} · ` +
        `${h.jobs_active} active job${h.jobs_active === 1 ? '' : 's'} · ${h.leases} lease${h.leases === 1 ? '' : 's'}`;
    } catch (_) {
      $('health').textContent = 'coordinator unreachable';
    }
  }

  async function refresh() {
    refreshHealth();
    try {
      const [jobs, workers] = await Promise.all([apiJson('/api/v1/jobs'), apiJson('/api/v1/workers')]);
      clearBanner('auth', 'offline', 'error');
      renderJobs(jobs.jobs);
      renderWorkers(workers.workers);
      if (state.selected === null && jobs.jobs.length) select(Math.max(...jobs.jobs.map((j) => j.id)));
      if (state.selected !== null && state.jobRows.has(state.selected)) await refreshDetail();
    } catch (e) {
      reportRefreshError(e);
    }
  }

  async function tick() {
    if (state.running) {
      state.again = true;
      return;
    }
    state.running = true;
    try {
      await refresh();
    } finally {
      state.running = false;
      schedule(state.again ? 0 : document.hidden ? HIDDEN_POLL_MS : POLL_MS);
      state.again = false;
    }
  }

  function schedule(ms) {
    clearTimeout(state.timer);
    state.timer = setTimeout(tick, ms);
  }

  // During a refresh, one more follows it at once; otherwise one starts now.
  function refreshSoon() {
    if (state.running) state.again = true;
    else schedule(0);
  }

  // ---- forms --------------------------------------------------------------------------------

  function setToken(token) {
    state.token = token;
    if (token) sessionStorage.setItem(TOKEN_KEY, token);
    else sessionStorage.removeItem(TOKEN_KEY);
    $('token').value = token;
    state.image.key = '';
    refreshSoon();
  }

  // The settings travel as a JSON part beside the bundle file, as `curl -F settings=...` sends them.
  async function submitJob(ev) {
    ev.preventDefault();
    const out = $('submit-result');
    const file = $('bundle').files[0];
    if (!file) return;
    const settings = {};
    const text = (id) => $(id).value.trim();
    if (text('job-name')) settings.name = text('job-name');
    if (text('scene-file')) settings.scene_file = text('scene-file');
    // Every field a person sets by hand (docs/api.md, JobRequest); an empty box leaves the default.
    for (const field of ['width', 'height', 'spp', 'priority', 'seed'])
      if (text(field) !== '') settings[field] = Number(text(field));
    if (text('target-error') !== '') settings.target_error = Number(text('target-error'));
    for (const [id, field] of [['integrator', 'integrator'], ['light-selection', 'light_selection'],
      ['denoise-mode', 'denoise_mode']])
      if (text(id)) settings[field] = text(id);
    if (text('guiding')) settings.guiding = text('guiding') === 'on';
    if ($('adaptive').checked) settings.adaptive = true;
    if ($('denoise').checked) settings.denoise = true;
    const form = new FormData();
    form.append('settings', new Blob([JSON.stringify(settings)], { type: 'application/json' }), 'settings.json');
    form.append('bundle', file, file.name);
    $('submit-button').disabled = true;
    out.className = 'muted';
    out.textContent = `Uploading ${file.name} (${bytes(file.size)})…`;
    try {
      const job = await apiJson('/api/v1/jobs', { method: 'POST', body: form });
      out.className = 'ok-text';
      out.textContent = `Submitted job #${job.id}: ${job.tiles} tiles × ${job.passes} passes.`;
      out.dataset.jobId = job.id;
      $('bundle').value = '';
      select(job.id);
    } catch (e) {
      out.className = 'error-text';
      out.textContent = e.status === 401 ? 'Refused (401): paste the client token first.'
        : e instanceof ApiError ? `Refused (${e.status}): ${e.message}` : `Upload failed: ${e.message}`;
      if (e.status === 401) unauthorized();
    } finally {
      $('submit-button').disabled = false;
    }
  }

  $('token').value = state.token;
  $('token-form').addEventListener('submit', (ev) => {
    ev.preventDefault();
    setToken($('token').value.trim());
  });
  $('token-forget').addEventListener('click', () => setToken(''));
  $('submit-form').addEventListener('submit', submitJob);
  for (const radio of document.querySelectorAll('input[name="image-kind"]')) {
    radio.addEventListener('change', () => {
      state.image.kind = radio.value;
      state.image.key = '';
      state.image.next = 0;
      refreshSoon();
    });
  }
  document.addEventListener('visibilitychange', () => !document.hidden && refreshSoon());
  tick();
})();
