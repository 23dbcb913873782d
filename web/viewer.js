// Penumbra live viewer: one WebSocket to the simulator (docs/viewer.md has the messages).
// commands are the bridges' commands (docs/zmq-protocol.md) as JSON; camera frames arrive as
// binary messages (u32 little-endian header length, JSON header, JPEG bytes).
import * as THREE from './three/build/three.module.js';
import { OrbitControls } from './three/examples/jsm/controls/OrbitControls.js';

const $ = (id) => document.getElementById(id);
const viewer = {            // state the tests read through window.penumbraViewer
  hello: null, scene: null, state: null, connected: false,
  framesReceived: 0, framesDrawn: 0, lastFrame: {}, errors: [], replies: [],
};
window.penumbraViewer = viewer;

// ---------- connection and commands ----------
let ws = null;
let nextId = 1;
const pending = new Map();

function log(text) {
  const el = $('log');
  el.textContent = (text + '\n' + el.textContent).slice(0, 4000);
}

function send(cmd, fields = {}) {
  if (!ws || ws.readyState !== WebSocket.OPEN) return Promise.reject(new Error('not connected'));
  const id = nextId++;
  ws.send(JSON.stringify({ cmd, id, ...fields }));
  return new Promise((resolve, reject) => {
    pending.set(id, { resolve, reject });
    setTimeout(() => { if (pending.delete(id)) reject(new Error(cmd + ': no reply')); }, 10000);
  });
}
viewer.send = send;

// the run's secret token, from the URL penumbra printed (http://127.0.0.1:PORT/?token=...):
// the server refuses a WebSocket without it (docs/viewer.md, "Access")
const token = new URLSearchParams(location.search).get('token') || '';

function connect() {
  ws = new WebSocket(`ws://${location.host}/ws?token=${encodeURIComponent(token)}`);
  ws.binaryType = 'arraybuffer';
  ws.onopen = () => { viewer.connected = true; setBadge('connection', 'connected', 'on'); };
  ws.onclose = () => {
    viewer.connected = false;
    setBadge('connection', 'disconnected', 'off');
    setTimeout(connect, 1000);
  };
  ws.onmessage = (ev) => {
    if (typeof ev.data !== 'string') return onFrame(ev.data);
    let m;
    try { m = JSON.parse(ev.data); } catch (e) { return log('bad message from server'); }
    if (m.type === 'viewer_hello') return onHello(m);
    if (m.type === 'scene') return onScene(m);
    if (m.type === 'state') return onState(m);
    if (m.type === 'lidar') return onLidar(m);
    if (m.type === 'status') return onStatus(m);
    if (m.type === 'error' || m.ok === false) {
      const text = m.error && m.error.message ? `${m.cmd}: ${m.error.message}` : String(m.error);
      viewer.errors.push(m);
      log(text);
    }
    if (m.id !== undefined && pending.has(m.id)) {
      const p = pending.get(m.id);
      pending.delete(m.id);
      viewer.replies.push(m);
      if (m.ok === false) p.reject(new Error(JSON.stringify(m.error))); else p.resolve(m);
    }
  };
}

function setBadge(id, text, cls) {
  const el = $(id);
  el.textContent = text;
  el.className = 'badge ' + (cls || '');
}

// ---------- hello: build the controls ----------
function onHello(h) {
  viewer.hello = h;
  $('world').textContent = h.world || '';
  $('controlPeriod').textContent = (h.control_period_sec || 0).toFixed(4);
  $('rtf').value = h.realtime_factor;
  const preset = $('preset');
  preset.innerHTML = '';
  for (const name of h.presets || []) preset.add(new Option(name, name, false, name === h.preset));
  buildEffectSliders(h.effect_sliders || []);
  buildJointSliders(h.joint_controls || []);
  $('teleop').style.display = (h.teleop_robots || []).length ? '' : 'none';
  $('record').disabled = !h.record_available;
  if (!h.record_available) $('recordState').textContent = 'no live recorder in this build';
  if (!document.querySelector('.cam-panel') && h.model && h.model.cameras.length) addCameraPanel();
  for (const p of panels) p.fillCameras();
  subscribe();
}

function sliderRow(parent, label, min, max, step, value, unit, oninput) {
  const row = document.createElement('div');
  row.className = 'slider';
  const l = document.createElement('label');
  const name = document.createElement('span');
  name.textContent = label;
  const input = document.createElement('input');
  input.type = 'range';
  Object.assign(input, { min, max, step });
  input.value = value;
  const out = document.createElement('output');
  out.textContent = `${Number(value).toPrecision(3)} ${unit}`;
  input.addEventListener('input', () => {
    out.textContent = `${Number(input.value).toPrecision(3)} ${unit}`;
  });
  input.addEventListener('change', () => oninput(Number(input.value)));
  l.append(name, input, out);
  row.append(l);
  parent.append(row);
  return input;
}

