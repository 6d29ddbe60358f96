// The timeline under the view: a ruler in seconds, the open panel's rows (drawn by the panel's
// `timeline` hook), the playhead; a click or drag seeks, or, where the panel takes it (the face
// span), a drag edits.
import { $, S, panelState, panels, capture } from './store.js';

export const tl = $('timeline');
// The x of frame `f` on a timeline `w` pixels wide over `n` frames.
export const frameX = (w, n) => (f) => 40 + (w - 50) * (n > 1 ? f / (n - 1) : 0);
// The frame under a pointer event (fractional, clamped to the open panel's frames).
export function frameAt(e) {
  const n = Math.max(1, panelState().frames);
  const r = tl.getBoundingClientRect();
  return Math.max(0, Math.min(n - 1, (e.clientX - r.left - 40) / (r.width - 50) * (n - 1)));
}

export function drawTimeline() {
  const w = tl.clientWidth, h = tl.clientHeight;
  if (tl.width !== w) tl.width = w;
  if (tl.height !== h) tl.height = h;
  const c = tl.getContext('2d');
  c.fillStyle = '#15171c'; c.fillRect(0, 0, w, h);
  const st = panelState();
  const n = Math.max(1, st.frames);
  const x = frameX(w, n);
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
  panels[S.panel]?.timeline?.(c, x, w, h, n);
  // Playhead.
  c.strokeStyle = '#4da3ff'; c.lineWidth = 2;
  c.beginPath(); c.moveTo(x(S.frame), 0); c.lineTo(x(S.frame), h); c.stroke(); c.lineWidth = 1;
}

// Pointer handling: `seek(frame)` is playback's (passed in, so this module does not import it).
export function installTimeline(seek) {
  let scrubbing = false;
  let dragFrom = null;
  tl.addEventListener('pointerdown', (e) => { scrubbing = true; capture(tl, e); dragFrom = { x: e.clientX, f: frameAt(e) }; seek(frameAt(e)); });
  tl.addEventListener('pointermove', (e) => {
    if (!scrubbing) return;
    const drag = dragFrom && Math.abs(e.clientX - dragFrom.x) > 4;
    if (drag && panels[S.panel]?.timelineDrag?.(dragFrom.f, frameAt(e))) return;
    seek(frameAt(e));
  });
  tl.addEventListener('pointerup', () => { scrubbing = false; dragFrom = null; });
}
