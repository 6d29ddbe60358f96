// inbetween studio: the page. Plain ES modules, three.js through the import map (index.html).
// Test hooks (crates/studio/README.md): data-testid attributes and window.inbetweenStudio.
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';

const $ = (id) => document.getElementById(id);

// ---------------------------------------------------------------- viewer
const canvas = $('viewport');
const renderer = new THREE.WebGLRenderer({ canvas, antialias: true, preserveDrawingBuffer: true });
renderer.setPixelRatio(1);
const scene = new THREE.Scene();
scene.background = new THREE.Color(0x2b2f37);
scene.add(new THREE.HemisphereLight(0xffffff, 0x444a55, 1.6));
const sun = new THREE.DirectionalLight(0xffffff, 1.8);
sun.position.set(4, 8, 6);
scene.add(sun);
const grid = new THREE.GridHelper(30, 30, 0x59606c, 0x3a3f48);
scene.add(grid);
const orbitCam = new THREE.PerspectiveCamera(45, 1, 0.05, 500);
orbitCam.position.set(6, 5, 9);
const controls = new OrbitControls(orbitCam, canvas);
controls.target.set(2, 0.8, 2);
controls.update();
controls.addEventListener('change', () => requestRender());
const groups = { script: new THREE.Group(), mocap: new THREE.Group() };
scene.add(groups.script, groups.mocap);

let dirty = true;
function requestRender() { dirty = true; }
function resize() {
  const w = canvas.clientWidth, h = canvas.clientHeight;
  if (canvas.width !== w || canvas.height !== h) {
    renderer.setSize(w, h, false);
    orbitCam.aspect = w / Math.max(1, h);
    orbitCam.updateProjectionMatrix();
    if (S.script.shotCam) { S.script.shotCam.aspect = orbitCam.aspect; S.script.shotCam.updateProjectionMatrix(); }
    drawTimeline();
    dirty = true;
  }
}

// ---------------------------------------------------------------- state
const S = {
  panel: 'script',
  playing: false,
  frame: 0,
  lastJob: null,
  script: { result: null, gltf: null, mixer: null, shotCam: null, camHelper: null, fps: 30, frames: 0 },
  mocap: { take: null, keysResult: null, orig: null, rec: null, fps: 30, frames: 0, scale: 0.01 },
};
const panelState = () => S[S.panel];

function setStatus(text) { $('status').textContent = text; }
function showError(msg) { $('error').textContent = msg; }
function clearError() { $('error').textContent = ''; }

// Jobs ---------------------------------------------------------------
let pending = Promise.resolve();
let maxUpload = 512e6;
let currentJob = null;

