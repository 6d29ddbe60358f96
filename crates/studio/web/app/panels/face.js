// The face panel: open a blendshape take, mark a span, and let the engine's EditJob fill it (keys
// drawn on the curves, a guide track, text or visemes); variants to pick from, undo and redo; the
// curves and two schematic faces (original, edited) at the playhead.
import { $, S, panels, capture, showError, clearError, downloadLink, fileName } from '../store.js';
import { start, job, post, uploadJob } from '../jobs.js';
import { drawTimeline } from '../timeline.js';
import { seek } from '../playback.js';

const faceCorpus = $('face-corpus');
export async function loadFaceCorpus() {
  const r = await (await fetch('/api/face/corpus')).json();
  faceCorpus.innerHTML = '<option value="">(choose a take)</option>';
  for (const f of [...r.builtin, ...r.files]) {
    const o = document.createElement('option'); o.value = f; o.textContent = f; faceCorpus.appendChild(o);
  }
}
faceCorpus.addEventListener('change', () => {
  const path = faceCorpus.value;
  if (path) start('face-open', async () => { const r = await job('/api/face/open', { path }); drawFaceTake(r); return r; });
});
$('face-file').addEventListener('change', (e) => {
  const f = e.target.files[0];
  if (f) start('face-open', async () => { const r = await uploadJob('/api/face/upload', f); drawFaceTake(r); return r; });
});
$('face-guide').addEventListener('change', (e) => {
  const f = e.target.files[0];
  if (f) start('face-guide', async () => {
    const r = await uploadJob('/api/face/guide', f);
    $('face-constraint').value = r.phonemes ? 'visemes' : 'noisy';
    return r;
  });
});

// The span in seconds of the file's own time (from its first row).
export function faceMask() {
  const a = parseFloat($('face-mask-start').value), b = parseFloat($('face-mask-end').value);
  return [Math.min(a, b), Math.max(a, b)];
}
for (const id of ['face-mask-start', 'face-mask-end', 'face-groups']) $(id).addEventListener('change', () => { drawTimeline(); drawFaceView(); });

function exportLink(url) {
  const ex = $('face-export');
  ex.innerHTML = '';
  downloadLink(ex, url).textContent = `export ${fileName(url)}`;
}

function drawFaceTake(r) {
  const f = S.face;
  f.take = r; f.fps = r.fps; f.frames = r.frames; f.keys = []; f.changed = []; f.lastEdit = null; f.version = 0; f.versions = 1;
  drawVariants(null);
  f.orig = r.columns;
  f.cur = Object.fromEntries(Object.entries(r.columns).map(([k, v]) => [k, v.slice()]));
  $('face-take').textContent = `${r.name}: ${r.frames} rows at ${r.fps.toFixed(3)} fps, ${r.duration_s.toFixed(2)} s.`;
  const dur = r.duration_s;
  if (parseFloat($('face-mask-end').value) > dur) { $('face-mask-start').value = (dur * 0.4).toFixed(2); $('face-mask-end').value = Math.min(dur, dur * 0.4 + 2).toFixed(2); }
  exportLink(r.files.export);
  updateKeysCount();
  S.frame = 0; seek(0);
}

function faceRequest() {
  const [a, b] = faceMask();
  const byTime = new Map();
  for (const k of S.face.keys) {
    if (k.time_s < a || k.time_s > b) continue;
    const e = byTime.get(k.time_s) || { time_s: k.time_s, shapes: {} };
    e.shapes[k.shape] = k.value; byTime.set(k.time_s, e);
  }
  return {
    start_s: a, end_s: b, constraint: $('face-constraint').value, text: $('face-text').value,
    keys: [...byTime.values()], groups: $('face-groups').value || 'all', method: $('face-method').value,
    seed: parseInt($('face-seed').value, 10) || 0,
    variants: Math.min(6, Math.max(1, parseInt($('face-variants-count').value, 10) || 1)),
  };
}

