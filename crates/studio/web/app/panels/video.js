// The video panel: open a clip, resequence its frames from a start frame (the engine's jobs), see
// the source and the new order side by side, every jump of the new order on the timeline with its
// explanation on hover, and export MP4 and GIF.
import { $, S, panels, downloadLink } from '../store.js';
import { start, job, uploadJob } from '../jobs.js';
import { tl, frameX, drawTimeline } from '../timeline.js';
import { seek } from '../playback.js';

const videoCorpus = $('video-corpus');
export async function loadVideoCorpus() {
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
    for (const url of [r.files.mp4, r.files.gif]) downloadLink(ex, url);
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
  const n = Math.max(1, v.frames), r = tl.getBoundingClientRect(), x = frameX(r.width, n);
  let best = null, bd = 6;
  for (const j of v.result.jumps) { const d = Math.abs(x(Math.min(j.position, n - 1)) - (e.clientX - r.left)); if (d < bd) { bd = d; best = j; } }
  return best;
}
tl.addEventListener('mousemove', (e) => {
  const j = jumpAt(e), tip = $('video-tip');
  if (!j) { tip.hidden = true; return; }
  tip.textContent = `position ${j.position}: ${j.kind}\n${j.text}`;
  tip.hidden = false;
  tip.style.left = `${Math.min(e.clientX + 12, window.innerWidth - 580)}px`;
  tip.style.top = `${Math.max(8, e.clientY - 20 - tip.offsetHeight)}px`;
});
tl.addEventListener('mouseleave', () => { $('video-tip').hidden = true; });

panels.video = {
  seek: () => drawVideoView(),
  tick() {
    const cv = $('video-source');
    if (cv.width !== cv.clientWidth || cv.height !== cv.clientHeight || $('video-strip').width !== $('video-strip').clientWidth) { drawVideoView(); drawVideoStrip(); drawTimeline(); }
  },
  // The new order's jumps, coloured by kind.
  timeline(c, x, w, h, n) {
    const st = S.video;
    if (!st.result) return;
    c.fillStyle = '#aab1bc'; c.fillText(`new order: ${st.result.order.length} frames, ${st.result.jumps.length} jumps (rest the pointer on a mark)`, 44, 26);
    for (const j of st.result.jumps) {
      const px = x(Math.min(j.position, n - 1));
      c.fillStyle = JUMP_COLORS[j.kind] || '#ffd84d';
      c.fillRect(px - 1.5, 32, 3, h - 40);
      c.beginPath(); c.moveTo(px, 32); c.lineTo(px + 5, 38); c.lineTo(px, 44); c.lineTo(px - 5, 38); c.closePath(); c.fill();
    }
  },
};