// the adversity sliders: their ranges come with hello, their values only with the server's
// status messages (renderAdversity): the page never shows a value the run is not in
const effectInputs = new Map();   // "block.key" -> {input, out, slider, dragging}

function buildEffectSliders(sliders) {
  const box = $('effectSliders');
  box.innerHTML = '';
  effectInputs.clear();
  for (const s of sliders) {
    const input = sliderRow(box, s.label, s.min, s.max, s.step, s.off, s.unit, (v) => {
      // the slider's "off" end removes the block
      const params = v === s.off ? null : { [s.key]: s.integer ? Math.round(v) : v };
      send('set_effect', { effect: s.block, params }).catch((e) => {
        log(e.message);
        renderAdversity(viewer.adversity);   // refused: back to the run's value
      });
    });
    input.id = `effect_${s.block}_${s.key}`;
    const e = { input, out: input.nextElementSibling, slider: s, dragging: false };
    input.addEventListener('pointerdown', () => { e.dragging = true; });
    input.addEventListener('change', () => { e.dragging = false; });
    effectInputs.set(`${s.block}.${s.key}`, e);
  }
  if (viewer.adversity) renderAdversity(viewer.adversity);
}

// shows the run's adversity (a status message's `adversity`): preset, and each slider's value
// (null: the block is off, the slider at its off end)
function renderAdversity(a) {
  if (!a) return;
  viewer.adversity = a;
  const preset = $('preset');
  if (![...preset.options].some((o) => o.value === a.preset)) preset.add(new Option(a.preset, a.preset));
  preset.value = a.preset;
  $('presetEdited').textContent = a.edited ? 'changed live' : '';
  for (const [name, e] of effectInputs) {
    if (e.dragging) continue;
    const v = a.values[name];
    const shown = v === null || v === undefined ? e.slider.off : v;
    e.input.value = shown;
    const text = e.slider.integer ? String(Math.round(shown)) : Number(shown).toPrecision(3);
    e.out.textContent = `${text} ${e.slider.unit}`;
  }
}

function buildJointSliders(controls) {
  const box = $('jointSliders');
  box.innerHTML = '';
  for (const c of controls) {
    const title = document.createElement('div');
    title.className = 'dim';
    title.textContent = c.kind === 'joint_targets' ? `${c.robot}: joint targets` : 'actuators (ctrl)';
    box.append(title);
    const values = c.value.slice();
    c.names.forEach((name, i) => {
      const step = (c.max[i] - c.min[i]) / 200 || 0.01;
      sliderRow(box, name, c.min[i], c.max[i], step, values[i], c.unit || '', (v) => {
        values[i] = v;
        if (c.kind === 'joint_targets')
          send('joint_targets', { robot: c.robot, mode: 'position', values }).catch((e) => log(e.message));
        else send('set_ctrl', { ctrl: { [name]: v } }).catch((e) => log(e.message));
      });
    });
  }
}

// ---------- camera panels ----------
const panels = [];
const decoding = {};        // stream -> true while a frame of it decodes
const latestFrame = {};     // stream -> newest frame waiting for the decoder
let streamFrames = 0;

class CameraPanel {
  constructor() {
    const el = document.createElement('div');
    el.className = 'cam-panel';
    el.innerHTML = `<div class="bar"><select class="cam-select"></select>
      <select class="kind-select"><option value="rgb">RGB</option><option value="depth">depth</option>
      <option value="segmentation">segmentation</option></select>
      <button class="close" title="close">x</button><span class="info"></span></div>
      <div class="cam-view"><canvas class="cam" width="640" height="480"></canvas></div>
      <div class="scale" style="visibility:hidden"><span class="near"></span><canvas width="256" height="1"></canvas><span class="far"></span></div>`;
    $('cameraPanels').append(el);
    this.el = el;
    this.canvas = el.querySelector('canvas.cam');
    this.camSelect = el.querySelector('.cam-select');
    this.kindSelect = el.querySelector('.kind-select');
    this.info = el.querySelector('.info');
    this.scale = el.querySelector('.scale');
    this.camSelect.addEventListener('change', () => subscribe());
    this.kindSelect.addEventListener('change', () => subscribe());
    el.querySelector('.close').addEventListener('click', () => {
      panels.splice(panels.indexOf(this), 1);
      el.remove();
      subscribe();
    });
    this.fillCameras();
  }
  fillCameras() {
    const h = viewer.hello;
    if (!h || !h.model) return;
    const keep = this.camSelect.value;
    this.camSelect.innerHTML = '';
    for (const c of h.model.cameras) this.camSelect.add(new Option(c.name, c.name, false, c.name === keep));
  }
  stream() { return `camera/${this.camSelect.value}/${this.kindSelect.value}`; }
  draw(header, bitmap) {
    if (this.canvas.width !== bitmap.width) this.canvas.width = bitmap.width;
    if (this.canvas.height !== bitmap.height) this.canvas.height = bitmap.height;
    this.canvas.getContext('2d').drawImage(bitmap, 0, 0);
    this.info.textContent = `t ${header.time_sec.toFixed(3)} s  #${header.index}  q${header.quality}`;
    this.canvas.dataset.timeSec = header.time_sec;
    this.canvas.dataset.step = header.step;
    if (header.kind === 'depth') {
      this.scale.style.visibility = 'visible';
      this.scale.querySelector('.near').textContent = `${header.near_m.toFixed(2)} m`;
      this.scale.querySelector('.far').textContent = `${header.far_m.toFixed(2)} m`;
      drawColormap(this.scale.querySelector('canvas'));
    } else {
      this.scale.style.visibility = 'hidden';
    }
  }
}

