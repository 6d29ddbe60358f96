// The camera panel: a scene of two characters, camera keys in Toric space (edited as numbers, taken
// from the view, or placed with a gizmo in the viewport, moved in time on the timeline), and the
// trajectories the engine generates in each style between them.
import * as THREE from 'three';
import { TransformControls } from 'three/addons/controls/TransformControls.js';
import { $, S, panels, capture, showError, downloadLink } from '../store.js';
import { canvas, scene, groups, orbitCam, controls, disposeTree, requestRender } from '../viewer.js';
import { start, job, post, uploadJob } from '../jobs.js';
import { tl, frameX, drawTimeline } from '../timeline.js';
import { seek, renderNow } from '../playback.js';

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
  if (t) for (const [url, label] of [[t.files.json, `camera-${style}.json`], [t.files.gltf, `camera-${style}.gltf`]]) downloadLink(ex, url, label);
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
  const r = tl.getBoundingClientRect(), x = frameX(r.width, Math.max(1, c.frames));
  let best = -1, bd = 7;
  c.keys.forEach((k, i) => { const d = Math.abs(x(k.frame) - (e.clientX - r.left)); if (d < bd && e.clientY - r.top < 60) { bd = d; best = i; } });
  return best;
}
let draggingKey = -1;
tl.addEventListener('pointerdown', (e) => {
  const i = cameraKeyNear(e);
  if (i < 0) return;
  e.stopImmediatePropagation();
  if (e.button === 2) return;
  S.camera.selKey = i; draggingKey = i; renderCameraKeys();
  capture(tl, e);
}, true);
tl.addEventListener('pointermove', (e) => {
  if (draggingKey < 0) return;
  e.stopImmediatePropagation();
  const c = S.camera, k = c.keys[draggingKey], r = tl.getBoundingClientRect();
  const f = Math.round(Math.max(0, Math.min(c.frames - 1, (e.clientX - r.left - 40) / (r.width - 50) * (c.frames - 1))));
  if (!c.keys.some((o) => o !== k && o.frame === f)) { k.frame = f; $('ck-frame').value = f; drawTimeline(); }
}, true);
tl.addEventListener('pointerup', () => { if (draggingKey >= 0) { const k = S.camera.keys[draggingKey]; draggingKey = -1; renderCameraKeys(); S.camera.selKey = S.camera.keys.indexOf(k); renderCameraKeys(); } }, true);
tl.addEventListener('contextmenu', (e) => {
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
export async function gizmoMoved() {
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

panels.camera = {
  seek: (t, frame) => seekCamera(frame),
  show(active) { gizmo.getHelper().visible = active; gizmo.enabled = active; },
  // Through the chosen trajectory's camera when asked.
  viewCamera() {
    const cam = S.camera;
    if (!($('camera-shot').checked && cam.selected && cam.cam)) return null;
    cam.cam.aspect = orbitCam.aspect; cam.cam.updateProjectionMatrix();
    return cam.cam;
  },
  // The keys (triangles; the selected one white), velocity marks, and each trajectory's frames.
  timeline(c, x, w, h) {
    const st = S.camera;
    if (!st.scene) return;
    c.fillStyle = '#aab1bc';
    const t = st.trajectories.find((tr) => tr.style === st.selected);
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
  },
};
