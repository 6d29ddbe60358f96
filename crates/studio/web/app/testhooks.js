// Test hooks (crates/studio/README.md): `window.inbetweenStudio`, what the browser tests and the
// bench read and drive (the state of the open panel, ready(), seek, timeline drags, the camera
// gizmo, face keys). The page's data-testid attributes are the other half.
import * as THREE from 'three';
import { $, S, panelState } from './store.js';
import { orbitCam, controls } from './viewer.js';
import { start, jobState } from './jobs.js';
import { tl } from './timeline.js';
import { seek, renderNow } from './playback.js';
import { gizmoMoved } from './panels/camera.js';
import { faceMask, updateKeysCount, drawFaceView } from './panels/face.js';

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
  ready: () => jobState.pending.then(() => undefined),
  seek: (f) => { seek(f); renderNow(); },
  // How many jobs the page has started (lets a test wait for a job a file change starts).
  started: () => jobState.started,
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