function applyColumns(r) {
  const f = S.face;
  const [a] = r.rows;
  f.changed = [];
  for (const [name, vals] of Object.entries(r.columns)) {
    const col = f.cur[name];
    let moved = 0;
    for (let i = 0; i < vals.length; i++) { moved = Math.max(moved, Math.abs(vals[i] - f.orig[name][a + i])); col[a + i] = vals[i]; }
    f.changed.push([name, moved]);
  }
  f.changed.sort((p, q) => q[1] - p[1]);
  f.version = r.version; f.versions = r.versions;
  exportLink(r.files.export);
}

function runFaceEdit() {
  return start('face-edit', async () => {
    if (!S.face.take) throw new Error('open a face take first');
    const r = await job('/api/face/edit', faceRequest());
    applyColumns(r);
    S.face.lastEdit = { method: r.method, masked_mse: r.masked_mse, mask: r.mask, ms: r.ms };
    drawVariants(r.variants);
    drawTimeline(); drawFaceView();
    return r;
  });
}

// The fills of an edit with variants, each a thumbnail of the two curves the first fill moved most
// (grey: original, blue: this variant) over the rows it changed; a click makes it the version shown.
function drawVariants(variants) {
  const f = S.face, box = $('face-variants');
  box.innerHTML = '';
  f.variants = variants || null; f.picked = variants ? 1 : null;
  if (!variants) return;
  const names = f.changed.filter(([, m]) => m > 1e-4).slice(0, 2).map(([n]) => n);
  for (const v of variants) {
    const b = document.createElement('button');
    b.className = 'variant' + (v.variant === 1 ? ' picked' : '');
    b.dataset.testid = `face-variant-${v.variant}`;
    b.dataset.variant = v.variant;
    const cv = document.createElement('canvas'); cv.width = 120; cv.height = 40;
    const c = cv.getContext('2d'), [a, e] = v.rows, n = Math.max(2, e - a);
    c.fillStyle = '#1b1d22'; c.fillRect(0, 0, cv.width, cv.height);
    names.forEach((name, k) => {
      // One scale per curve for every variant, so thumbnails compare.
      let lo = Infinity, hi = -Infinity;
      for (const w of variants) {
        const col = w.columns[name] || [];
        for (let i = 0; i < col.length; i++) { lo = Math.min(lo, col[i], f.orig[name][w.rows[0] + i] ?? col[i]); hi = Math.max(hi, col[i], f.orig[name][w.rows[0] + i] ?? col[i]); }
      }
      if (!(hi - lo > 0.05)) { const m = Number.isFinite(lo) ? (lo + hi) / 2 : 0.5; lo = m - 0.025; hi = m + 0.025; }
      const y0 = k * 20, line = (val, colr) => {
        c.strokeStyle = colr; c.beginPath();
        for (let i = 0; i < n; i++) { const x = 120 * i / (n - 1), y = y0 + 18 - 16 * (val(i) - lo) / (hi - lo); i ? c.lineTo(x, y) : c.moveTo(x, y); }
        c.stroke();
      };
      line((i) => f.orig[name][a + i] ?? 0, '#8a8f98');
      const col = v.columns[name];
      if (col) line((i) => col[i] ?? 0, '#4da3ff');
    });
    const label = document.createElement('span');
    label.innerHTML = `#${v.variant} · seed ${v.seed}<br>MSE ${v.masked_mse.toFixed(4)}`;
    b.append(cv, label);
    b.title = names.length ? `${names.join(', ')} inside the span` : 'no curve moved';
    b.addEventListener('click', () => pickVariant(v.variant));
    box.appendChild(b);
  }
}
function pickVariant(k) {
  return start('face-pick', async () => {
    const r = await post('/api/face/pick', { variant: k });
    applyColumns(r);
    S.face.picked = k;
    for (const b of $('face-variants').children) b.classList.toggle('picked', Number(b.dataset.variant) === k);
    drawTimeline(); drawFaceView();
    return r;
  });
}
$('face-generate').addEventListener('click', runFaceEdit);
for (const step of ['undo', 'redo']) {
  $(`face-${step}`).addEventListener('click', () => start(`face-${step}`, async () => {
    const r = await post('/api/face/history', { step });
    applyColumns(r);
    drawTimeline(); drawFaceView();
    return r;
  }));
}