// Starts a job: `work` is an async function; ready() follows the most recent one.
let started = 0;
function start(kind, work) {
  const clickedAt = performance.now();
  started += 1;
  const p = (async () => {
    try {
      const r = await work();
      if (r && r.ok) {
        clearError();
        const redraw = performance.now() - clickedAt;
        S.lastJob = {
          kind: r.kind || kind, ms: r.ms, ok: true, message: r.message,
          error_cm: r.error_cm ?? null, ratio: r.ratio ?? null, bytes: r.bytes ?? null, redraw_ms: redraw,
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
  pending = p;
  return p;
}

async function post(url, body, headers = { 'content-type': 'application/json' }) {
  const r = await fetch(url, { method: 'POST', headers, body: typeof body === 'string' || body instanceof Blob || body instanceof ArrayBuffer ? body : JSON.stringify(body) });
  if (r.status === 413) throw new Error(`${decodeURIComponent(url.split('name=')[1] || url)}: larger than this studio's upload cap of ${(maxUpload / 1e6).toFixed(0)} MB (start it with --max-upload SIZE)`);
  let j;
  try { j = await r.json(); } catch { throw new Error(`${url}: HTTP ${r.status} ${r.statusText}`); }
  if (!r.ok) { const e = new Error(j.error || `HTTP ${r.status}`); throw e; }
  return j;
}

function follow(id) {
  currentJob = id;
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
async function job(url, body, headers) {
  const j = await post(url, body, headers);
  if (j.job && j.event) {
    currentJob = j.job;
    if (j.event === 'result') return j.data;
    const err = new Error(j.event === 'cancelled' ? 'cancelled' : j.data.error);
    err.job = j.data; err.cancelled = j.event === 'cancelled';
    throw err;
  }
  return j.job ? follow(j.job) : j;
}

$('cancel').addEventListener('click', () => { if (currentJob) fetch(`/api/jobs/${currentJob}/cancel`, { method: 'POST' }); });

// ---------------------------------------------------------------- panels
function showPanel(name) {
  S.panel = name;
  S.playing = false;
  for (const b of document.querySelectorAll('nav button')) b.classList.toggle('active', b.dataset.panel === name);
  for (const p of document.querySelectorAll('section.panel')) p.hidden = p.dataset.panel !== name;
  groups.script.visible = name === 'script';
  groups.mocap.visible = name === 'mocap';
  S.frame = Math.min(S.frame, Math.max(0, panelState().frames - 1));
  seek(S.frame);
  resize();
}
for (const b of document.querySelectorAll('nav button')) b.addEventListener('click', () => showPanel(b.dataset.panel));

// ---------------------------------------------------------------- script panel
const storySelect = $('script-story');
const text = $('script-text');
const backdrop = $('script-backdrop');

async function loadStories() {
  const r = await (await fetch('/api/script/stories')).json();
  for (const s of r.stories) {
    const o = document.createElement('option');
    o.value = s.name; o.textContent = s.name; o.dataset.text = s.text;
    storySelect.appendChild(o);
  }
  storySelect.value = r.default;
  text.value = r.stories.find((s) => s.name === r.default).text;
  syncBackdrop([]);
}
storySelect.addEventListener('change', () => {
  text.value = storySelect.selectedOptions[0].dataset.text;
  syncBackdrop([]);
});
text.addEventListener('input', () => syncBackdrop(S.script.result ? S.script.result.diagnostics : []));
text.addEventListener('scroll', () => { backdrop.scrollTop = text.scrollTop; });
text.addEventListener('keydown', (e) => { if (e.key === 'Enter' && (e.ctrlKey || e.metaKey)) { e.preventDefault(); runScript(); } });
$('script-run').addEventListener('click', () => runScript());
$('script-file').addEventListener('change', (e) => {
  const f = e.target.files[0];
  if (!f) return;
  start('script', async () => {
    text.value = await f.text();
    return runScriptJob();
  });
});
$('script-shotcam').addEventListener('change', () => requestRender());

const esc = (s) => s.replace(/&/g, '&amp;').replace(/</g, '&lt;').replace(/>/g, '&gt;');
// Marks each diagnostic's word in the backdrop behind the text box, on the line it concerns.
function syncBackdrop(diags) {
  const lines = text.value.split('\n');
  const marks = new Map();
  for (const d of diags || []) if (d.word) { const l = d.line - 1; if (!marks.has(l)) marks.set(l, []); marks.get(l).push(d.word.toLowerCase()); }
  backdrop.innerHTML = lines.map((line, i) => {
    let html = esc(line);
    for (const w of marks.get(i) || []) {
      const re = new RegExp(`\\b(${w.replace(/[.*+?^${}()|[\]\\]/g, '\\$&')})\\b`, 'i');
      html = html.replace(re, '<mark>$1</mark>');
    }
    return html;
  }).join('\n') + '\n';
}

function runScript() { return start('script', runScriptJob); }

async function runScriptJob() {
  const t0 = performance.now();
  const r = await job('/api/script/run', { text: text.value, optimize: $('script-optimize').checked });
  const requestMs = performance.now() - t0;
  await drawScript(r);
  S.drawTimes.request_ms = requestMs;
  return r;
}

// Frees the GPU buffers and textures of objects leaving the scene (a story run or a K change
// replaces them; without this every edit would leave its meshes in GPU memory).
function disposeTree(root) {
  root.traverse((o) => {
    if (o.geometry) o.geometry.dispose();
    for (const m of [].concat(o.material || [])) {
      for (const v of Object.values(m)) if (v && v.isTexture) v.dispose();
      m.dispose();
    }
  });
}

function parseGlb(buf) {
  return new Promise((resolve, reject) => new GLTFLoader().parse(buf, '', resolve, (e) => reject(new Error(`glTF: ${e.message || e}`))));
}

async function drawScript(r) {
  const t0 = performance.now();
  const buf = await (await fetch(r.files.glb)).arrayBuffer();
  const t1 = performance.now();
  const gltf = await parseGlb(buf);
  const t2 = performance.now();
  const g = groups.script;
  for (const c of [...g.children]) disposeTree(c);
  g.clear();
  g.add(gltf.scene);
  const st = S.script;
  st.result = r; st.gltf = gltf; st.fps = r.fps; st.frames = r.frames;
  st.mixer = new THREE.AnimationMixer(gltf.scene);
  for (const clip of gltf.animations) st.mixer.clipAction(clip).play();
  st.shotCam = gltf.cameras[0] || null;
  if (st.shotCam) {
    st.shotCam.aspect = orbitCam.aspect; st.shotCam.near = 0.05; st.shotCam.far = 40; st.shotCam.updateProjectionMatrix();
    st.camHelper = new THREE.CameraHelper(st.shotCam);
    g.add(st.camHelper);
  }
  if (!st.framed) {
    // Frame the room once; later runs keep the user's view.
    const box = new THREE.Box3().setFromObject(gltf.scene);
    const c = box.getCenter(new THREE.Vector3()), s = box.getSize(new THREE.Vector3());
    controls.target.copy(c).setY(0.8);
    orbitCam.position.set(c.x + s.x * 0.6 + 2, Math.max(s.x, s.z) * 0.9 + 2, c.z + s.z * 0.9 + 3);
    controls.update();
    st.framed = true;
  }
  // Diagnostics at their words.
  const ul = $('script-diagnostics');
  ul.innerHTML = '';
  for (const d of r.diagnostics) {
    const li = document.createElement('li');
    li.textContent = `line ${d.line}${d.word ? `, "${d.word}"` : ''}: ${d.message}${d.suggestions.length ? ` (did you mean ${d.suggestions.join(', ')}?)` : ''}`;
    ul.appendChild(li);
  }
  for (const n of r.notes || []) { const li = document.createElement('li'); li.textContent = n; ul.appendChild(li); }
  syncBackdrop(r.diagnostics);
  S.drawTimes = { fetch_ms: t1 - t0, parse_ms: t2 - t1, build_ms: performance.now() - t2 };
  // Exports.
  const ex = $('script-export');
  ex.innerHTML = '';
  const link = (href, label) => { const a = document.createElement('a'); a.href = href; a.textContent = label; a.download = label; ex.appendChild(a); };
  link(r.files.glb + '&download=1', 'story.glb');
  link(r.files.gltf + '&download=1', 'story.gltf');
  link(r.files.scene + '&download=1', 'scene.json');
  for (const c of r.characters) link(c.bvh + '&download=1', `${c.name}.bvh`);
  link(URL.createObjectURL(new Blob([JSON.stringify(r, null, 1)], { type: 'application/json' })), 'story.json');
  S.frame = Math.min(S.frame, r.frames - 1);
  seek(S.frame);
  drawTimeline();
  const t3 = performance.now();
  renderNow();
  S.drawTimes.render_ms = performance.now() - t3;
}

// ---------------------------------------------------------------- mocap panel
const corpusSelect = $('mocap-corpus');
async function loadCorpus() {
  const r = await (await fetch('/api/mocap/corpus')).json();
  corpusSelect.innerHTML = '<option value="">(choose a take)</option>';
  for (const f of [...r.builtin, ...r.files]) {
    const o = document.createElement('option'); o.value = f; o.textContent = f; corpusSelect.appendChild(o);
  }
  if (!r.root) { const o = document.createElement('option'); o.disabled = true; o.textContent = '(start with --root DIR to list files)'; corpusSelect.appendChild(o); }
}
corpusSelect.addEventListener('change', () => {
  const path = corpusSelect.value;
  if (path) start('open', async () => { const r = await job('/api/mocap/open', { path }); await drawTake(r); return r; });
});
$('mocap-file').addEventListener('change', (e) => openFiles([...e.target.files]));
canvas.addEventListener('dragover', (e) => e.preventDefault());
canvas.addEventListener('drop', (e) => {
  e.preventDefault();
  if (S.panel !== 'mocap') showPanel('mocap');
  openFiles([...e.dataTransfer.files]);
});

function openFiles(files) {
  if (!files.length) return;
  // ASF first, so the AMC finds its skeleton.
  files.sort((a, b) => (a.name.toLowerCase().endsWith('.asf') ? -1 : 0) - (b.name.toLowerCase().endsWith('.asf') ? -1 : 0));
  start('open', async () => {
    let r;
    for (const f of files) {
      if (f.size > maxUpload) throw new Error(`${f.name}: ${(f.size / 1e6).toFixed(1)} MB is larger than this studio's upload cap of ${(maxUpload / 1e6).toFixed(0)} MB (start it with --max-upload SIZE)`);
      r = await job(`/api/mocap/upload?name=${encodeURIComponent(f.name)}`, f, { 'content-type': 'application/octet-stream' });
    }
    if (r.pending) throw new Error(`${r.pending}: waiting for ${r.need}`);
    await drawTake(r);
    return r;
  });
}

// A take as the server sends it to the viewer: a glTF whose nodes are the joints and whose one
// animation samples every frame. The nodes become bones (so SkeletonHelper draws them) and the
// clip drives them by name.
async function loadTake(url) {
  const gltf = await parseGlb(await (await fetch(url)).arrayBuffer());
  const bones = [];
  const toBone = (node) => {
    const b = new THREE.Bone();
    b.name = node.name; b.position.copy(node.position); b.quaternion.copy(node.quaternion);
    bones.push(b);
    for (const c of node.children) b.add(toBone(c));
    return b;
  };
  toBone(gltf.scene.children[0]);
  return { skeleton: { bones }, clip: gltf.animations[0] };
}

function bvhFigure(result, color, radius) {
  const root = result.skeleton.bones[0];
  const holder = new THREE.Group();
  holder.scale.setScalar(S.mocap.scale);
  holder.add(root);
  const helper = new THREE.SkeletonHelper(root);
  helper.material = new THREE.LineBasicMaterial({ color, depthTest: false });
  const ball = new THREE.SphereGeometry(radius / S.mocap.scale, 10, 8);
  const mat = new THREE.MeshStandardMaterial({ color, roughness: 0.6 });
  for (const b of result.skeleton.bones) b.add(new THREE.Mesh(ball, mat));
  const mixer = new THREE.AnimationMixer(helper);
  mixer.clipAction(result.clip).play();
  return { holder, helper, mixer, root };
}

async function drawTake(r) {
  const m = S.mocap;
  const parsed = await loadTake(r.files.original_glb);
  m.take = r; m.fps = r.fps; m.frames = r.frames; m.scale = r.cm_per_unit / 100; m.keysResult = null;
  const g = groups.mocap;
  for (const c of [...g.children]) disposeTree(c);
  g.clear(); m.rec = null;
  m.orig = bvhFigure(parsed, 0xe8e8e8, 0.025);
  g.add(m.orig.holder, m.orig.helper);
  $('mocap-take').textContent = `${r.name}: ${r.frames} frames at ${r.fps.toFixed(1)} fps, ${r.joints} joints. Length unit: ${r.unit} (${r.unit_reason}).`;
  $('mocap-export').innerHTML = '';
  $('mocap-k').max = r.frames;
  S.frame = 0; seek(0);
  frameTake();
  drawTimeline();
  renderNow();
}

function frameTake() {
  const m = S.mocap;
  m.orig.holder.updateMatrixWorld(true);
  const box = new THREE.Box3();
  // The path of the root over the take, and the body at frame 0.
  const p = new THREE.Vector3();
  for (let f = 0; f < m.frames; f += Math.max(1, Math.floor(m.frames / 40))) {
    m.orig.mixer.setTime(f / m.fps); m.orig.holder.updateMatrixWorld(true);
    for (const b of m.orig.helper.bones) box.expandByPoint(b.getWorldPosition(p));
  }
  m.orig.mixer.setTime(0);
  const c = box.getCenter(new THREE.Vector3()), s = box.getSize(new THREE.Vector3());
  controls.target.copy(c);
  const d = Math.max(s.x, s.y, s.z, 1.5) * 1.3 + 1;
  orbitCam.position.set(c.x + d * 0.8, c.y + d * 0.5, c.z + d);
  controls.update();
}

function keysRequest() {
  return { method: $('mocap-method').value, k: parseInt($('mocap-k').value, 10), bound_cm: parseFloat($('mocap-bound').value) };
}
function runKeys() {
  return start('keys', async () => {
    const r = await job('/api/mocap/keys', keysRequest());
    await drawKeys(r);
    return r;
  });
}
$('mocap-run').addEventListener('click', runKeys);
$('mocap-method').addEventListener('change', () => { if (S.mocap.take) runKeys(); });
$('mocap-k').addEventListener('change', () => { if (S.mocap.take) runKeys(); });
$('mocap-compress').addEventListener('click', () => start('compress', async () => {
  const r = await job('/api/mocap/compress', { bound_cm: parseFloat($('mocap-bound').value) });
  const ex = $('mocap-export');
  for (const a of ex.querySelectorAll('a.compress')) a.remove();
  const link = (href, label) => { const a = document.createElement('a'); a.href = href + '&download=1'; a.textContent = label; a.download = label; a.className = 'compress'; ex.appendChild(a); };
  link(r.files.ibk, r.files.ibk.split('/').pop().split('?')[0]);
  link(r.files.decoded, r.files.decoded.split('/').pop().split('?')[0]);
  return r;
}));

async function drawKeys(r) {
  const m = S.mocap;
  const parsed = await loadTake(r.files.reconstructed_glb);
  if (m.rec) { groups.mocap.remove(m.rec.holder, m.rec.helper); disposeTree(m.rec.holder); disposeTree(m.rec.helper); m.rec.mixer.stopAllAction(); }
  m.rec = bvhFigure(parsed, 0xff8c1a, 0.02);
  groups.mocap.add(m.rec.holder, m.rec.helper);
  m.keysResult = r;
  if (r.method === 'bound') $('mocap-k').value = r.k;
  const ex = $('mocap-export');
  for (const a of ex.querySelectorAll('a.keys, span.muted')) a.remove();
  const a = document.createElement('a'); a.href = r.files.reconstructed + '&download=1'; a.textContent = 'reconstructed.bvh'; a.download = 'reconstructed.bvh'; a.className = 'keys';
  ex.prepend(a);
  seek(S.frame);
  drawTimeline();
  renderNow();
}

// ---------------------------------------------------------------- playback
function seek(frame) {
  const st = panelState();
  const n = Math.max(1, st.frames);
  S.frame = Math.max(0, Math.min(n - 1, Math.round(frame)));
  const t = S.frame / (st.fps || 30);
  if (S.panel === 'script' && st.mixer) {
    st.mixer.setTime(t);
    if (st.camHelper) { st.gltf.scene.updateMatrixWorld(true); st.camHelper.update(); }
  }
  if (S.panel === 'mocap') {
    if (st.orig) st.orig.mixer.setTime(t);
    if (st.rec) st.rec.mixer.setTime(t);
  }
  $('frame').textContent = `${S.frame} / ${Math.max(0, n - 1)}`;
  $('time').textContent = `${t.toFixed(2)} s`;
  drawTimeline();
  requestRender();
}

$('play').addEventListener('click', () => { S.playing = !S.playing; $('play').textContent = S.playing ? '❚❚' : '▶'; last = performance.now(); });
document.addEventListener('keydown', (e) => { if (e.key === ' ' && e.target === document.body) { e.preventDefault(); $('play').click(); } });

let last = performance.now();
let playFrame = 0;
function loop(now) {
  requestAnimationFrame(loop);
  resize();
  if (S.playing) {
    const st = panelState();
    playFrame = (S.frame + (now - last) / 1000 * (st.fps || 30));
    if (playFrame >= st.frames - 1) playFrame = 0;
    seek(playFrame);
  }
  last = now;
  if (dirty) renderNow();
}

function renderNow() {
  dirty = false;
  const st = S.script;
  const useShot = S.panel === 'script' && $('script-shotcam').checked && st.shotCam;
  if (st.camHelper) st.camHelper.visible = !useShot;
  renderer.render(scene, useShot ? st.shotCam : orbitCam);
}

// ---------------------------------------------------------------- timeline
const tl = $('timeline');
const COLORS = ['#d62728', '#1f77b4', '#2ca02c', '#9467bd', '#ff7f0e', '#17becf'];
function drawTimeline() {
  const w = tl.clientWidth, h = tl.clientHeight;
  if (tl.width !== w) tl.width = w;
  if (tl.height !== h) tl.height = h;
  const c = tl.getContext('2d');
  c.fillStyle = '#15171c'; c.fillRect(0, 0, w, h);
  const st = panelState();
  const n = Math.max(1, st.frames);
  const x = (f) => 40 + (w - 50) * (n > 1 ? f / (n - 1) : 0);
  c.font = '11px system-ui, sans-serif';
  // Ruler: seconds.
  c.fillStyle = '#6d7480'; c.strokeStyle = '#2c3038';
  const secs = (n - 1) / (st.fps || 30);
  const step = secs > 60 ? 10 : secs > 20 ? 5 : secs > 5 ? 1 : 0.5;
  for (let s = 0; s <= secs + 1e-9; s += step) {
    const px = x(s * (st.fps || 30));
    c.beginPath(); c.moveTo(px, 0); c.lineTo(px, h); c.stroke();
    c.fillText(`${s}s`, px + 2, 10);
  }
  if (S.panel === 'script' && st.result) {
    const chars = st.result.characters;
    const rowH = Math.min(26, (h - 16) / Math.max(1, chars.length));
    chars.forEach((ch, i) => {
      const y = 14 + i * rowH;
      c.fillStyle = '#aab1bc'; c.fillText(ch.name, 2, y + rowH * 0.65);
      for (const s of ch.segments) {
        c.fillStyle = COLORS[i % COLORS.length] + 'aa';
        c.fillRect(x(s.start), y + 2, Math.max(1, x(s.end) - x(s.start) - 1), rowH - 4);
        c.fillStyle = '#fff';
        const label = s.target ? `${s.verb} ${s.target}` : s.verb;
        const wpx = x(s.end) - x(s.start);
        if (wpx > 24) { c.save(); c.beginPath(); c.rect(x(s.start), y, wpx - 2, rowH); c.clip(); c.fillText(label, x(s.start) + 3, y + rowH * 0.65); c.restore(); }
      }
    });
  }
  if (S.panel === 'mocap' && st.keysResult) {
    const r = st.keysResult;
    const errs = r.per_frame_cm;
    const maxE = Math.max(1e-9, ...errs);
    const top = 40, bottom = h - 14;
    c.strokeStyle = '#ff8c1a'; c.beginPath();
    errs.forEach((e, f) => { const px = x(f), py = bottom - (bottom - top) * e / maxE; f ? c.lineTo(px, py) : c.moveTo(px, py); });
    c.stroke();
    c.fillStyle = '#ff8c1a';
    c.fillText(`error per frame (cm), max ${maxE.toFixed(2)} cm`, 44, top - 4);
    c.fillText('0 cm', 2, bottom);
    c.fillStyle = '#ffd84d';
    for (const k of r.keys) { const px = x(k); c.beginPath(); c.moveTo(px, 16); c.lineTo(px + 5, 22); c.lineTo(px, 28); c.lineTo(px - 5, 22); c.closePath(); c.fill(); }
    c.fillStyle = '#aab1bc'; c.fillText(`${r.keys.length} keys`, 2, 26);
  }
  // Playhead.
  c.strokeStyle = '#4da3ff'; c.lineWidth = 2;
  c.beginPath(); c.moveTo(x(S.frame), 0); c.lineTo(x(S.frame), h); c.stroke(); c.lineWidth = 1;
}
let scrubbing = false;
const scrub = (e) => {
  const st = panelState(); const n = Math.max(1, st.frames);
  const r = tl.getBoundingClientRect();
  seek((e.clientX - r.left - 40) / (r.width - 50) * (n - 1));
};
tl.addEventListener('pointerdown', (e) => { scrubbing = true; tl.setPointerCapture(e.pointerId); scrub(e); });
tl.addEventListener('pointermove', (e) => { if (scrubbing) scrub(e); });
tl.addEventListener('pointerup', () => { scrubbing = false; });

// ---------------------------------------------------------------- test hooks
function state() {
  const st = panelState();
  let camera = null;
  let objects = [], characters = [], keys = [];
  if (S.panel === 'script' && st.result) {
    objects = st.result.objects.map((o) => ({ label: o.label, category: o.category, position: o.position, size: o.size, yaw: o.yaw }));
    characters = st.result.characters.map((c) => ({ name: c.name, joints: c.joints, frames: c.frames }));
    const cam = st.result.camera[Math.min(S.frame, st.result.camera.length - 1)];
    if (cam) camera = { eye: cam.slice(0, 3), target: cam.slice(3, 6), fov: cam[6], shot: $('script-shotcam').checked };
  }
  if (S.panel === 'mocap' && st.take) {
    characters = [{ name: st.take.name, joints: st.take.joints, frames: st.take.frames }];
    if (st.keysResult) keys = [...st.keysResult.keys];
  }
  if (!camera) camera = { eye: orbitCam.position.toArray(), target: controls.target.toArray(), fov: orbitCam.fov, shot: false };
  return JSON.parse(JSON.stringify({ panel: S.panel, fps: st.fps, frames: st.frames, frame: S.frame, objects, characters, camera, keys, lastJob: S.lastJob }));
}

window.inbetweenStudio = {
  state,
  ready: () => pending.then(() => undefined),
  seek: (f) => { seek(f); renderNow(); },
  // How many jobs the page has started (lets a test wait for a job a file change starts).
  started: () => started,
  firstPaintMs: null,
  // The last story drawn: ms of its request (job included), to fetch its GLB, to parse it, to
  // build the view (for the bench).
  drawTimes: () => S.drawTimes || null,
};

// ---------------------------------------------------------------- start
showPanel('script');
requestAnimationFrame(loop);
pending = (async () => {
  try {
    await Promise.all([loadStories(), loadCorpus()]);
    maxUpload = (await (await fetch('/api/info')).json()).max_upload;
    setStatus('ready: run the story (Ctrl-Enter) or open a take');
  } catch (e) { showError(`could not reach the studio server: ${e.message}`); }
  renderNow();
  // Milliseconds from navigation start to the first frame drawn with the page's data loaded.
  window.inbetweenStudio.firstPaintMs = performance.now();
})();