function drawColormap(canvas) {
  const cmap = viewer.hello && viewer.hello.colormap;
  if (!cmap || canvas.dataset.done) return;
  const ctx = canvas.getContext('2d');
  cmap.forEach((c, i) => { ctx.fillStyle = c; ctx.fillRect(i, 0, 1, 1); });
  canvas.dataset.done = '1';
}

function addCameraPanel() {
  const p = new CameraPanel();
  panels.push(p);
  subscribe();
  return p;
}

function subscribe() {
  const streams = [...new Set(panels.map((p) => p.stream()))];
  if (ws && ws.readyState === WebSocket.OPEN)
    send('subscribe', { streams }).catch((e) => log(e.message));
}

function onFrame(buf) {
  const dv = new DataView(buf);
  const n = dv.getUint32(0, true);
  const header = JSON.parse(new TextDecoder().decode(new Uint8Array(buf, 4, n)));
  viewer.framesReceived++;
  streamFrames++;
  latestFrame[header.stream] = { header, jpeg: new Blob([new Uint8Array(buf, 4 + n)], { type: 'image/jpeg' }) };
  decodeNext(header.stream);
}

function decodeNext(stream) {
  if (decoding[stream] || !latestFrame[stream]) return;
  const { header, jpeg } = latestFrame[stream];
  delete latestFrame[stream];
  decoding[stream] = true;
  createImageBitmap(jpeg).then((bitmap) => {
    for (const p of panels) if (p.stream() === stream) p.draw(header, bitmap);
    bitmap.close();
    viewer.framesDrawn++;
    viewer.lastHeader = header;
    viewer.lastFrame[stream] = { time_sec: header.time_sec, step: header.step, index: header.index, drawn_ms: performance.now() };
    if (header.stream.endsWith('/rgb')) updateFrustum(header);
  }).catch((e) => log('frame: ' + e.message)).finally(() => {
    decoding[stream] = false;
    decodeNext(stream);
  });
}

// ---------- 3D overview ----------
const overview = $('overview');
const renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
renderer.setPixelRatio(window.devicePixelRatio);
overview.append(renderer.domElement);
const scene3 = new THREE.Scene();
scene3.background = new THREE.Color(0x0d0f12);
const camera3 = new THREE.PerspectiveCamera(55, 1, 0.05, 500);
camera3.up.set(0, 0, 1);
camera3.position.set(-6, -7, 6);
const orbit = new OrbitControls(camera3, renderer.domElement);
orbit.target.set(0, 0, 0.3);
orbit.update();
scene3.add(new THREE.HemisphereLight(0xffffff, 0x404040, 0.9));
const sunLight = new THREE.DirectionalLight(0xffffff, 0.6);
sunLight.position.set(3, 5, 10);
scene3.add(sunLight);
scene3.add(new THREE.AxesHelper(0.5));
// for the tests: the overview's renderer, scene, camera and body nodes
viewer.three = { renderer, scene: scene3, camera: camera3, bodyNodes: () => bodyNodes, cutAway: () => cutAway() };
let bodyNodes = [];
let robotBody = -1;          // the body the camera orbits (findRobotBody)
let cameraPlaced = false;    // the camera was put on the robot (first state after a scene)
let staticObjects = [];      // static geoms the cut-away may hide
const robotPos = new THREE.Vector3();
const trails = new Map();    // body index -> {line, points, count}
const frusta = new Map();    // camera -> LineSegments
const lidarClouds = new Map();
let waypointMarker = null;

function resize3() {
  const w = overview.clientWidth, h = overview.clientHeight;
  renderer.setSize(w, h, false);
  renderer.domElement.style.width = '100%';
  renderer.domElement.style.height = '100%';
  camera3.aspect = w / Math.max(h, 1);
  camera3.updateProjectionMatrix();
}
window.addEventListener('resize', resize3);