// Groups of the panel's text field, as in `face edit --groups`.
function selectedGroups() {
  const words = ($('face-groups').value || 'all').toLowerCase().split(',').map((w) => w.trim()).filter(Boolean);
  const out = new Set();
  for (const w of words) {
    if (w === 'all') ['eyes', 'brows', 'jaw', 'mouth', 'cheeks', 'tongue'].forEach((g) => out.add(g));
    else if (w === 'upper') ['eyes', 'brows'].forEach((g) => out.add(g));
    else if (w === 'lower') ['jaw', 'mouth', 'cheeks', 'tongue'].forEach((g) => out.add(g));
    else out.add(w);
  }
  return out;
}

// Six curves of the selected groups (the ones the last edit moved most first, then the most active)
// and the six lip / eyelid distances, over the span ± 2 s.
const CURVE_ROWS = 6;
function faceCurves() {
  const f = S.face, groupsOf = f.take.groups, sel = selectedGroups();
  const inSel = (n) => sel.has(groupsOf[n]);
  const moved = f.changed.filter(([n, m]) => m > 1e-4 && inSel(n)).map(([n]) => n);
  const spread = (n) => { const v = f.orig[n]; let lo = 1, hi = 0; for (let i = 0; i < v.length; i += 4) { lo = Math.min(lo, v[i]); hi = Math.max(hi, v[i]); } return hi - lo; };
  const rest = Object.keys(f.orig).filter((n) => inSel(n) && !moved.includes(n)).sort((p, q) => spread(q) - spread(p));
  return [...moved, ...rest].slice(0, CURVE_ROWS);
}
function distancesAt(cols, f) {
  const t = S.face.take, W = t.distance_matrix, names = Object.keys(cols), k = t.distance_bases.length;
  const d = t.distance_bases.slice();
  const arkit = Object.keys(t.groups);
  for (let c = 0; c < arkit.length; c++) {
    const x = cols[arkit[c]][f];
    if (!x) continue;
    for (let j = 0; j < k; j++) d[j] += x * W[c * k + j];
  }
  void names;
  return d;
}

