// The page's state, in one place: `S` with a named field per panel, and `panels`, the hooks each
// panel module registers so the shared modules (playback, timeline, viewer) reach a panel without
// importing it. Every other module imports this one; it imports nothing.

export const $ = (id) => document.getElementById(id);

export const S = {
  panel: 'script',
  playing: false,
  frame: 0,
  lastJob: null,
  // The last story drawn: ms of its request, fetch, parse, build and first render (the bench).
  drawTimes: null,
  script: { result: null, gltf: null, mixer: null, shotCam: null, camHelper: null, fps: 30, frames: 0, framed: false },
  mocap: { take: null, keysResult: null, orig: null, rec: null, fps: 30, frames: 0, scale: 0.01 },
  face: {
    take: null, orig: null, cur: null, keys: [], changed: [], lastEdit: null, fps: 60, frames: 0,
    version: 0, versions: 1, variants: null, picked: null,
  },
  video: { clip: null, sprite: null, result: null, fps: 25, frames: 0 },
  camera: {
    scene: null, keys: [], selKey: 0, trajectories: [], selected: null, fps: 30, frames: 0,
    framed: false, figures: [], paths: null, cam: null, helper: null, proxy: null, arrow: null, lookAt: null,
  },
};

// The open panel's state.
export const panelState = () => S[S.panel];

// Per panel (all optional): seek(t, frame) poses the view at time t; frameTime(frame) the time of
// a frame when not frame / fps; timeline(c, x, w, h, n) draws the panel's rows on the timeline;
// timelineDrag(fromFrame, frame) handles a drag on it (true when it did); tick() runs every
// animation frame; beforeRender() and viewCamera() (the camera to render through, or null);
// show(active) when the panel opens or closes.
export const panels = {};

export function setStatus(text) { $('status').textContent = text; }
export function showError(msg) { $('error').textContent = msg; }
export function clearError() { $('error').textContent = ''; }
// Keeps a drag's pointer events on `el` (a pointer the browser does not know, as in a scripted
// test, just goes without capture).
export function capture(el, e) { try { el.setPointerCapture(e.pointerId); } catch { /* no such pointer */ } }
// The file name of a result URL (`/api/files/mocap/walk.ibk?v=3` → `walk.ibk`).
export const fileName = (url) => url.split('/').pop().split('?')[0];
// A download link for a result URL in `box`, named `label`.
export function downloadLink(box, url, label = fileName(url), className = '') {
  const a = document.createElement('a');
  a.href = url + '&download=1'; a.textContent = label; a.download = label;
  if (className) a.className = className;
  box.appendChild(a);
  return a;
}
