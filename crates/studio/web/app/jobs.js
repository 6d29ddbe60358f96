// Jobs: a panel action posts to the server and follows the job over its event stream; the page
// shows its progress, status and error, and `ready()` (the test hooks) waits for the latest one.
import { $, S, setStatus, showError, clearError } from './store.js';
import { requestRender } from './viewer.js';

// The latest job's promise, how many were started, the server's upload cap, the job a Cancel stops.
export const jobState = { pending: Promise.resolve(), started: 0, maxUpload: 512e6, currentJob: null };

// Starts a job: `work` is an async function; ready() follows the most recent one.
export function start(kind, work) {
  const clickedAt = performance.now();
  jobState.started += 1;
  const p = (async () => {
    try {
      const r = await work();
      if (r && r.ok) {
        clearError();
        const redraw = performance.now() - clickedAt;
        S.lastJob = {
          kind: r.kind || kind, ms: r.ms, ok: true, message: r.message,
          error_cm: r.error_cm ?? null, ratio: r.ratio ?? null, bytes: r.bytes ?? null, redraw_ms: redraw,
          masked_mse: r.masked_mse ?? null,
        };
        setStatus(r.message);
      }
    } catch (e) {
      const d = e.job || {};
      S.lastJob = { kind: d.kind || kind, ms: d.ms ?? null, ok: false, message: e.message, error_cm: null, ratio: null, bytes: null, redraw_ms: performance.now() - clickedAt };
      if (e.cancelled) { setStatus(`${kind}: cancelled after ${(d.ms ?? 0).toFixed(0)} ms`); }
      else { showError(e.message); setStatus(`${kind}: failed`); }
    } finally {
      $('progress').hidden = true;
      requestRender();
    }
  })();
  jobState.pending = p;
  return p;
}

const capText = () => `this studio's upload cap of ${(jobState.maxUpload / 1e6).toFixed(0)} MB (start it with --max-upload SIZE)`;

export async function post(url, body, headers = { 'content-type': 'application/json' }) {
  const r = await fetch(url, { method: 'POST', headers, body: typeof body === 'string' || body instanceof Blob || body instanceof ArrayBuffer ? body : JSON.stringify(body) });
  if (r.status === 413) throw new Error(`${decodeURIComponent(url.split('name=')[1] || url)}: larger than ${capText()}`);
  let j;
  try { j = await r.json(); } catch { throw new Error(`${url}: HTTP ${r.status} ${r.statusText}`); }
  if (!r.ok) { const e = new Error(j.error || `HTTP ${r.status}`); throw e; }
  return j;
}

function follow(id) {
  jobState.currentJob = id;
  return new Promise((resolve, reject) => {
    const es = new EventSource(`/api/jobs/${id}/events`);
    es.addEventListener('progress', (e) => {
      const d = JSON.parse(e.data);
      $('progress').hidden = false;
      $('progress-text').textContent = d.stage;
      $('progress-bar').value = d.fraction;
    });
    es.addEventListener('result', (e) => { es.close(); resolve(JSON.parse(e.data)); });
    es.addEventListener('failed', (e) => {
      es.close();
      const d = JSON.parse(e.data);
      const err = new Error(d.error); err.job = d; reject(err);
    });
    es.addEventListener('cancelled', (e) => {
      es.close();
      const err = new Error('cancelled'); err.job = JSON.parse(e.data); err.cancelled = true; reject(err);
    });
    es.onerror = () => { es.close(); reject(new Error('lost the connection to the studio server')); };
  });
}

// A job the server finished before answering comes back in the same response (`event`, `data`);
// a longer one is followed over its event stream.
export async function job(url, body, headers) {
  const j = await post(url, body, headers);
  if (j.job && j.event) {
    jobState.currentJob = j.job;
    if (j.event === 'result') return j.data;
    const err = new Error(j.event === 'cancelled' ? 'cancelled' : j.data.error);
    err.job = j.data; err.cancelled = j.event === 'cancelled';
    throw err;
  }
  return j.job ? follow(j.job) : j;
}

// Refuses a file over the server's upload cap before sending it.
export function uploadCheck(f) {
  if (f.size > jobState.maxUpload) throw new Error(`${f.name}: ${(f.size / 1e6).toFixed(1)} MB is larger than ${capText()}`);
}

// Sends file `f` to `url` (its name in the query, `extra` appended) as a job.
export function uploadJob(url, f, extra = '') {
  uploadCheck(f);
  return job(`${url}?name=${encodeURIComponent(f.name)}${extra}`, f, { 'content-type': 'application/octet-stream' });
}

$('cancel').addEventListener('click', () => { if (jobState.currentJob) fetch(`/api/jobs/${jobState.currentJob}/cancel`, { method: 'POST' }); });
