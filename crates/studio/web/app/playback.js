// Playback: the frame shown (seek), the play button, the animation loop that draws the view when
// asked, and which panel is open.
import { $, S, panelState, panels } from './store.js';
import { canvas, renderer, scene, orbitCam, groups, needsRender, rendered, requestRender } from './viewer.js';
import { drawTimeline } from './timeline.js';

export function seek(frame) {
  const st = panelState();
  const n = Math.max(1, st.frames);
  S.frame = Math.max(0, Math.min(n - 1, Math.round(frame)));
  const hooks = panels[S.panel] || {};
  const t = hooks.frameTime?.(S.frame) ?? S.frame / (st.fps || 30);
  hooks.seek?.(t, S.frame);
  $('frame').textContent = `${S.frame} / ${Math.max(0, n - 1)}`;
  $('time').textContent = `${t.toFixed(2)} s`;
  drawTimeline();
  requestRender();
}

export function renderNow() {
  rendered();
  for (const p of Object.values(panels)) p.beforeRender?.();
  const cam = panels[S.panel]?.viewCamera?.() || orbitCam;
  renderer.render(scene, cam);
}

// Fits the renderer and the cameras to the canvas when its size changed.
export function resize() {
  const w = canvas.clientWidth, h = canvas.clientHeight;
  if (canvas.width !== w || canvas.height !== h) {
    renderer.setSize(w, h, false);
    orbitCam.aspect = w / Math.max(1, h);
    orbitCam.updateProjectionMatrix();
    if (S.script.shotCam) { S.script.shotCam.aspect = orbitCam.aspect; S.script.shotCam.updateProjectionMatrix(); }
    drawTimeline();
    requestRender();
  }
}

export function showPanel(name) {
  S.panel = name;
  S.playing = false;
  for (const b of document.querySelectorAll('nav button')) b.classList.toggle('active', b.dataset.panel === name);
  for (const p of document.querySelectorAll('section.panel')) p.hidden = p.dataset.panel !== name;
  for (const [g, group] of Object.entries(groups)) group.visible = name === g;
  for (const [p, hooks] of Object.entries(panels)) hooks.show?.(p === name);
  canvas.hidden = name === 'face' || name === 'video';
  $('face-view').hidden = name !== 'face';
  $('video-view').hidden = name !== 'video';
  S.frame = Math.min(S.frame, Math.max(0, panelState().frames - 1));
  seek(S.frame);
  resize();
}

const clock = { last: performance.now() };
$('play').addEventListener('click', () => { S.playing = !S.playing; $('play').textContent = S.playing ? '❚❚' : '▶'; clock.last = performance.now(); });
document.addEventListener('keydown', (e) => { if (e.key === ' ' && e.target === document.body) { e.preventDefault(); $('play').click(); } });

export function loop(now) {
  requestAnimationFrame(loop);
  resize();
  panels[S.panel]?.tick?.();
  if (S.playing) {
    const st = panelState();
    let playFrame = S.frame + (now - clock.last) / 1000 * (st.fps || 30);
    if (playFrame >= st.frames - 1) playFrame = 0;
    seek(playFrame);
  }
  clock.last = now;
  if (needsRender()) renderNow();
}
