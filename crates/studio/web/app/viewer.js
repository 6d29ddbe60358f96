// The 3D view: renderer, scene, orbit camera, one group per panel that draws in 3D, and glTF
// loading with embedded images shared between loads.
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import { $ } from './store.js';

export const canvas = $('viewport');
export const renderer = new THREE.WebGLRenderer({ canvas, antialias: true, preserveDrawingBuffer: true });
renderer.setPixelRatio(1);
export const scene = new THREE.Scene();
scene.background = new THREE.Color(0x2b2f37);
scene.add(new THREE.HemisphereLight(0xffffff, 0x444a55, 1.6));
const sun = new THREE.DirectionalLight(0xffffff, 1.8);
sun.position.set(4, 8, 6);
scene.add(sun);
scene.add(new THREE.GridHelper(30, 30, 0x59606c, 0x3a3f48));
export const orbitCam = new THREE.PerspectiveCamera(45, 1, 0.05, 500);
orbitCam.position.set(6, 5, 9);
export const controls = new OrbitControls(orbitCam, canvas);
controls.target.set(2, 0.8, 2);
controls.update();
controls.addEventListener('change', () => requestRender());
export const groups = { script: new THREE.Group(), mocap: new THREE.Group(), camera: new THREE.Group() };
scene.add(groups.script, groups.mocap, groups.camera);

// Whether the view needs drawing at the next animation frame.
const view = { dirty: true };
export function requestRender() { view.dirty = true; }
export const needsRender = () => view.dirty;
export function rendered() { view.dirty = false; }

// Frees the GPU buffers and textures of objects leaving the scene (a story run or a K change
// replaces them; without this every edit would leave its meshes in GPU memory).
export function disposeTree(root) {
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

export function parseGlb(buf) {
  return new Promise((resolve, reject) => new GLTFLoader().register((p) => new SharedTextures(p))
    .parse(buf, '', resolve, (e) => reject(new Error(`glTF: ${e.message || e}`))));
}