function geomObject(g, s) {
  const color = new THREE.Color(g.color[0], g.color[1], g.color[2]);
  const material = new THREE.MeshLambertMaterial({ color, transparent: g.color[3] < 1, opacity: g.color[3] });
  const [a, b, c] = g.size;
  let geo = null;
  const obj = new THREE.Group();
  switch (g.shape) {
    case 'plane': geo = new THREE.PlaneBufferGeometry(2 * (a || 10), 2 * (b || 10)); break;
    case 'sphere': geo = new THREE.SphereBufferGeometry(a, 20, 14); break;
    case 'ellipsoid': geo = new THREE.SphereBufferGeometry(1, 20, 14).scale(a, b, c); break;
    case 'box': geo = new THREE.BoxBufferGeometry(2 * a, 2 * b, 2 * c); break;
    case 'cylinder': geo = new THREE.CylinderBufferGeometry(a, a, 2 * b, 20).rotateX(Math.PI / 2); break;
    case 'capsule': {
      geo = new THREE.CylinderBufferGeometry(a, a, 2 * b, 16).rotateX(Math.PI / 2);
      for (const z of [-b, b]) {
        const cap = new THREE.Mesh(new THREE.SphereBufferGeometry(a, 16, 10), material);
        cap.position.z = z;
        obj.add(cap);
      }
      break;
    }
    case 'mesh': {
      const m = s.meshes[g.mesh];
      geo = new THREE.BufferGeometry();
      geo.setAttribute('position', new THREE.Float32BufferAttribute(m.v, 3));
      geo.setIndex(m.f);
      geo.computeVertexNormals();
      break;
    }
    case 'hfield': {
      const hf = s.hfields[g.hfield];
      geo = new THREE.PlaneBufferGeometry(2 * hf.size[0], 2 * hf.size[1], hf.cols - 1, hf.rows - 1);
      const pos = geo.attributes.position;
      for (let i = 0; i < hf.rows; i++)
        for (let j = 0; j < hf.cols; j++)
          pos.setZ(i * hf.cols + j, hf.e[(hf.rows - 1 - i) * hf.cols + j] * hf.size[2]);
      geo.computeVertexNormals();
      break;
    }
    default: return null;
  }
  obj.add(new THREE.Mesh(geo, material));
  obj.position.set(g.pos[0], g.pos[1], g.pos[2]);
  obj.quaternion.set(g.quat[1], g.quat[2], g.quat[3], g.quat[0]);
  return obj;
}

// the robot the scene view orbits: the root body (one of the world's free bodies) of the
// first controlled robot, else the first free body; -1 when the scene has none
function findRobotBody(s) {
  const robots = ((viewer.hello && viewer.hello.model && viewer.hello.model.controllers) || [])
    .map((c) => c.robot).filter((r) => r);
  for (const r of robots) {
    const i = s.bodies.findIndex((b) => b.trail && b.name.startsWith(r + '/'));
    if (i >= 0) return i;
  }
  return s.bodies.findIndex((b) => b.trail && !b.name.startsWith('agents/'));
}

function onScene(s) {
  const first = !viewer.scene;
  viewer.scene = s;
  if (first && s.center) {
    // until the first state places the robot: the whole world from above
    const [cx, cy, cz] = s.center, e = Math.max(1, s.extent || 5);
    orbit.target.set(cx, cy, Math.max(0, cz - 0.3 * e));
    camera3.position.set(cx, cy - 0.3 * e, cz + 1.5 * e);
    orbit.update();
  }
  robotBody = findRobotBody(s);
  viewer.robotBody = robotBody;
  cameraPlaced = false;
  for (const n of bodyNodes) scene3.remove(n);
  bodyNodes = s.bodies.map(() => new THREE.Group());
  for (const n of bodyNodes) scene3.add(n);
  staticObjects = [];
  for (const g of s.geoms) {
    const o = geomObject(g, s);
    if (!o) continue;
    bodyNodes[g.body].add(o);
    // walls, ceilings and furniture may hide the robot: cut away (cutAway)
    if (s.bodies[g.body].static && g.shape !== 'plane' && g.shape !== 'hfield') staticObjects.push(o);
  }
  for (const [, t] of trails) scene3.remove(t.line);
  trails.clear();
  s.bodies.forEach((b, i) => {
    if (!b.trail) return;
    const points = new Float32Array(3 * 4000);
    const geo = new THREE.BufferGeometry();
    geo.setAttribute('position', new THREE.BufferAttribute(points, 3));
    geo.setDrawRange(0, 0);
    const line = new THREE.Line(geo, new THREE.LineBasicMaterial({ color: 0xffb000 }));
    line.frustumCulled = false;
    scene3.add(line);
    trails.set(i, { line, points, count: 0 });
  });
  buildNpcMap(s.npc_map);
  // the poses as the run started (a paused run sends no state before its first step)
  if (s.X_WB && !viewer.state) applyPoses(s.X_WB);
  else if (viewer.state) applyPoses(viewer.state.X_WB);
}

