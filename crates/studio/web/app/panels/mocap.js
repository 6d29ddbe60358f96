// The mocap panel: open a take (corpus, file picker, drop on the view), choose keys with one of the
// engine's selectors, see the reconstruction beside the original and its error per frame on the
// timeline, compress to .ibk.
import * as THREE from 'three';
import { $, S, panels, downloadLink, fileName } from '../store.js';
import { canvas, groups, orbitCam, controls, parseGlb, disposeTree } from '../viewer.js';
import { start, job, uploadJob } from '../jobs.js';
import { drawTimeline } from '../timeline.js';
import { seek, renderNow, showPanel } from '../playback.js';

const corpusSelect = $('mocap-corpus');
export async function loadCorpus() {
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
    for (const f of files) r = await uploadJob('/api/mocap/upload', f);
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

const boneNames = (result) => result.skeleton.bones.map((b) => b.name).join('\n');
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
  downloadLink(ex, r.files.ibk, fileName(r.files.ibk), 'compress');
  downloadLink(ex, r.files.decoded, fileName(r.files.decoded), 'compress');
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
  const a = downloadLink(ex, r.files.reconstructed, 'reconstructed.bvh', 'keys');
  ex.prepend(a);
  seek(S.frame);
  drawTimeline();
  renderNow();
  // Freed after the first frame with the new figure: its materials find their programs compiled.
  if (old) { disposeTree(old.holder); disposeTree(old.helper); }
}

panels.mocap = {
  seek(t) {
    const m = S.mocap;
    if (m.orig) m.orig.mixer.setTime(t);
    if (m.rec) m.rec.mixer.setTime(t);
  },
  // The reconstruction's error per frame and the keys.
  timeline(c, x, w, h) {
    const r = S.mocap.keysResult;
    if (!r) return;
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
  },
};