let faceLayout = null;
export function drawFaceView() {
  if (S.panel !== 'face') return;
  const cv = $('face-curves');
  const w = cv.clientWidth, h = cv.clientHeight;
  if (cv.width !== w) cv.width = w;
  if (cv.height !== h) cv.height = h;
  const c = cv.getContext('2d');
  c.fillStyle = '#1b1d22'; c.fillRect(0, 0, w, h);
  const f = S.face;
  c.font = '11px system-ui, sans-serif';
  if (!f.take) { c.fillStyle = '#8a919c'; c.fillText('Open a face take (Live Link Face CSV, curve CSV or JSON).', 20, 30); drawFaces(); return; }
  const times = f.take.times, n = times.length;
  const [ma, mb] = faceMask();
  const t0 = Math.max(0, ma - 2), t1 = Math.min(times[n - 1], mb + 2);
  const rowOf = (t) => { let lo = 0, hi = n - 1; while (lo < hi) { const m = (lo + hi) >> 1; if (times[m] < t) lo = m + 1; else hi = m; } return lo; };
  const r0 = rowOf(t0), r1 = Math.min(n - 1, rowOf(t1));
  const L = 120, R = 10;
  const X = (t) => L + (w - L - R) * (t - t0) / Math.max(1e-9, t1 - t0);
  const curves = faceCurves();
  const rows = curves.length + 6, rh = (h - 20) / rows;
  faceLayout = { L, R, t0, t1, rh, curves, X, rowOf };
  c.fillStyle = 'rgba(255, 196, 0, 0.18)'; c.fillRect(X(ma), 0, X(mb) - X(ma), h);
  const step = Math.max(1, Math.floor((r1 - r0) / (w - L)));
  const plot = (vals, y0, lo, hi, colr) => {
    c.strokeStyle = colr; c.beginPath();
    for (let i = r0; i <= r1; i += step) { const px = X(times[i]), py = y0 + rh - 4 - (rh - 10) * (vals(i) - lo) / (hi - lo); i === r0 ? c.moveTo(px, py) : c.lineTo(px, py); }
    c.stroke();
  };
  curves.forEach((name, k) => {
    const y0 = 16 + k * rh;
    c.strokeStyle = '#2c3038'; c.beginPath(); c.moveTo(L, y0 + rh - 2); c.lineTo(w - R, y0 + rh - 2); c.stroke();
    c.fillStyle = '#aab1bc'; c.fillText(name, 4, y0 + rh / 2 + 4);
    plot((i) => f.orig[name][i], y0, 0, 1, '#8a8f98');
    c.lineWidth = 1.5; plot((i) => f.cur[name][i], y0, 0, 1, '#4da3ff'); c.lineWidth = 1;
    c.fillStyle = '#ffd84d';
    for (const key of f.keys) if (key.shape === name) { c.beginPath(); c.arc(X(key.time_s), y0 + rh - 4 - (rh - 10) * key.value, 4, 0, 7); c.fill(); }
  });
  const dn = f.take.distance_names;
  const dOrig = [], dCur = [];
  for (let i = r0; i <= r1; i += step) { dOrig[i] = distancesAt(f.orig, i); dCur[i] = distancesAt(f.cur, i); }
  dn.forEach((name, k) => {
    const y0 = 16 + (curves.length + k) * rh;
    let lo = Infinity, hi = -Infinity;
    for (let i = r0; i <= r1; i += step) { lo = Math.min(lo, dOrig[i][k], dCur[i][k]); hi = Math.max(hi, dOrig[i][k], dCur[i][k]); }
    if (hi - lo < 0.05) { lo -= 0.025; hi += 0.025; }
    c.strokeStyle = '#2c3038'; c.beginPath(); c.moveTo(L, y0 + rh - 2); c.lineTo(w - R, y0 + rh - 2); c.stroke();
    c.fillStyle = '#c9b6ff'; c.fillText(name.replace(/_/g, ' '), 4, y0 + rh / 2 + 4);
    const at = (arr) => (i) => { let j = i; while (j > r0 && !arr[j]) j--; return arr[j][k]; };
    plot(at(dOrig), y0, lo, hi, '#8a8f98');
    c.lineWidth = 1.5; plot(at(dCur), y0, lo, hi, '#c9b6ff'); c.lineWidth = 1;
  });
  c.fillStyle = '#6d7480';
  for (let s = Math.ceil(t0); s <= t1; s += 1) { c.fillText(`${s}s`, X(s) + 2, 11); c.strokeStyle = '#2c3038'; c.beginPath(); c.moveTo(X(s), 14); c.lineTo(X(s), h); c.stroke(); }
  const tp = times[S.frame];
  if (tp >= t0 && tp <= t1) { c.strokeStyle = '#4da3ff'; c.lineWidth = 2; c.beginPath(); c.moveTo(X(tp), 0); c.lineTo(X(tp), h); c.stroke(); c.lineWidth = 1; }
  drawFaces();
}