// a crowd's walkable map (scene.npc_map, docs/npcs.md) on its floor: one texel per cell, the
// colours of `penumbra npc-map` (people green, vehicles blue, blocked and too-close cells left
// clear), the lanes as orange lines and the areas' centres as red dots
let npcMapObject = null;
const npcMapColours = { '2': [150, 215, 140, 150], '3': [110, 160, 225, 170] };
function buildNpcMap(m) {
  if (npcMapObject) scene3.remove(npcMapObject);
  npcMapObject = null;
  viewer.npcMap = null;
  if (!m || !m.nx || !m.ny || m.cells.length !== m.nx * m.ny) return;
  const data = new Uint8Array(4 * m.nx * m.ny);
  let drawn = 0;
  for (let i = 0; i < m.cells.length; i++) {
    const c = npcMapColours[m.cells[i]];
    if (!c) continue;
    data.set(c, 4 * i);
    drawn++;
  }
  // row 0 of the texture (v = 0) is the grid's row iy = 0, the plane's south edge
  const texture = new THREE.DataTexture(data, m.nx, m.ny, THREE.RGBAFormat);
  texture.magFilter = THREE.NearestFilter;
  texture.minFilter = THREE.NearestFilter;
  texture.needsUpdate = true;
  // 5 cm above the crowd's floor: above floor slabs (the house's top 3 cm higher) and rugs
  const w = m.nx * m.cell_m, h = m.ny * m.cell_m, z = m.z + 0.05;
  const group = new THREE.Group();
  const plane = new THREE.Mesh(new THREE.PlaneBufferGeometry(w, h),
    new THREE.MeshBasicMaterial({ map: texture, transparent: true, depthWrite: false }));
  plane.position.set(m.min[0] + w / 2, m.min[1] + h / 2, z);
  group.add(plane);
  const laneMaterial = new THREE.LineBasicMaterial({ color: 0xf08c14 });
  for (const lane of m.lanes || []) {
    const pts = [];
    for (const [x, y] of lane.points) pts.push(x, y, z + 0.005);
    const geo = new THREE.BufferGeometry();
    geo.setAttribute('position', new THREE.Float32BufferAttribute(pts, 3));
    group.add(new THREE.Line(geo, laneMaterial));
  }
  const dot = new THREE.MeshBasicMaterial({ color: 0xd21e1e });
  for (const a of m.areas || []) {
    const d = new THREE.Mesh(new THREE.CircleBufferGeometry(0.15, 16), dot);
    d.position.set((a.min[0] + a.max[0]) / 2, (a.min[1] + a.max[1]) / 2, z + 0.005);
    group.add(d);
  }
  group.visible = $('showNpcMap').checked;
  scene3.add(group);
  npcMapObject = group;
  viewer.npcMap = { nx: m.nx, ny: m.ny, cells: drawn, lanes: (m.lanes || []).length };
}
$('showNpcMap').addEventListener('change', () => {
  if (npcMapObject) npcMapObject.visible = $('showNpcMap').checked;
});

function onState(m) {
  viewer.state = m;
  $('simTime').textContent = m.time_sec.toFixed(3);
  $('simStep').textContent = m.step;
  $('stepsPerSec').textContent = Math.round(m.steps_per_sec);
  $('renderFps').textContent = m.render_fps.toFixed(1);
  setBadge('runState', m.ended ? 'ended' : m.paused ? 'paused' : 'running', m.paused ? 'off' : 'on');
  applyPoses(m.X_WB);
  for (const [, t] of trails) t.line.visible = $('showTrails').checked;
  if (m.signals) pushSignals(m.time_sec, m.signals);
}

// the bodies' poses (7 per body: x y z qw qx qy qz) onto the overview, its trails and camera
function applyPoses(X) {
  if (X && bodyNodes.length * 7 === X.length) {
    bodyNodes.forEach((n, i) => {
      n.position.set(X[7 * i], X[7 * i + 1], X[7 * i + 2]);
      n.quaternion.set(X[7 * i + 4], X[7 * i + 5], X[7 * i + 6], X[7 * i + 3]);
    });
    followRobot(X);
    for (const [i, t] of trails) {
      const k = t.count % 4000;
      const last = t.count ? (t.count - 1) % 4000 : -1;
      const p = [X[7 * i], X[7 * i + 1], X[7 * i + 2]];
      if (last >= 0 && Math.hypot(p[0] - t.points[3 * last], p[1] - t.points[3 * last + 1]) < 0.02) continue;
      if (t.count >= 4000) { t.points.copyWithin(0, 3); t.count = 3999; }
      t.points.set(p, 3 * Math.min(t.count, 3999));
      t.count++;
      t.line.geometry.setDrawRange(0, t.count);
      t.line.geometry.attributes.position.needsUpdate = true;
    }
  }
}

