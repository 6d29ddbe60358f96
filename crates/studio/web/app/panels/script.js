// The script panel: a story's text (built-in or opened), run on the server; the scene and its
// characters in the 3D view, diagnostics at their words, each character's actions on the timeline.
import * as THREE from 'three';
import { $, S, panels, downloadLink } from '../store.js';
import { groups, orbitCam, controls, parseGlb, disposeTree, requestRender } from '../viewer.js';
import { start, job } from '../jobs.js';
import { drawTimeline } from '../timeline.js';
import { seek, renderNow } from '../playback.js';

const storySelect = $('script-story');
const text = $('script-text');
const backdrop = $('script-backdrop');
const COLORS = ['#d62728', '#1f77b4', '#2ca02c', '#9467bd', '#ff7f0e', '#17becf'];

export async function loadStories() {
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
  downloadLink(ex, r.files.glb, 'story.glb');
  downloadLink(ex, r.files.gltf, 'story.gltf');
  downloadLink(ex, r.files.scene, 'scene.json');
  for (const c of r.characters) downloadLink(ex, c.bvh, `${c.name}.bvh`);
  const json = document.createElement('a');
  json.href = URL.createObjectURL(new Blob([JSON.stringify(r, null, 1)], { type: 'application/json' }));
  json.textContent = 'story.json'; json.download = 'story.json'; ex.appendChild(json);
  S.frame = Math.min(S.frame, r.frames - 1);
  seek(S.frame);
  drawTimeline();
  const t3 = performance.now();
  renderNow();
  S.drawTimes.render_ms = performance.now() - t3;
  for (const c of old) disposeTree(c);
}

// Through the story's shot camera when asked.
const shotView = () => S.panel === 'script' && $('script-shotcam').checked && S.script.shotCam;

panels.script = {
  seek(t) {
    const st = S.script;
    if (!st.mixer) return;
    st.mixer.setTime(t);
    if (st.camHelper) { st.gltf.scene.updateMatrixWorld(true); st.camHelper.update(); }
  },
  beforeRender() { if (S.script.camHelper) S.script.camHelper.visible = !shotView(); },
  viewCamera: () => shotView() || null,
  // Each character's actions, one row per character.
  timeline(c, x, w, h) {
    const st = S.script;
    if (!st.result) return;
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
  },
};