// The schematic face of one version at the playhead: eyelids and lips from the six distances,
// brows and gaze from their shapes.
function drawFace(cv, cols) {
  const c = cv.getContext('2d'), W = cv.width, H = cv.height;
  c.fillStyle = '#23262d'; c.fillRect(0, 0, W, H);
  if (!cols) return;
  const f = S.frame, d = distancesAt(cols, f), v = (n) => (cols[n] ? cols[n][f] : 0);
  const cx = W / 2, cy = H / 2 + 6;
  c.fillStyle = '#e2c4a8'; c.beginPath(); c.ellipse(cx, cy, 80, 104, 0, 0, 7); c.fill();
  for (const side of [-1, 1]) {
    const L = side < 0, ex = cx + side * 34, ey = cy - 24;
    const open = Math.max(0, Math.min(1.4, d[L ? 4 : 5]));
    c.fillStyle = '#fff'; c.beginPath(); c.ellipse(ex, ey, 17, Math.max(0.8, 10 * open), 0, 0, 7); c.fill();
    if (open > 0.15) {
      const gx = (v(L ? 'EyeLookOutLeft' : 'EyeLookInRight') - v(L ? 'EyeLookInLeft' : 'EyeLookOutRight')) * 8 * side;
      const gy = (v(L ? 'EyeLookDownLeft' : 'EyeLookDownRight') - v(L ? 'EyeLookUpLeft' : 'EyeLookUpRight')) * 5;
      c.fillStyle = '#3a2a1e'; c.beginPath(); c.arc(ex + gx, ey + gy, Math.min(6, 10 * open), 0, 7); c.fill();
    }
    c.strokeStyle = '#5a3a25'; c.lineWidth = 3;
    const inner = v('BrowInnerUp') * 12 - v(L ? 'BrowDownLeft' : 'BrowDownRight') * 8;
    const outer = v(L ? 'BrowOuterUpLeft' : 'BrowOuterUpRight') * 12 - v(L ? 'BrowDownLeft' : 'BrowDownRight') * 4;
    c.beginPath(); c.moveTo(ex - side * 16, ey - 20 - inner); c.lineTo(ex + side * 18, ey - 18 - outer); c.stroke();
  }
  const mw = 26 * Math.max(0.4, d[3]), my = cy + 46;
  const smileL = (v('MouthSmileLeft') - v('MouthFrownLeft')) * 10, smileR = (v('MouthSmileRight') - v('MouthFrownRight')) * 10;
  const gap = (k) => Math.max(0, d[k]) * 30;
  c.fillStyle = '#7a2e2e'; c.strokeStyle = '#a04848'; c.lineWidth = 3;
  c.beginPath();
  c.moveTo(cx - mw, my - smileL);
  c.quadraticCurveTo(cx - mw / 2, my - 4 - gap(0) * 0.3, cx, my - 3 - gap(1) * 0.3);
  c.quadraticCurveTo(cx + mw / 2, my - 4 - gap(2) * 0.3, cx + mw, my - smileR);
  c.quadraticCurveTo(cx + mw / 2, my + 3 + gap(2) * 0.7, cx, my + 3 + gap(1) * 0.7);
  c.quadraticCurveTo(cx - mw / 2, my + 3 + gap(0) * 0.7, cx - mw, my - smileL);
  c.closePath(); c.fill(); c.stroke(); c.lineWidth = 1;
}
function drawFaces() {
  drawFace($('face-original'), S.face.orig);
  drawFace($('face-edited'), S.face.cur);
}