// the orbit camera's target is the robot: placed behind and above it at the first state,
// then it follows the robot's motion (the user's rotation and zoom are kept)
function followRobot(X) {
  if (robotBody < 0) return;
  const p = new THREE.Vector3(X[7 * robotBody], X[7 * robotBody + 1], X[7 * robotBody + 2]);
  if (!cameraPlaced) {
    const q = new THREE.Quaternion(X[7 * robotBody + 4], X[7 * robotBody + 5], X[7 * robotBody + 6], X[7 * robotBody + 3]);
    const back = new THREE.Vector3(1, 0, 0).applyQuaternion(q).setZ(0);
    if (back.lengthSq() < 1e-6) back.set(1, 0, 0);
    back.normalize().multiplyScalar(-1.6);
    orbit.target.copy(p);
    camera3.position.set(p.x + back.x, p.y + back.y, p.z + 1.4);
    cameraPlaced = true;
  } else if ($('followRobot').checked) {
    const d = p.clone().sub(robotPos);
    orbit.target.add(d);
    camera3.position.add(d);
  }
  robotPos.copy(p);
  orbit.update();
}

// static geometry between the camera and the robot is hidden (walls, ceiling cut away): rays
// from the camera to the robot's origin and to points 0.25 m around it
const cutRay = new THREE.Raycaster();
function cutAway() {
  for (const o of staticObjects) o.visible = true;
  if (robotBody < 0 || !cameraPlaced || !$('cutAway').checked) return;
  const hidden = new Set();
  for (const [dx, dy, dz] of [[0, 0, 0], [0.25, 0, 0], [-0.25, 0, 0], [0, 0.25, 0], [0, -0.25, 0], [0, 0, 0.2]]) {
    const to = robotPos.clone().add(new THREE.Vector3(dx, dy, dz));
    const dir = to.clone().sub(camera3.position);
    const far = dir.length();
    cutRay.set(camera3.position, dir.normalize());
    cutRay.far = far;
    for (const hit of cutRay.intersectObjects(staticObjects, true)) {
      let o = hit.object;
      while (o && !staticObjects.includes(o)) o = o.parent;
      if (o) hidden.add(o);
    }
  }
  for (const o of hidden) o.visible = false;
  viewer.cutAway = hidden.size;
}

// a change of the run's state at a step boundary (pause, resume, step, reset, end)
function onStatus(m) {
  viewer.status = m;
  if (m.adversity) renderAdversity(m.adversity);
  if (m.time_sec !== undefined) $('simTime').textContent = m.time_sec.toFixed(3);
  if (m.step !== undefined) $('simStep').textContent = m.step;
  if (m.realtime_factor !== undefined && document.activeElement !== $('rtf')) $('rtf').value = m.realtime_factor;
  if (m.ended) setBadge('runState', 'ended', 'off');
  else if (m.paused !== undefined) setBadge('runState', m.paused ? 'paused' : 'running', m.paused ? 'off' : 'on');
}

function updateFrustum(h) {
  if (!h.X_WO) return;
  let f = frusta.get(h.camera);
  if (!f) {
    const d = 0.35;
    const corners = [[0, 0], [h.width, 0], [h.width, h.height], [0, h.height]].map(([u, v]) =>
      [(u - h.cx) / h.fx * d, (v - h.cy) / h.fy * d, d]);
    const pts = [];
    for (const c of corners) pts.push(0, 0, 0, ...c);
    for (let i = 0; i < 4; i++) pts.push(...corners[i], ...corners[(i + 1) % 4]);
    const geo = new THREE.BufferGeometry();
    geo.setAttribute('position', new THREE.Float32BufferAttribute(pts, 3));
    f = new THREE.LineSegments(geo, new THREE.LineBasicMaterial({ color: 0x4fc3f7 }));
    scene3.add(f);
    frusta.set(h.camera, f);
  }
  const X = h.X_WO;
  f.position.set(X[0], X[1], X[2]);
  f.quaternion.set(X[4], X[5], X[6], X[3]);
  f.visible = $('showFrusta').checked;
}

function onLidar(m) {
  let c = lidarClouds.get(m.sensor);
  if (!c) {
    const geo = new THREE.BufferGeometry();
    c = new THREE.Points(geo, new THREE.PointsMaterial({ color: 0x7cfc00, size: 0.03 }));
    c.frustumCulled = false;
    scene3.add(c);
    lidarClouds.set(m.sensor, c);
  }
  c.geometry.setAttribute('position', new THREE.Float32BufferAttribute(m.points, 3));
  c.visible = $('showLidar').checked;
}

