// inbetween studio: the page. Plain ES modules, three.js through the import map (index.html):
// store (state), viewer (3D view), jobs, timeline, playback, one module per panel, test hooks.
// This one starts the page: the panels register themselves on import; then the first panel, the
// animation loop and the server's lists.
import { S, setStatus, showError } from './store.js';
import { jobState } from './jobs.js';
import { installTimeline } from './timeline.js';
import { seek, renderNow, showPanel, loop } from './playback.js';
import { loadStories } from './panels/script.js';
import { loadCorpus } from './panels/mocap.js';
import './panels/camera.js';
import { loadFaceCorpus } from './panels/face.js';
import { loadVideoCorpus } from './panels/video.js';
import './testhooks.js';

installTimeline(seek);
for (const b of document.querySelectorAll('nav button')) b.addEventListener('click', () => showPanel(b.dataset.panel));
showPanel(S.panel);
requestAnimationFrame(loop);
jobState.pending = (async () => {
  try {
    await Promise.all([loadStories(), loadCorpus(), loadFaceCorpus(), loadVideoCorpus()]);
    jobState.maxUpload = (await (await fetch('/api/info')).json()).max_upload;
    setStatus('ready: run the story (Ctrl-Enter) or open a take');
  } catch (e) { showError(`could not reach the studio server: ${e.message}`); }
  renderNow();
  // Milliseconds from navigation start to the first frame drawn with the page's data loaded.
  window.inbetweenStudio.firstPaintMs = performance.now();
})();
