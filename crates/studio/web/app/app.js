// inbetween studio: the page. Plain ES modules, three.js through the import map (index.html).
// Test hooks (crates/studio/README.md): data-testid attributes and window.inbetweenStudio.
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import { TransformControls } from 'three/addons/controls/TransformControls.js';
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
const groups = { script: new THREE.Group(), mocap: new THREE.Group(), camera: new THREE.Group() };
scene.add(groups.script, groups.mocap, groups.camera);

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
  face: { take: null, orig: null, cur: null, keys: [], changed: [], lastEdit: null, fps: 60, frames: 0 },
  video: { clip: null, sprite: null, result: null, fps: 25, frames: 0 },
  camera: { scene: null, keys: [], selKey: 0, trajectories: [], selected: null, fps: 30, frames: 0 },
};
const panelState = () => S[S.panel];

function setStatus(text) { $('status').textContent = text; }
// Keeps a drag's pointer events on `el` (a pointer the browser does not know, as in a scripted
// test, just goes without capture).
function capture(el, e) { try { el.setPointerCapture(e.pointerId); } catch { /* no such pointer */ } }
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
  groups.camera.visible = name === 'camera';
  gizmo.getHelper().visible = name === 'camera';
  gizmo.enabled = name === 'camera';
  canvas.hidden = name === 'face' || name === 'video';
  $('face-view').hidden = name !== 'face';
  $('video-view').hidden = name !== 'video';
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
      for (const v of Object.values(m)) if (v && v.isTexture && !v.userData.shared) v.dispose();
      m.dispose();
    }
  });
}

// Embedded images already seen (by content and sampler), shared between loads: a story re-run
// sends the same character skins again, and sharing them skips their decode and GPU upload.
const sharedTextures = new Map();
const SHARED_TEXTURES_MAX = 64;
class SharedTextures {
  constructor(parser) { this.parser = parser; this.name = 'inbetween_shared_textures'; }
  loadTexture(index) {
    const p = this.parser, json = p.json, def = json.textures[index], src = json.images[def.source];
    if (src.bufferView === undefined || !crypto.subtle) return null; // the loader's own path
    return p.getDependency('bufferView', src.bufferView).then(async (buf) => {
      const digest = new Uint8Array(await crypto.subtle.digest('SHA-256', buf));
      const key = Array.from(digest, (b) => b.toString(16).padStart(2, '0')).join('')
        + JSON.stringify((json.samplers || [])[def.sampler] || {});
      if (!sharedTextures.has(key)) {
        if (sharedTextures.size >= SHARED_TEXTURES_MAX) {
          const [oldest, t] = sharedTextures.entries().next().value;
          sharedTextures.delete(oldest);
          t.then((tex) => tex && tex.dispose());
        }
        sharedTextures.set(key, p.loadTextureImage(index, def.source, p.textureLoader).then((tex) => {
          if (tex) tex.userData.shared = true;
          return tex;
        }));
      }
      return sharedTextures.get(key);
    });
  }
}

function parseGlb(buf) {
  return new Promise((resolve, reject) => new GLTFLoader().register((p) => new SharedTextures(p))
    .parse(buf, '', resolve, (e) => reject(new Error(`glTF: ${e.message || e}`))));
}

async function drawScript(r) {
  const t0 = performance.now();
  const buf = await (await fetch(r.files.glb)).arrayBuffer();
  const t1 = performance.now();
  const gltf = await parseGlb(buf);
  const t2 = performance.now();
  const g = groups.script;
  // The old tree is freed after the first frame with the new one: materials of the same kind then
  // find their shader programs still compiled (three.js frees a program with its last material).
  const old = [...g.children];
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
  for (const c of old) disposeTree(c);
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
  return { holder, helper, mixer, root, clip: result.clip, names: boneNames(result) };
}
const boneNames = (result) => result.skeleton.bones.map((b) => b.name).join('\n');

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
  let old = null;
  if (m.rec && m.rec.names === boneNames(parsed)) {
    // The same skeleton (a new K or method): the new clip drives the figure already drawn, so no
    // geometry is rebuilt and no shader compiled again.
    m.rec.mixer.stopAllAction();
    m.rec.mixer.uncacheClip(m.rec.clip);
    m.rec.clip = parsed.clip;
    m.rec.mixer.clipAction(parsed.clip).play();
  } else {
    old = m.rec;
    if (old) { groups.mocap.remove(old.holder, old.helper); old.mixer.stopAllAction(); }
    m.rec = bvhFigure(parsed, 0xff8c1a, 0.02);
    groups.mocap.add(m.rec.holder, m.rec.helper);
  }
  m.keysResult = r;
  if (r.method === 'bound') $('mocap-k').value = r.k;
  const ex = $('mocap-export');
  for (const a of ex.querySelectorAll('a.keys, span.muted')) a.remove();
  const a = document.createElement('a'); a.href = r.files.reconstructed + '&download=1'; a.textContent = 'reconstructed.bvh'; a.download = 'reconstructed.bvh'; a.className = 'keys';
  ex.prepend(a);
  seek(S.frame);
  drawTimeline();
  renderNow();
  // Freed after the first frame with the new figure: its materials find their programs compiled.
  if (old) { disposeTree(old.holder); disposeTree(old.helper); }
}

