// The contact viewer: draws what `caliber view` recorded (docs/viewer.md). Reads the JSON in
// <script id="caliber-data">, builds one geometry per distinct mesh, and redraws the poses,
// contacts, pair shares and run-time tasks of the step the slider selects.
//
// window.caliberView exposes what is drawn, for the headless-browser test (viewer/test/view_test.mjs)
// and for anyone at the console: the step shown, how many contacts and task boxes are drawn.

import * as THREE from 'three';
import { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';
import { decodeMeshes, heat, threadColour, boxEdges } from './geometry.js';
import { drawGantt } from './gantt.js';

const data = JSON.parse(document.getElementById('caliber-data').textContent);
const canvas = document.getElementById('view');
const slider = document.getElementById('step');
const label = document.getElementById('step-label');
const info = document.getElementById('info');
const pairList = document.getElementById('pairs');
const showTasks = document.getElementById('show-tasks');
const showObjects = document.getElementById('show-objects');

const renderer = new THREE.WebGLRenderer({ canvas, antialias: true, preserveDrawingBuffer: true });
renderer.setPixelRatio(window.devicePixelRatio || 1);
const scene = new THREE.Scene();
const background = new THREE.Color(0xf4f4f0);
scene.background = background;
scene.add(new THREE.HemisphereLight(0xffffff, 0x8a8a80, 2.2));
const sun = new THREE.DirectionalLight(0xffffff, 1.6);
sun.position.set(1, 2, 3);
scene.add(sun);

const camera = new THREE.PerspectiveCamera(40, 1, 1e-4, 1e6);
const controls = new OrbitControls(camera, canvas);
controls.addEventListener('change', render);

// One geometry per distinct mesh, one THREE.Mesh per object (posed per step).
const geometries = decodeMeshes(data.meshes);
const objects = data.objects.map((o, i) => {
  const material = new THREE.MeshStandardMaterial({
    color: new THREE.Color().setHSL((i * 0.137) % 1, 0.25, 0.72),
    roughness: 0.8, metalness: 0.0, transparent: true, opacity: 0.55, side: THREE.DoubleSide,
    depthWrite: false,
  });
  const mesh = new THREE.Mesh(geometries[o.mesh], material);
  mesh.matrixAutoUpdate = false;
  mesh.name = o.name;
  scene.add(mesh);
  return mesh;
});

// What changes with the step, rebuilt on each change.
const dynamic = new THREE.Group();
scene.add(dynamic);

function poseMatrix(p) {
  // p: row-major rotation (9 numbers) then translation (3).
  return new THREE.Matrix4().set(p[0], p[1], p[2], p[9], p[3], p[4], p[5], p[10], p[6], p[7], p[8], p[11], 0, 0, 0, 1);
}

function clearDynamic() {
  for (const child of [...dynamic.children]) {
    dynamic.remove(child);
    child.geometry?.dispose();
    child.material?.dispose();
  }
}

// The two objects of the pair with the most node tests over the run: where the work is, what the
// camera frames first ("frame all" frames every object).
function heaviestPairObjects() {
  const work = new Map();
  for (const step of data.steps) for (const p of step.pairs) work.set(p.a + ',' + p.b, (work.get(p.a + ',' + p.b) ?? 0) + p.node_tests);
  let best = null;
  for (const [key, tests] of work) if (!best || tests > best[1]) best = [key, tests];
  return best ? best[0].split(',').map((i) => objects[Number(i)]) : objects;
}

function sceneSize(framed) {
  const box = new THREE.Box3();
  for (const o of framed) box.expandByObject(o);
  return box;
}

let normalLength = 1;

function fitCamera(framed) {
  const box = sceneSize(framed);
  const centre = box.getCenter(new THREE.Vector3());
  const size = Math.max(box.getSize(new THREE.Vector3()).length(), 1e-9);
  normalLength = size * 0.03;
  camera.near = size * 1e-3;
  camera.far = size * 1000;
  camera.position.copy(centre).add(new THREE.Vector3(0.55, 0.4, 0.75).multiplyScalar(size * 1.5));
  camera.updateProjectionMatrix();
  controls.target.copy(centre);
  controls.update();
}

// Contacts of the step: points coloured by their pair's share of the step's node tests, normals
// as short segments from each point (A's side).
function drawContacts(step, shareOf) {
  const c = step.contacts;
  const n = c.pairs.length / 2;
  const positions = new Float32Array(n * 3);
  const colours = new Float32Array(n * 3);
  const segments = new Float32Array(n * 6);
  for (let k = 0; k < n; ++k) {
    const colour = heat(shareOf(c.pairs[2 * k], c.pairs[2 * k + 1]));
    for (let j = 0; j < 3; ++j) {
      positions[3 * k + j] = c.points[3 * k + j];
      segments[6 * k + j] = c.points[3 * k + j];
      segments[6 * k + 3 + j] = c.points[3 * k + j] + normalLength * c.normals[3 * k + j];
    }
    colours.set([colour.r, colour.g, colour.b], 3 * k);
  }
  const points = new THREE.BufferGeometry();
  points.setAttribute('position', new THREE.BufferAttribute(positions, 3));
  points.setAttribute('color', new THREE.BufferAttribute(colours, 3));
  const cloud = new THREE.Points(points, new THREE.PointsMaterial({ size: 6, sizeAttenuation: false, vertexColors: true }));
  cloud.name = 'contacts';
  dynamic.add(cloud);
  const lines = new THREE.BufferGeometry();
  lines.setAttribute('position', new THREE.BufferAttribute(segments, 3));
  dynamic.add(new THREE.LineSegments(lines, new THREE.LineBasicMaterial({ color: 0x1a1a1a })));
  return n;
}

// Run-time tasks: the box of each root's node in A, posed with A, coloured by the thread that ran it.
function drawTasks(step) {
  const positions = [];
  const colours = [];
  let boxes = 0;
  for (const task of step.tasks) {
    const colour = threadColour(task.thread, data.threads);
    for (const root of task.roots) {
      const [object, cx, cy, cz, hx, hy, hz] = root;
      boxEdges(positions, poseMatrix(step.poses[object]), cx, cy, cz, hx, hy, hz);
      for (let e = 0; e < 24; ++e) colours.push(colour.r, colour.g, colour.b);
      ++boxes;
    }
  }
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', new THREE.Float32BufferAttribute(positions, 3));
  geometry.setAttribute('color', new THREE.Float32BufferAttribute(colours, 3));
  const lines = new THREE.LineSegments(geometry, new THREE.LineBasicMaterial({ vertexColors: true }));
  lines.name = 'tasks';
  dynamic.add(lines);
  return boxes;
}

function listPairs(step, total) {
  pairList.replaceChildren();
  const sorted = [...step.pairs].sort((x, y) => y.node_tests - x.node_tests).slice(0, 12);
  for (const p of sorted) {
    const share = total > 0 ? p.node_tests / total : 0;
    const row = document.createElement('div');
    row.className = 'pair';
    const swatch = document.createElement('span');
    swatch.className = 'swatch';
    swatch.style.background = '#' + heat(share).getHexString();
    row.append(swatch, `${data.objects[p.a].name} / ${data.objects[p.b].name}: ${(100 * share).toFixed(1)} % · ${p.contacts} contacts`);
    pairList.append(row);
  }
}

const state = { ready: false, step: 0, drawnContacts: 0, drawnTaskBoxes: 0 };

function showStep(index) {
  const step = data.steps[index];
  objects.forEach((o, i) => {
    o.matrix.copy(poseMatrix(step.poses[i]));
    o.matrixWorldNeedsUpdate = true;
    o.visible = showObjects.checked;
  });
  clearDynamic();
  const total = step.pairs.reduce((sum, p) => sum + p.node_tests, 0);
  const shares = new Map(step.pairs.map((p) => [p.a + ',' + p.b, total > 0 ? p.node_tests / total : 0]));
  state.step = index;
  state.drawnContacts = drawContacts(step, (a, b) => shares.get(a + ',' + b) ?? 0);
  state.drawnTaskBoxes = showTasks.checked ? drawTasks(step) : 0;
  label.textContent = `step ${step.step}`;
  info.textContent = `${data.scene} · ${data.method} on ${data.threads} thread(s) · ${data.query} query · ` +
    `${state.drawnContacts} contacts · ${step.pairs.length} pairs · ${total} node tests · ${step.tasks.length} run-time tasks · ` +
    `${step.step_ms.toFixed(2)} ms`;
  listPairs(step, total);
  drawGantt(document.getElementById('gantt'), step, data.threads);
  render();
}

function render() {
  renderer.render(scene, camera);
}

function resize() {
  const w = canvas.clientWidth;
  const h = canvas.clientHeight;
  renderer.setSize(w, h, false);
  camera.aspect = w / Math.max(h, 1);
  camera.updateProjectionMatrix();
  render();
}

// The share of the drawing that is not background: the test's evidence that WebGL drew the meshes.
function coveredFraction() {
  render();
  const gl = renderer.getContext();
  const w = gl.drawingBufferWidth;
  const h = gl.drawingBufferHeight;
  const pixels = new Uint8Array(w * h * 4);
  gl.readPixels(0, 0, w, h, gl.RGBA, gl.UNSIGNED_BYTE, pixels);
  const bg = [0xf4, 0xf4, 0xf0];  // the background, as drawn (sRGB)
  let covered = 0;
  for (let i = 0; i < pixels.length; i += 4) {
    if (Math.abs(pixels[i] - bg[0]) + Math.abs(pixels[i + 1] - bg[1]) + Math.abs(pixels[i + 2] - bg[2]) > 12) ++covered;
  }
  return covered / (w * h);
}

slider.max = String(data.steps.length - 1);
slider.addEventListener('input', () => showStep(Number(slider.value)));
showTasks.addEventListener('change', () => showStep(state.step));
showObjects.addEventListener('change', () => showStep(state.step));
window.addEventListener('resize', resize);
showTasks.disabled = !data.steps.some((s) => s.tasks.length > 0);
document.getElementById('frame-all').addEventListener('click', () => { fitCamera(objects); showStep(state.step); });
document.getElementById('frame-heaviest').addEventListener('click', () => { fitCamera(heaviestPairObjects()); showStep(state.step); });
showStep(0);
fitCamera(heaviestPairObjects());
showStep(0);
resize();
state.ready = true;
window.caliberView = { state, showStep, coveredFraction, data, scene };