// click on the floor (z = 0) sets a waypoint goal for the robot
renderer.domElement.addEventListener('click', (ev) => {
  if (!$('waypointMode').checked) return;
  const r = renderer.domElement.getBoundingClientRect();
  const ndc = new THREE.Vector2(((ev.clientX - r.left) / r.width) * 2 - 1, -((ev.clientY - r.top) / r.height) * 2 + 1);
  const ray = new THREE.Raycaster();
  ray.setFromCamera(ndc, camera3);
  const hit = new THREE.Vector3();
  if (!ray.ray.intersectPlane(new THREE.Plane(new THREE.Vector3(0, 0, 1), 0), hit)) return;
  const robot = (viewer.hello.waypoint_robots || [])[0];
  if (!robot) return log('no robot takes waypoints');
  send('waypoints', { robot, points: [[hit.x, hit.y]] }).then(() => {
    if (!waypointMarker) {
      waypointMarker = new THREE.Mesh(new THREE.ConeBufferGeometry(0.08, 0.3, 12).rotateX(-Math.PI / 2),
        new THREE.MeshLambertMaterial({ color: 0xff4081 }));
      scene3.add(waypointMarker);
    }
    waypointMarker.position.set(hit.x, hit.y, 0.15);
  }).catch((e) => log(e.message));
});

function animate() {
  requestAnimationFrame(animate);
  if (overview.clientWidth !== renderer.domElement.width / window.devicePixelRatio) resize3();
  cutAway();
  renderer.render(scene3, camera3);
  viewer.view3 = { target: orbit.target.toArray(), camera: camera3.position.toArray() };
}

// ---------- plots ----------
const plots = [];
const history = new Map();  // signal -> [[t, v], ...]

function pushSignals(t, signals) {
  for (const [k, v] of Object.entries(signals)) {
    if (!history.has(k)) {
      history.set(k, []);
      $('plotSignal').add(new Option(k, k));
    }
    const h = history.get(k);
    if (h.length && t < h[h.length - 1][0]) h.length = 0;  // reset or a new run
    h.push([t, v]);
    while (h.length && h[0][0] < t - 10) h.shift();
  }
  if (plots.length === 0) {
    const keys = Object.keys(signals);
    // the first robot's contact force (its weight when it stands), else an IMU, else all contacts
    const first = keys.find((k) => /^contacts\/.+\/normal_force_N$/.test(k)) ||
      keys.find((k) => k.startsWith('imu/')) || keys.find((k) => k.startsWith('contacts/normal'));
    if (first) addPlot(first);
  }
}

function addPlot(signal) {
  const el = document.createElement('div');
  el.className = 'plot';
  el.innerHTML = `<div class="bar"><span class="name"></span><span class="value dim"></span><button>x</button></div><canvas width="600" height="110"></canvas>`;
  el.querySelector('.name').textContent = signal;
  $('plotList').append(el);
  const p = { signal, el, canvas: el.querySelector('canvas'), value: el.querySelector('.value') };
  el.querySelector('button').addEventListener('click', () => { plots.splice(plots.indexOf(p), 1); el.remove(); });
  plots.push(p);
}

function drawPlots() {
  for (const p of plots) {
    const h = history.get(p.signal) || [];
    const ctx = p.canvas.getContext('2d');
    const W = p.canvas.width, H = p.canvas.height;
    ctx.clearRect(0, 0, W, H);
    if (h.length < 2) continue;
    let lo = Infinity, hi = -Infinity;
    for (const [, v] of h) { lo = Math.min(lo, v); hi = Math.max(hi, v); }
    if (hi - lo < 1e-9) { hi += 0.5; lo -= 0.5; }
    const t1 = h[h.length - 1][0], t0 = t1 - 10;
    ctx.strokeStyle = '#333a42';
    ctx.beginPath(); ctx.moveTo(0, H / 2); ctx.lineTo(W, H / 2); ctx.stroke();
    ctx.strokeStyle = '#4fc3f7';
    ctx.beginPath();
    h.forEach(([t, v], i) => {
      const x = ((t - t0) / 10) * W, y = H - 4 - ((v - lo) / (hi - lo)) * (H - 8);
      if (i) ctx.lineTo(x, y); else ctx.moveTo(x, y);
    });
    ctx.stroke();
    ctx.fillStyle = '#8a95a1';
    ctx.fillText(hi.toPrecision(4), 2, 10);
    ctx.fillText(lo.toPrecision(4), 2, H - 2);
    p.value.textContent = h[h.length - 1][1].toPrecision(4);
  }
}
setInterval(drawPlots, 100);