// ---------------------------------------------------------------- face panel
const faceCorpus = $('face-corpus');
async function loadFaceCorpus() {
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
const uploadCheck = (f) => { if (f.size > maxUpload) throw new Error(`${f.name}: ${(f.size / 1e6).toFixed(1)} MB is larger than this studio's upload cap of ${(maxUpload / 1e6).toFixed(0)} MB (start it with --max-upload SIZE)`); };
// Sends file `f` to `url` (its name in the query, `extra` appended) as a job.
function uploadJob(url, f, extra = '') {
  uploadCheck(f);
  return job(`${url}?name=${encodeURIComponent(f.name)}${extra}`, f, { 'content-type': 'application/octet-stream' });
}
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
function faceMask() {
  const a = parseFloat($('face-mask-start').value), b = parseFloat($('face-mask-end').value);
  return [Math.min(a, b), Math.max(a, b)];
}
for (const id of ['face-mask-start', 'face-mask-end', 'face-groups']) $(id).addEventListener('change', () => { drawTimeline(); drawFaceView(); });

function exportLink(url) {
  const ex = $('face-export');
  ex.innerHTML = '';
  const a = document.createElement('a'); const name = url.split('/').pop().split('?')[0];
  a.href = url + '&download=1'; a.textContent = `export ${name}`; a.download = name; ex.appendChild(a);
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
function drawFaceView() {
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
function updateKeysCount() { $('face-keys-count').textContent = `${S.face.keys.length} key${S.face.keys.length === 1 ? '' : 's'}`; }
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

// ---------------------------------------------------------------- video panel
const videoCorpus = $('video-corpus');
async function loadVideoCorpus() {
  const r = await (await fetch('/api/video/corpus')).json();
  videoCorpus.innerHTML = '<option value="">(choose a clip)</option>';
  for (const f of [...r.builtin, ...r.files]) {
    const o = document.createElement('option'); o.value = f; o.textContent = f; videoCorpus.appendChild(o);
  }
}
videoCorpus.addEventListener('change', () => {
  const path = videoCorpus.value;
  if (path) start('video-open', async () => { const r = await job('/api/video/open', { path }); await drawVideoClip(r); return r; });
});
$('video-file').addEventListener('change', (e) => {
  const f = e.target.files[0];
  if (f) start('video-open', async () => { const r = await uploadJob('/api/video/upload', f); await drawVideoClip(r); return r; });
});

function loadImage(url) {
  return new Promise((ok, fail) => { const i = new Image(); i.onload = () => ok(i); i.onerror = () => fail(new Error(`could not load ${url}`)); i.src = url; });
}

async function drawVideoClip(r) {
  const v = S.video;
  v.clip = r; v.sprite = await loadImage(r.sprite.url); v.result = null;
  v.fps = r.fps; v.frames = r.frames;
  $('video-take').textContent = `${r.name}: ${r.frames} frames ${r.width}×${r.height} at ${r.fps.toFixed(2)} fps, ${r.cuts.length + 1} shot(s)${r.cuts.length ? ` (cuts before frames ${r.cuts.join(', ')})` : ''}; M_D of the source ${r.source_md.toFixed(4)}.`;
  $('video-start').max = r.frames - 1;
  if (parseInt($('video-start').value, 10) >= r.frames) $('video-start').value = 0;
  $('video-order').textContent = ''; $('video-stats').textContent = '';
  $('video-export').innerHTML = '<span class="muted">Export appears after Generate.</span>';
  S.frame = 0; seek(0); drawVideoStrip(); drawTimeline();
}

function videoRequest() {
  const len = parseInt($('video-length').value, 10);
  return { start: parseInt($('video-start').value, 10) || 0, length: Number.isFinite(len) && len > 0 ? len : null, loop: $('video-loop').checked, seed: parseInt($('video-seed').value, 10) || 0 };
}
function runVideo() {
  return start('video-generate', async () => {
    if (!S.video.clip) throw new Error('open a clip first');
    const r = await job('/api/video/generate', videoRequest());
    const v = S.video;
    v.result = r; v.frames = r.order.length;
    $('video-order').textContent = r.order.join(' ');
    $('video-stats').textContent = `${r.order.length} frames, ${r.jumps.length} jumps; M_D ${r.md.toFixed(4)} (source ${r.source_md.toFixed(4)}; lower is steadier)${r.closes_loop ? '; the loop closes' : ''}.`;
    const ex = $('video-export'); ex.innerHTML = '';
    for (const url of [r.files.mp4, r.files.gif]) {
      const a = document.createElement('a'); const name = url.split('/').pop().split('?')[0];
      a.href = url + '&download=1'; a.textContent = name; a.download = name; ex.appendChild(a);
    }
    S.frame = 0; seek(0); drawVideoStrip(); drawTimeline();
    return r;
  });
}
$('video-generate').addEventListener('click', runVideo);
$('video-start').addEventListener('change', () => drawVideoStrip());

// Draws source frame `i` of the sprite into `cv`, letterboxed.
function drawSpriteFrame(cv, i) {
  const v = S.video, c = cv.getContext('2d');
  const w = cv.clientWidth, h = cv.clientHeight;
  if (cv.width !== w) cv.width = w;
  if (cv.height !== h) cv.height = h;
  c.fillStyle = '#111'; c.fillRect(0, 0, w, h);
  if (!v.sprite || i == null) return;
  const sp = v.clip.sprite, sx = (i % sp.columns) * sp.width, sy = Math.floor(i / sp.columns) * sp.height;
  const k = Math.min(w / sp.width, h / sp.height), dw = sp.width * k, dh = sp.height * k;
  c.drawImage(v.sprite, sx, sy, sp.width, sp.height, (w - dw) / 2, (h - dh) / 2, dw, dh);
}
function drawVideoView() {
  if (S.panel !== 'video') return;
  const v = S.video;
  if (!v.clip) { drawSpriteFrame($('video-source'), null); drawSpriteFrame($('video-new'), null); return; }
  const n = v.clip.frames, t = S.frame;
  const src = Math.min(t, n - 1);
  drawSpriteFrame($('video-source'), src);
  $('video-source-cap').textContent = `source: frame ${src}`;
  if (v.result) {
    const f = v.result.order[Math.min(t, v.result.order.length - 1)];
    drawSpriteFrame($('video-new'), f);
    $('video-new-cap').textContent = `new order: position ${t} = source frame ${f}`;
  } else {
    drawSpriteFrame($('video-new'), null);
    $('video-new-cap').textContent = 'new order (Generate)';
  }
}

// The strip: every source frame, shot boundaries in red, the start frame outlined; a click picks the start.
function drawVideoStrip() {
  const cv = $('video-strip'), v = S.video;
  const w = cv.clientWidth, h = cv.clientHeight;
  if (cv.width !== w) cv.width = w;
  if (cv.height !== h) cv.height = h;
  const c = cv.getContext('2d');
  c.fillStyle = '#15171c'; c.fillRect(0, 0, w, h);
  if (!v.clip || !v.sprite) return;
  const n = v.clip.frames, sp = v.clip.sprite, cw = w / n;
  const th = h - 14, tw = th * sp.width / sp.height;
  const every = Math.max(1, Math.ceil(tw / cw));
  for (let i = 0; i < n; i += every) {
    c.drawImage(v.sprite, (i % sp.columns) * sp.width, Math.floor(i / sp.columns) * sp.height, sp.width, sp.height, i * cw, 0, tw, th);
  }
  c.fillStyle = '#ff5a5a';
  for (const cut of v.clip.cuts) c.fillRect(cut * cw - 1, 0, 3, h);
  const s = parseInt($('video-start').value, 10) || 0;
  c.strokeStyle = '#ffd84d'; c.lineWidth = 2; c.strokeRect(s * cw, 1, Math.max(3, cw), h - 2); c.lineWidth = 1;
  if (v.result) {
    c.fillStyle = '#4da3ff';
    const used = new Set(v.result.order);
    for (let i = 0; i < n; i++) if (used.has(i)) c.fillRect(i * cw, h - 5, Math.max(1, cw), 4);
  }
  c.fillStyle = '#aab1bc'; c.font = '10px system-ui, sans-serif';
  c.fillText(`start ${s} · red: shot boundary · blue: frames the new order uses`, 4, h - 7);
}
$('video-strip').addEventListener('click', (e) => {
  const v = S.video; if (!v.clip) return;
  const r = $('video-strip').getBoundingClientRect();
  $('video-start').value = Math.max(0, Math.min(v.clip.frames - 1, Math.floor((e.clientX - r.left) / r.width * v.clip.frames)));
  drawVideoStrip();
});

// Hovering a jump mark on the timeline shows that step's explanation.
const JUMP_COLORS = { jump: '#ffd84d', back: '#ff5a5a', cut: '#4da3ff', loop: '#c77dff', repeat: '#7d6a99' };
function jumpAt(e) {
  const v = S.video; if (S.panel !== 'video' || !v.result) return null;
  const r = $('timeline').getBoundingClientRect(), n = Math.max(1, v.frames);
  const x = (f) => 40 + (r.width - 50) * (n > 1 ? f / (n - 1) : 0);
  let best = null, bd = 6;
  for (const j of v.result.jumps) { const d = Math.abs(x(Math.min(j.position, n - 1)) - (e.clientX - r.left)); if (d < bd) { bd = d; best = j; } }
  return best;
}
$('timeline').addEventListener('mousemove', (e) => {
  const j = jumpAt(e), tip = $('video-tip');
  if (!j) { tip.hidden = true; return; }
  tip.textContent = `position ${j.position}: ${j.kind}\n${j.text}`;
  tip.hidden = false;
  tip.style.left = `${Math.min(e.clientX + 12, window.innerWidth - 580)}px`;
  tip.style.top = `${Math.max(8, e.clientY - 20 - tip.offsetHeight)}px`;
});
$('timeline').addEventListener('mouseleave', () => { $('video-tip').hidden = true; });

// ---------------------------------------------------------------- camera panel
const STYLE_COLORS = { direct: 0xff8c1a, relative: 0x4da3ff, side: 0x2ca02c, orbit: 0xc77dff };
const styleColor = (name) => STYLE_COLORS[name] ?? 0xffd84d;
const hex = (c) => `#${c.toString(16).padStart(6, '0')}`;

$('camera-scene').addEventListener('change', () => {
  const path = $('camera-scene').value;
  if (path) start('camera-scene', async () => { const r = await job('/api/camera/open', { path }); drawCameraScene(r); return r; });
});
$('camera-characters').addEventListener('change', (e) => {
  const files = [...e.target.files];
  start('camera-scene', async () => {
    if (files.length !== 2) throw new Error(`pick two BVH takes together (got ${files.length})`);
    let r;
    for (const [slot, f] of files.entries()) r = await uploadJob('/api/camera/upload', f, `&slot=${slot}`);
    drawCameraScene(r);
    return r;
  });
});
$('camera-reference').addEventListener('change', (e) => {
  const f = e.target.files[0];
  if (f) start('camera-reference', async () => {
    const r = await uploadJob('/api/camera/reference', f);
    $('camera-style').value = 'reference';
    return r;
  });
});

function cameraFigure(color) {
  const g = new THREE.Group();
  const mat = new THREE.MeshStandardMaterial({ color, roughness: 0.7 });
  const body = new THREE.Mesh(new THREE.CylinderGeometry(0.16, 0.12, 1, 12), mat);
  const head = new THREE.Mesh(new THREE.SphereGeometry(0.12, 14, 10), mat);
  const bar = new THREE.Mesh(new THREE.BoxGeometry(1, 0.07, 0.07), mat);
  const legs = new THREE.Mesh(new THREE.CylinderGeometry(0.1, 0.06, 1, 10), mat);
  g.add(body, head, bar, legs);
  return { g, body, head, bar, legs };
}
const v3 = (a) => new THREE.Vector3(a[0], a[1], a[2]);
function poseFigure(fig, ch, f) {
  const root = v3(ch.root[f]), l = v3(ch.shoulder_l[f]), r = v3(ch.shoulder_r[f]);
  const mid = l.clone().add(r).multiplyScalar(0.5);
  const place = (mesh, a, b) => {
    const d = b.clone().sub(a), len = Math.max(1e-3, d.length());
    mesh.position.copy(a).addScaledVector(d, 0.5);
    mesh.scale.set(1, len, 1);
    mesh.quaternion.setFromUnitVectors(new THREE.Vector3(0, 1, 0), d.normalize());
  };
  place(fig.body, root, mid);
  place(fig.legs, new THREE.Vector3(root.x, 0, root.z), root);
  fig.head.position.copy(mid).add(new THREE.Vector3(0, 0.22, 0));
  const across = r.clone().sub(l);
  fig.bar.position.copy(mid); fig.bar.scale.set(Math.max(0.05, across.length()), 1, 1);
  fig.bar.quaternion.setFromUnitVectors(new THREE.Vector3(1, 0, 0), across.normalize());
}

function drawCameraScene(r) {
  const c = S.camera;
  c.scene = r; c.fps = r.fps; c.frames = r.frames; c.trajectories = []; c.selected = null; c.framed = false;
  c.keys = r.keys.keys.map((k) => ({ ...k }));
  c.selKey = 0;
  const g = groups.camera;
  for (const ch of [...g.children]) disposeTree(ch);
  g.clear();
  c.figures = r.characters.map((ch, i) => { const f = cameraFigure([0xe8e8e8, 0xf2c14e, 0x8fd18f][i % 3]); g.add(f.g); return f; });
  c.paths = new THREE.Group(); g.add(c.paths);
  c.cam = new THREE.PerspectiveCamera(r.lens.fovy * 180 / Math.PI, r.lens.aspect, 0.1, 200);
  c.helper = new THREE.CameraHelper(c.cam); c.helper.visible = false;
  g.add(c.cam, c.helper);
  $('camera-take').textContent = `${r.name}: ${r.characters.map((x) => x.name).join(' and ')}, ${r.frames} frames at ${r.fps.toFixed(1)} fps.${r.notes.length ? ' ' + r.notes.join(' ') : ''}`;
  $('camera-trajectories').innerHTML = '';
  $('camera-export').innerHTML = '<span class="muted">Export appears after Generate.</span>';
  // Frame the pair from above and behind.
  const box = new THREE.Box3();
  for (const ch of r.characters) for (let f = 0; f < r.frames; f += 10) box.expandByPoint(v3(ch.root[f]));
  const ctr = box.getCenter(new THREE.Vector3()), size = box.getSize(new THREE.Vector3());
  controls.target.copy(ctr); const d = Math.max(size.x, size.z, 3) * 1.1 + 3;
  orbitCam.position.set(ctr.x + d * 0.6, ctr.y + d * 0.7, ctr.z + d); controls.update();
  renderCameraKeys();
  S.frame = 0; seek(0); drawTimeline();
}

function renderCameraKeys(moveGizmo = true) {
  const c = S.camera, ul = $('camera-keys');
  c.keys.sort((a, b) => a.frame - b.frame);
  ul.innerHTML = '';
  c.keys.forEach((k, i) => {
    const li = document.createElement('li');
    li.textContent = `key ${i}: frame ${k.frame} · A (${k.camera.pa.map((v) => v.toFixed(2)).join(', ')}) B (${k.camera.pb.map((v) => v.toFixed(2)).join(', ')}) θ ${k.camera.theta.toFixed(2)} φ ${k.camera.phi.toFixed(2)}${k.velocity ? ' · velocity' : ''}`;
    li.className = i === c.selKey ? 'sel' : '';
    li.addEventListener('click', () => { c.selKey = i; renderCameraKeys(); seek(k.frame); });
    ul.appendChild(li);
  });
  const k = c.keys[c.selKey];
  $('camera-editor').hidden = !k;
  if (k) {
    $('ck-frame').value = k.frame; $('ck-theta').value = k.camera.theta.toFixed(3); $('ck-phi').value = k.camera.phi.toFixed(3);
    $('ck-pax').value = k.camera.pa[0].toFixed(3); $('ck-pay').value = k.camera.pa[1].toFixed(3);
    $('ck-pbx').value = k.camera.pb[0].toFixed(3); $('ck-pby').value = k.camera.pb[1].toFixed(3);
    $('ck-vel').checked = !!k.velocity; if (k.velocity) $('ck-velocity').value = k.velocity.join(',');
    $('ck-swap').checked = !!k.targets;
  }
  drawTimeline();
  if (moveGizmo && S.panel === 'camera') placeGizmo().catch((e) => showError(e.message));
}
for (const id of ['ck-frame', 'ck-theta', 'ck-phi', 'ck-pax', 'ck-pay', 'ck-pbx', 'ck-pby', 'ck-vel', 'ck-velocity', 'ck-swap']) {
  $(id).addEventListener('change', () => {
    const c = S.camera, k = c.keys[c.selKey]; if (!k) return;
    const num = (x) => parseFloat($(x).value);
    k.frame = Math.max(0, Math.min(c.frames - 1, parseInt($('ck-frame').value, 10) || 0));
    k.camera = { pa: [num('ck-pax'), num('ck-pay')], pb: [num('ck-pbx'), num('ck-pby')], theta: num('ck-theta'), phi: num('ck-phi') };
    const vel = $('ck-velocity').value.split(',').map(Number);
    k.velocity = $('ck-vel').checked && vel.length === 6 && vel.every(Number.isFinite) ? vel : null;
    const names = c.scene.characters.map((x) => x.name);
    k.targets = $('ck-swap').checked ? [names[1], names[0]] : null;
    const keep = k; renderCameraKeys(); S.camera.selKey = S.camera.keys.indexOf(keep); renderCameraKeys();
  });
}
async function addCameraKey() {
  const c = S.camera;
  if (!c.scene) throw new Error('open a scene first');
  if (c.keys.some((k) => k.frame === S.frame)) throw new Error(`frame ${S.frame} already has a key`);
  const r = await post('/api/camera/key_at', { frame: S.frame });
  c.keys.push(r.key); c.selKey = c.keys.indexOf(r.key);
  renderCameraKeys();
  const i = c.keys.indexOf(r.key); c.selKey = i; renderCameraKeys();
  return { ok: true, kind: 'camera-add-key', message: `key added at frame ${S.frame} (${c.keys.length} keys)` };
}
$('camera-add-key').addEventListener('click', () => start('camera-add-key', addCameraKey));
$('camera-delete-key').addEventListener('click', () => {
  const c = S.camera; if (c.keys[c.selKey]) { c.keys.splice(c.selKey, 1); c.selKey = Math.min(c.selKey, c.keys.length - 1); renderCameraKeys(); }
});
// The selected key takes the Toric pose of the 3D view's camera (place it with the mouse, then click).
$('camera-key-from-view').addEventListener('click', () => start('camera-key-from-view', async () => {
  const c = S.camera, k = c.keys[c.selKey];
  if (!k) throw new Error('select a key first');
  const q = orbitCam.quaternion;
  const r = await post('/api/camera/toric', { frame: k.frame, position: orbitCam.position.toArray(), rotation: [q.x, q.y, q.z, q.w] });
  k.camera = r.camera; renderCameraKeys();
  return { ok: true, kind: 'camera-key-from-view', message: `key at frame ${k.frame} set from the view: θ ${r.camera.theta.toFixed(2)}, φ ${r.camera.phi.toFixed(2)}` };
}));

function runCamera() {
  return start('camera-generate', async () => {
    const c = S.camera;
    if (!c.scene) throw new Error('open a scene first');
    const style = $('camera-style').value;
    const keys = { main: c.scene.keys.main, keys: c.keys.map((k) => ({ frame: k.frame, camera: k.camera, ...(k.velocity ? { velocity: k.velocity } : {}), ...(k.targets ? { targets: k.targets } : {}) })) };
    const r = await job('/api/camera/generate', { keys, styles: style ? [style] : [] });
    c.trajectories = r.trajectories;
    for (const ch of [...c.paths.children]) disposeTree(ch);
    c.paths.clear();
    for (const t of r.trajectories) {
      const geo = new THREE.BufferGeometry().setFromPoints(t.position.map(v3));
      t.line = new THREE.Line(geo, new THREE.LineBasicMaterial({ color: styleColor(t.style) }));
      c.paths.add(t.line);
    }
    const list = $('camera-trajectories'); list.innerHTML = '';
    for (const t of r.trajectories) {
      const div = document.createElement('div');
      div.dataset.style = t.style;
      const cv = document.createElement('canvas'); cv.width = 170; cv.height = 70;
      const cap = document.createElement('span');
      cap.textContent = `${t.style} · ${t.ms.toFixed(0)} ms · key error ${t.key_hit_error.toExponential(1)}`;
      div.append(cv, cap);
      div.addEventListener('click', () => selectTrajectory(t.style));
      list.appendChild(div);
      drawTrajectoryPreview(cv, t);
    }
    selectTrajectory(r.trajectories.some((t) => t.style === c.selected) ? c.selected : r.trajectories[0].style);
    if (!c.framed) { frameCameraView(); c.framed = true; }
    return r;
  });
}
$('camera-generate').addEventListener('click', runCamera);
$('camera-style').addEventListener('change', () => { if (S.camera.trajectories.length) runCamera(); });
$('camera-shot').addEventListener('change', () => { seek(S.frame); renderNow(); });

// Top-down preview: the characters' paths (grey) and the camera's (its style's colour).
function drawTrajectoryPreview(cv, t) {
  const c = cv.getContext('2d'), sc = S.camera.scene;
  const pts = [...t.position.map((p) => [p[0], p[2]]), ...sc.characters.flatMap((ch) => ch.root.filter((_, i) => i % 5 === 0).map((p) => [p[0], p[2]]))];
  const xs = pts.map((p) => p[0]), zs = pts.map((p) => p[1]);
  const [x0, x1, z0, z1] = [Math.min(...xs), Math.max(...xs), Math.min(...zs), Math.max(...zs)];
  const k = Math.min((cv.width - 8) / Math.max(1e-3, x1 - x0), (cv.height - 8) / Math.max(1e-3, z1 - z0));
  const X = (p) => 4 + (p[0] - x0) * k, Y = (p) => 4 + (p[1] - z0) * k;
  c.fillStyle = '#15171c'; c.fillRect(0, 0, cv.width, cv.height);
  const line = (ps, col) => { c.strokeStyle = col; c.beginPath(); ps.forEach((p, i) => (i ? c.lineTo(X(p), Y(p)) : c.moveTo(X(p), Y(p)))); c.stroke(); };
  for (const ch of sc.characters) line(ch.root.map((p) => [p[0], p[2]]), '#6d7480');
  line(t.position.map((p) => [p[0], p[2]]), hex(styleColor(t.style)));
}

// Fits the 3D view to the characters and the trajectories (once per scene: later generations keep
// the view the user chose).
function frameCameraView() {
  const c = S.camera, box = new THREE.Box3();
  for (const ch of c.scene.characters) for (let f = 0; f < c.frames; f += 10) box.expandByPoint(v3(ch.root[f]));
  for (const t of c.trajectories) for (let i = 0; i < t.position.length; i += 5) box.expandByPoint(v3(t.position[i]));
  // Look at the characters; stand back far enough to see the trajectories around them.
  const chars = new THREE.Box3();
  for (const ch of c.scene.characters) for (let f = 0; f < c.frames; f += 10) chars.expandByPoint(v3(ch.root[f]));
  const ctr = chars.getCenter(new THREE.Vector3()), size = box.getSize(new THREE.Vector3());
  const d = Math.max(size.x, size.y, size.z, 3) * 0.75 + 2;
  controls.target.copy(ctr); orbitCam.position.set(ctr.x + d * 0.5, ctr.y + d * 0.55, ctr.z + d); controls.update();
}

function selectTrajectory(style) {
  const c = S.camera;
  c.selected = style;
  for (const d of $('camera-trajectories').children) d.classList.toggle('sel', d.dataset.style === style);
  for (const t of c.trajectories) t.line.material.opacity = t.style === style ? 1 : 0.35, t.line.material.transparent = t.style !== style;
  const t = c.trajectories.find((x) => x.style === style);
  const ex = $('camera-export'); ex.innerHTML = '';
  if (t) for (const [url, label] of [[t.files.json, `camera-${style}.json`], [t.files.gltf, `camera-${style}.gltf`]]) {
    const a = document.createElement('a'); a.href = url + '&download=1'; a.textContent = label; a.download = label; ex.appendChild(a);
  }
  seek(S.frame);
}

// Per frame: the characters, and the chosen trajectory's camera (its frustum, or the view itself).
function seekCamera(f) {
  const c = S.camera; if (!c.scene) return;
  c.scene.characters.forEach((ch, i) => poseFigure(c.figures[i], ch, f));
  const t = c.trajectories.find((x) => x.style === c.selected);
  if (t) {
    const i = Math.max(0, Math.min(t.position.length - 1, f - t.first_frame));
    c.cam.position.fromArray(t.position[i]);
    c.cam.quaternion.set(...t.rotation[i]);
    // A short frustum for the drawn helper; the full depth when the view looks through it.
    c.cam.far = $('camera-shot').checked ? 200 : 1.5;
    c.cam.fov = t.fovy_deg; c.cam.aspect = t.aspect; c.cam.updateProjectionMatrix(); c.cam.updateMatrixWorld(true);
    c.helper.update();
    c.helper.visible = !$('camera-shot').checked;
  } else c.helper.visible = false;
}

// Timeline keys: press near a key's triangle to select and drag it in time; right-click deletes.
function cameraKeyNear(e) {
  const c = S.camera; if (S.panel !== 'camera' || !c.scene) return -1;
  const r = $('timeline').getBoundingClientRect(), n = Math.max(1, c.frames);
  const x = (f) => 40 + (r.width - 50) * (n > 1 ? f / (n - 1) : 0);
  let best = -1, bd = 7;
  c.keys.forEach((k, i) => { const d = Math.abs(x(k.frame) - (e.clientX - r.left)); if (d < bd && e.clientY - r.top < 60) { bd = d; best = i; } });
  return best;
}
let draggingKey = -1;
$('timeline').addEventListener('pointerdown', (e) => {
  const i = cameraKeyNear(e);
  if (i < 0) return;
  e.stopImmediatePropagation();
  if (e.button === 2) return;
  S.camera.selKey = i; draggingKey = i; renderCameraKeys();
  capture($('timeline'), e);
}, true);
$('timeline').addEventListener('pointermove', (e) => {
  if (draggingKey < 0) return;
  e.stopImmediatePropagation();
  const c = S.camera, k = c.keys[draggingKey], r = $('timeline').getBoundingClientRect();
  const f = Math.round(Math.max(0, Math.min(c.frames - 1, (e.clientX - r.left - 40) / (r.width - 50) * (c.frames - 1))));
  if (!c.keys.some((o) => o !== k && o.frame === f)) { k.frame = f; $('ck-frame').value = f; drawTimeline(); }
}, true);
$('timeline').addEventListener('pointerup', () => { if (draggingKey >= 0) { const k = S.camera.keys[draggingKey]; draggingKey = -1; renderCameraKeys(); S.camera.selKey = S.camera.keys.indexOf(k); renderCameraKeys(); } }, true);
$('timeline').addEventListener('contextmenu', (e) => {
  const i = cameraKeyNear(e); if (i < 0) return;
  e.preventDefault(); S.camera.keys.splice(i, 1); S.camera.selKey = Math.min(S.camera.selKey, S.camera.keys.length - 1); renderCameraKeys();
});


// The gizmo: the selected key's camera as a small body the user drags in the viewport
// (three.js TransformControls); on release the camera looks at the pair and the server turns that
// pose into the key's Toric coordinates.
const gizmo = new TransformControls(orbitCam, canvas);
gizmo.setMode('translate');
gizmo.setSize(0.8);
scene.add(gizmo.getHelper());
gizmo.addEventListener('dragging-changed', (e) => { controls.enabled = !e.value; });
gizmo.addEventListener('change', () => requestRender());
gizmo.addEventListener('mouseUp', () => { if (S.camera.proxy) start('camera-gizmo', gizmoMoved); });
function cameraProxy() {
  const g = new THREE.Group();
  const mat = new THREE.MeshStandardMaterial({ color: 0xffd84d, roughness: 0.5 });
  const body = new THREE.Mesh(new THREE.BoxGeometry(0.22, 0.16, 0.3), mat);
  const lens = new THREE.Mesh(new THREE.ConeGeometry(0.09, 0.16, 12), mat);
  lens.rotation.x = Math.PI / 2; lens.position.z = -0.22;
  g.add(body, lens);
  return g;
}
// Places the gizmo on the selected key's camera (the server poses its Toric coordinates).
async function placeGizmo() {
  const c = S.camera, k = c.keys[c.selKey];
  if (!c.scene || !k) { gizmo.detach(); if (c.proxy) c.proxy.visible = false; return; }
  const targets = k.targets ? [1, 0] : null;
  const r = await post('/api/camera/pose', { frame: k.frame, camera: k.camera, targets });
  if (!c.proxy) { c.proxy = cameraProxy(); groups.camera.add(c.proxy); }
  // The velocity at the key (Fig. 6): where the camera would be a quarter second later at that
  // Toric velocity, drawn as an arrow from the key's camera.
  if (c.arrow) { groups.camera.remove(c.arrow); c.arrow.dispose(); c.arrow = null; }
  if (k.velocity) {
    const dt = 0.25, v = k.velocity;
    const later = { pa: [k.camera.pa[0] + v[0] * dt, k.camera.pa[1] + v[1] * dt], pb: [k.camera.pb[0] + v[2] * dt, k.camera.pb[1] + v[3] * dt], theta: k.camera.theta + v[4] * dt, phi: k.camera.phi + v[5] * dt };
    const r2 = await post('/api/camera/pose', { frame: k.frame, camera: later, targets }).catch(() => null);
    if (r2) {
      const from = v3(r.position), d = v3(r2.position).sub(from), len = d.length();
      if (len > 1e-4) { c.arrow = new THREE.ArrowHelper(d.normalize(), from, Math.max(0.3, len * 4), 0xff5a5a, 0.15, 0.1); groups.camera.add(c.arrow); }
    }
  }
  c.proxy.visible = true;
  c.proxy.position.fromArray(r.position);
  c.proxy.quaternion.set(...r.rotation);
  c.lookAt = r.look_at;
  gizmo.attach(c.proxy);
  requestRender();
}
async function gizmoMoved() {
  const c = S.camera, k = c.keys[c.selKey];
  if (!k || !c.proxy) throw new Error('select a key first');
  const look = new THREE.PerspectiveCamera();
  look.position.copy(c.proxy.position);
  look.lookAt(v3(c.lookAt));
  c.proxy.quaternion.copy(look.quaternion);
  const q = look.quaternion;
  const r = await post('/api/camera/toric', { frame: k.frame, position: c.proxy.position.toArray(), rotation: [q.x, q.y, q.z, q.w], targets: k.targets ? [1, 0] : null });
  k.camera = r.camera; renderCameraKeys(false);
  return { ok: true, kind: 'camera-gizmo', message: `key at frame ${k.frame} placed in the viewport: θ ${r.camera.theta.toFixed(2)}, φ ${r.camera.phi.toFixed(2)}` };
}

// ---------------------------------------------------------------- playback
function seek(frame) {
  const st = panelState();
  const n = Math.max(1, st.frames);
  S.frame = Math.max(0, Math.min(n - 1, Math.round(frame)));
  const t = S.panel === 'face' && st.take ? st.take.times[S.frame] : S.frame / (st.fps || 30);
  if (S.panel === 'script' && st.mixer) {
    st.mixer.setTime(t);
    if (st.camHelper) { st.gltf.scene.updateMatrixWorld(true); st.camHelper.update(); }
  }
  if (S.panel === 'mocap') {
    if (st.orig) st.orig.mixer.setTime(t);
    if (st.rec) st.rec.mixer.setTime(t);
  }
  if (S.panel === 'face') drawFaceView();
  if (S.panel === 'video') drawVideoView();
  if (S.panel === 'camera') seekCamera(S.frame);
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
  if (S.panel === 'face') { const cv = $('face-curves'); if (cv.width !== cv.clientWidth || cv.height !== cv.clientHeight) { drawFaceView(); drawTimeline(); } }
  if (S.panel === 'video') { const cv = $('video-source'); if (cv.width !== cv.clientWidth || cv.height !== cv.clientHeight || $('video-strip').width !== $('video-strip').clientWidth) { drawVideoView(); drawVideoStrip(); drawTimeline(); } }
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
  const cam = S.camera;
  const camShot = S.panel === 'camera' && $('camera-shot').checked && cam.selected && cam.cam;
  if (camShot) { cam.cam.aspect = orbitCam.aspect; cam.cam.updateProjectionMatrix(); }
  renderer.render(scene, useShot ? st.shotCam : camShot ? cam.cam : orbitCam);
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
  if (S.panel === 'camera' && st.scene) {
    c.fillStyle = '#aab1bc';
    const t = st.trajectories.find((x) => x.style === st.selected);
    c.fillText(`${st.keys.length} keys (drag a triangle in time; right-click deletes)${t ? ` · ${t.style}: key hit error ${t.key_hit_error.toExponential(1)}, ${t.ms.toFixed(0)} ms` : ''}`, 44, 26);
    st.keys.forEach((k, i) => {
      const px = x(k.frame);
      c.fillStyle = i === st.selKey ? '#ffffff' : '#ffd84d';
      c.beginPath(); c.moveTo(px - 7, 32); c.lineTo(px + 7, 32); c.lineTo(px, 46); c.closePath(); c.fill();
      if (k.velocity) { c.strokeStyle = '#ffd84d'; c.beginPath(); c.moveTo(px, 50); c.lineTo(px + 14, 50); c.stroke(); }
    });
    for (const tr of st.trajectories) {
      c.fillStyle = hex(styleColor(tr.style)); c.fillRect(x(tr.first_frame), h - 10 - 5 * st.trajectories.indexOf(tr), Math.max(1, x(tr.first_frame + tr.position.length - 1) - x(tr.first_frame)), 3);
    }
  }
  if (S.panel === 'video' && st.result) {
    c.fillStyle = '#aab1bc'; c.fillText(`new order: ${st.result.order.length} frames, ${st.result.jumps.length} jumps (rest the pointer on a mark)`, 44, 26);
    for (const j of st.result.jumps) {
      const px = x(Math.min(j.position, n - 1));
      c.fillStyle = JUMP_COLORS[j.kind] || '#ffd84d';
      c.fillRect(px - 1.5, 32, 3, h - 40);
      c.beginPath(); c.moveTo(px, 32); c.lineTo(px + 5, 38); c.lineTo(px, 44); c.lineTo(px - 5, 38); c.closePath(); c.fill();
    }
  }
  if (S.panel === 'face' && st.take) {
    const [a, b] = faceMask();
    const fa = a * st.fps, fb = b * st.fps;
    c.fillStyle = 'rgba(255, 196, 0, 0.25)'; c.fillRect(x(fa), 14, Math.max(2, x(fb) - x(fa)), h - 14);
    c.fillStyle = '#ffc400'; c.fillText(`span ${a.toFixed(2)}–${b.toFixed(2)} s (drag on the timeline to set it)`, 44, 26);
    // Blink and jaw curves of the current version, for orientation.
    for (const [name, col] of [['EyeBlinkLeft', '#9fe0a8'], ['JawOpen', '#ff8c1a']]) {
      const v = st.cur[name]; if (!v) continue;
      c.strokeStyle = col; c.beginPath();
      const step = Math.max(1, Math.floor(v.length / w));
      for (let f = 0; f < v.length; f += step) { const px = x(f), py = h - 6 - (h - 40) * v[f]; f ? c.lineTo(px, py) : c.moveTo(px, py); }
      c.stroke();
    }
    c.fillStyle = '#9fe0a8'; c.fillText('EyeBlinkLeft', 2, h - 20); c.fillStyle = '#ff8c1a'; c.fillText('JawOpen', 2, h - 8);
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
// On the face panel a drag sets the span (seconds of the file's own time); a click seeks.
let dragFrom = null;
const tlFrame = (e) => { const st = panelState(); const n = Math.max(1, st.frames); const r = tl.getBoundingClientRect(); return Math.max(0, Math.min(n - 1, (e.clientX - r.left - 40) / (r.width - 50) * (n - 1))); };
tl.addEventListener('pointerdown', (e) => { scrubbing = true; capture(tl, e); dragFrom = { x: e.clientX, f: tlFrame(e) }; scrub(e); });
tl.addEventListener('pointermove', (e) => {
  if (!scrubbing) return;
  if (S.panel === 'face' && S.face.take && dragFrom && Math.abs(e.clientX - dragFrom.x) > 4) {
    const t = S.face.take.times, f = tlFrame(e);
    const a = t[Math.round(Math.min(dragFrom.f, f))], b = t[Math.round(Math.max(dragFrom.f, f))];
    $('face-mask-start').value = a.toFixed(2); $('face-mask-end').value = b.toFixed(2);
    drawTimeline(); drawFaceView();
  } else scrub(e);
});
tl.addEventListener('pointerup', () => { scrubbing = false; dragFrom = null; });

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
  if (S.panel === 'camera' && S.camera.scene) {
    const cs = S.camera;
    characters = cs.scene.characters.map((c) => ({ name: c.name, joints: 3, frames: cs.frames }));
    camera = {
      ...camera, shot: $('camera-shot').checked,
      keys: cs.keys.map((k) => ({ frame: k.frame, camera: k.camera, velocity: k.velocity ?? null, targets: k.targets ?? null })),
      arrow: !!cs.arrow,
      trajectories: cs.trajectories.map((t) => ({ style: t.style, first_frame: t.first_frame, frames: t.position.length, key_hit_error: t.key_hit_error, network_key_miss: t.network_key_miss, ms: t.ms })),
      selected: cs.selected,
    };
  }
  let video = null;
  if (S.video.clip) video = { order: S.video.result ? S.video.result.order : null, md: S.video.result ? S.video.result.md : null, source_md: S.video.clip.source_md, cuts: S.video.clip.cuts, jumps: S.video.result ? S.video.result.jumps.map((j) => ({ position: j.position, from: j.from, to: j.to, kind: j.kind })) : [] };
  let face = null;
  if (S.face.take) face = { mask: faceMask(), edited: S.face.cur, keys: S.face.keys, version: S.face.version ?? 0, versions: S.face.versions ?? 1, lastEdit: S.face.lastEdit, variants: S.face.variants ? S.face.variants.length : 0, picked: S.face.picked ?? null };
  return JSON.parse(JSON.stringify({ panel: S.panel, fps: st.fps, frames: st.frames, frame: S.frame, objects, characters, camera, keys, face, video, lastJob: S.lastJob }));
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
  // Drags on the timeline from frame `a` to frame `b` with pointer events, as a mouse would.
  dragTimeline: (a, b) => {
    const r = tl.getBoundingClientRect(), n = Math.max(1, panelState().frames);
    const x = (f) => r.left + 40 + (r.width - 50) * f / Math.max(1, n - 1);
    const ev = (type, f) => tl.dispatchEvent(new PointerEvent(type, { clientX: x(f), clientY: r.top + 39, bubbles: true, pointerId: 1, button: 0 }));
    ev('pointerdown', a); for (let k = 1; k <= 4; k++) ev('pointermove', a + (b - a) * k / 4); ev('pointerup', b);
    return true;
  },
  // Moves the camera gizmo by (dx, dy, dz) metres and releases it, as a drag in the viewport does.
  cameraGizmoMove: (dx, dy, dz) => { const p = S.camera.proxy; if (!p) return Promise.reject(new Error('no gizmo')); p.position.add(new THREE.Vector3(dx, dy, dz)); return start('camera-gizmo', gizmoMoved); },
  // The face take's row times, seconds from its first row.
  faceTimes: () => (S.face.take ? S.face.take.times : []),
  // Adds a face key as a click on a curve would (keyframes constraint).
  faceKey: (time_s, shape, value) => { S.face.keys.push({ time_s, shape, value }); updateKeysCount(); drawFaceView(); },
};

// ---------------------------------------------------------------- start
showPanel('script');
requestAnimationFrame(loop);
pending = (async () => {
  try {
    await Promise.all([loadStories(), loadCorpus(), loadFaceCorpus(), loadVideoCorpus()]);
    maxUpload = (await (await fetch('/api/info')).json()).max_upload;
    setStatus('ready: run the story (Ctrl-Enter) or open a take');
  } catch (e) { showError(`could not reach the studio server: ${e.message}`); }
  renderNow();
  // Milliseconds from navigation start to the first frame drawn with the page's data loaded.
  window.inbetweenStudio.firstPaintMs = performance.now();
})();