// Keys: click a curve inside the span (keyframes constraint), drag to move, right-click to delete.
const faceCv = $('face-curves');
let dragKey = null;
function curveHit(e) {
  if (!faceLayout || !S.face.take) return null;
  const r = faceCv.getBoundingClientRect(), x = e.clientX - r.left, y = e.clientY - r.top;
  const { L, R, t0, t1, rh, curves } = faceLayout;
  const row = Math.floor((y - 16) / rh);
  if (row < 0 || row >= curves.length || x < L) return null;
  const t = t0 + (x - L) / (r.width - L - R) * (t1 - t0);
  const value = Math.max(0, Math.min(1, (16 + row * rh + rh - 4 - y) / (rh - 10)));
  return { shape: curves[row], t, value, x, y };
}
function nearestKey(hit) {
  const { X, rh, curves } = faceLayout;
  let best = null, bd = 10;
  for (const k of S.face.keys) {
    if (k.shape !== hit.shape) continue;
    const row = curves.indexOf(k.shape);
    const dx = X(k.time_s) - hit.x, dy = (16 + row * rh + rh - 4 - (rh - 10) * k.value) - hit.y;
    const dd = Math.hypot(dx, dy);
    if (dd < bd) { bd = dd; best = k; }
  }
  return best;
}
export function updateKeysCount() { $('face-keys-count').textContent = `${S.face.keys.length} key${S.face.keys.length === 1 ? '' : 's'}`; }
faceCv.addEventListener('pointerdown', (e) => {
  const hit = curveHit(e);
  if (!hit) return;
  if (e.button === 2) return;
  const near = nearestKey(hit);
  if (near) { dragKey = near; capture(faceCv, e); return; }
  if ($('face-constraint').value !== 'keys') { seek(faceLayout.rowOf(hit.t)); return; }
  const [a, b] = faceMask();
  if (hit.t < a || hit.t > b) { showError(`a key at ${hit.t.toFixed(2)} s lies outside the span ${a.toFixed(2)}–${b.toFixed(2)} s; keys guide the edit only inside it`); return; }
  clearError();
  const k = { time_s: Math.round(hit.t * 100) / 100, shape: hit.shape, value: Math.round(hit.value * 1000) / 1000 };
  S.face.keys.push(k); dragKey = k; capture(faceCv, e);
  updateKeysCount(); drawFaceView();
});
faceCv.addEventListener('pointermove', (e) => {
  if (!dragKey) return;
  const hit = curveHit(e);
  if (!hit) return;
  const [a, b] = faceMask();
  dragKey.time_s = Math.round(Math.max(a, Math.min(b, hit.t)) * 100) / 100;
  dragKey.value = Math.round(hit.value * 1000) / 1000;
  drawFaceView();
});
faceCv.addEventListener('pointerup', () => { dragKey = null; });
faceCv.addEventListener('contextmenu', (e) => {
  e.preventDefault();
  const hit = curveHit(e); if (!hit) return;
  const near = nearestKey(hit);
  if (near) { S.face.keys = S.face.keys.filter((k) => k !== near); updateKeysCount(); drawFaceView(); }
});
$('face-clear-keys').addEventListener('click', () => { S.face.keys = []; updateKeysCount(); drawFaceView(); });

panels.face = {
  // The take's own row times (Live Link rows are not evenly spaced).
  frameTime: (frame) => (S.face.take ? S.face.take.times[frame] : undefined),
  seek: () => drawFaceView(),
  tick() {
    const cv = $('face-curves');
    if (cv.width !== cv.clientWidth || cv.height !== cv.clientHeight) { drawFaceView(); drawTimeline(); }
  },
  // A drag on the timeline sets the span (seconds of the file's own time).
  timelineDrag(fromFrame, frame) {
    if (!S.face.take) return false;
    const t = S.face.take.times;
    const a = t[Math.round(Math.min(fromFrame, frame))], b = t[Math.round(Math.max(fromFrame, frame))];
    $('face-mask-start').value = a.toFixed(2); $('face-mask-end').value = b.toFixed(2);
    drawTimeline(); drawFaceView();
    return true;
  },
  // The span, and the blink and jaw curves of the current version for orientation.
  timeline(c, x, w, h) {
    const st = S.face;
    if (!st.take) return;
    const [a, b] = faceMask();
    const fa = a * st.fps, fb = b * st.fps;
    c.fillStyle = 'rgba(255, 196, 0, 0.25)'; c.fillRect(x(fa), 14, Math.max(2, x(fb) - x(fa)), h - 14);
    c.fillStyle = '#ffc400'; c.fillText(`span ${a.toFixed(2)}–${b.toFixed(2)} s (drag on the timeline to set it)`, 44, 26);
    for (const [name, col] of [['EyeBlinkLeft', '#9fe0a8'], ['JawOpen', '#ff8c1a']]) {
      const v = st.cur[name]; if (!v) continue;
      c.strokeStyle = col; c.beginPath();
      const step = Math.max(1, Math.floor(v.length / w));
      for (let f = 0; f < v.length; f += step) { const px = x(f), py = h - 6 - (h - 40) * v[f]; f ? c.lineTo(px, py) : c.moveTo(px, py); }
      c.stroke();
    }
    c.fillStyle = '#9fe0a8'; c.fillText('EyeBlinkLeft', 2, h - 20); c.fillStyle = '#ff8c1a'; c.fillText('JawOpen', 2, h - 8);
  },
};