// ---------- teleop ----------
const held = new Set();
let teleopTimer = null;
let teleopActive = false;

function twistFromKeys() {
  const v = Number($('teleopSpeed').value);
  const vx = (held.has('w') ? v : 0) - (held.has('s') ? v : 0);
  const vy = (held.has('q') ? v : 0) - (held.has('e') ? v : 0);
  const yaw = (held.has('a') ? 1 : 0) - (held.has('d') ? 1 : 0);
  return { vx, vy, yaw_rate: yaw * Math.min(1.5, 2 * v) };
}

function sendTwist() {
  const robot = (viewer.hello && viewer.hello.teleop_robots || [])[0];
  if (!robot) return;
  const t = twistFromKeys();
  if (!viewer.hello.teleop_vy) t.vy = 0;
  viewer.lastTwistSentMs = performance.now();
  send('twist', { robot, ...t }).catch((e) => log(e.message));
}

function keyChanged() {
  teleopActive = true;
  sendTwist();
  if (held.size && !teleopTimer) teleopTimer = setInterval(sendTwist, 200);
  if (!held.size && teleopTimer) { clearInterval(teleopTimer); teleopTimer = null; }
}

const teleopKeys = new Set(['w', 'a', 's', 'd', 'q', 'e']);
window.addEventListener('keydown', (ev) => {
  if (ev.target.tagName === 'INPUT' && ev.target.type === 'text') return;
  const k = ev.key.toLowerCase();
  if (!teleopKeys.has(k) || held.has(k)) return;
  held.add(k);
  keyChanged();
});
window.addEventListener('keyup', (ev) => {
  const k = ev.key.toLowerCase();
  if (!held.delete(k)) return;
  keyChanged();
});
for (const b of document.querySelectorAll('#teleop .pad button')) {
  const k = b.dataset.key;
  b.addEventListener('pointerdown', () => { held.add(k); b.classList.add('active'); keyChanged(); });
  for (const e of ['pointerup', 'pointerleave'])
    b.addEventListener(e, () => { if (held.delete(k)) { b.classList.remove('active'); keyChanged(); } });
}
$('teleopSpeed').addEventListener('input', () => { $('teleopSpeedValue').textContent = $('teleopSpeed').value; });
$('twistClear').addEventListener('click', () => {
  const robot = (viewer.hello.teleop_robots || [])[0];
  if (robot) send('twist', { robot, clear: true }).catch((e) => log(e.message));
});

// ---------- simulation controls ----------
$('play').addEventListener('click', () => send('resume').catch((e) => log(e.message)));
$('pause').addEventListener('click', () => send('pause').catch((e) => log(e.message)));
$('step').addEventListener('click', () => {
  const h = viewer.hello;
  const n = Math.max(1, Math.round(h.control_period_sec / h.timestep_sec));
  send('step', { n }).catch((e) => log(e.message));
});
$('reset').addEventListener('click', () => {
  for (const [, t] of trails) { t.count = 0; t.line.geometry.setDrawRange(0, 0); }
  send('reset').catch((e) => log(e.message));
});
$('rtf').addEventListener('change', () => send('set_realtime_factor', { factor: Number($('rtf').value) }).catch((e) => log(e.message)));
$('preset').addEventListener('change', () => send('set_adversity', { preset: $('preset').value }).catch((e) => {
  log(e.message);
  renderAdversity(viewer.adversity);   // refused: back to the run's preset
}));
$('addView').addEventListener('click', () => addCameraPanel());
$('addPlot').addEventListener('click', () => addPlot($('plotSignal').value));
let recording = false;
// viewer.plog -> viewer-2.plog -> viewer-3.plog ...
function nextRecordName(name) {
  const m = /^(.*?)(?:-(\d+))?\.plog$/.exec(name);
  return m ? `${m[1]}-${m[2] ? Number(m[2]) + 1 : 2}.plog` : name;
}
$('record').addEventListener('click', () => {
  const cmd = recording ? 'stop_recording' : 'start_recording';
  const fields = recording ? {} : { path: $('recordPath').value };
  send(cmd, fields).then((r) => {
    recording = !recording;
    $('record').classList.toggle('active', recording);
    $('record').textContent = recording ? '\u25A0 stop' : '\u25CF record';
    $('recordState').textContent = recording ? `recording to ${fields.path}` : `wrote ${r.path} (${r.bytes} bytes, ${r.steps} steps) in the run's output folder`;
    // a recording never overwrites a file: offer the next free-looking name
    if (!recording) $('recordPath').value = nextRecordName($('recordPath').value);
  }).catch((e) => { $('recordState').textContent = e.message; log(e.message); });
});

setInterval(() => { $('streamFps').textContent = streamFrames; streamFrames = 0; }, 1000);
resize3();
animate();
connect();
