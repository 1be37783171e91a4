// daylit's browser viewer (docs/serve.md). The scene's own coordinates are three.js's world
// (metres, +Z up), so the stream's sun direction and SH coefficients are used as they come.
// Radiance units become the camera's linear pixel values through the frame's exposure k, and
// three.js encodes them with sRGB, the response of the bundled recordings.
import * as THREE from 'three';
import { shIrradiance } from '/viewer/sh.mjs';

const status = document.getElementById('status');
const view = document.getElementById('view');
const background = document.getElementById('background');

// What a test reads: the last frame drawn and its message.
window.daylit = { renderedFrame: -1, message: null, scene: null };

// OpenCV intrinsics → an OpenGL projection (pixel centres at integer coordinates, as OpenCV's).
function projectionFromIntrinsics(c, near, far) {
  const m = new THREE.Matrix4();
  m.set(2 * c.fx / c.width, 0, 1 - 2 * (c.cx + 0.5) / c.width, 0,
        0, 2 * c.fy / c.height, 2 * (c.cy + 0.5) / c.height - 1, 0,
        0, 0, -(far + near) / (far - near), -2 * far * near / (far - near),
        0, 0, -1, 0);
  return m;
}

// world_to_camera (OpenCV: x right, y down, z forward) → the camera's world matrix (OpenGL: y up,
// looking along −z).
function cameraMatrix(c) {
  const r = c.world_to_camera.rotation, t = c.world_to_camera.translation;
  const view = new THREE.Matrix4();
  view.set(r[0][0], r[0][1], r[0][2], t[0],
           -r[1][0], -r[1][1], -r[1][2], -t[1],
           -r[2][0], -r[2][1], -r[2][2], -t[2],
           0, 0, 0, 1);
  return view.invert();
}

function objectMesh(o) {
  let geometry;
  if (o.mesh === 'sphere') geometry = new THREE.SphereGeometry(o.radius, 96, 48);
  else if (o.mesh === 'box') geometry = new THREE.BoxGeometry(o.size[0], o.size[1], o.size[2]);
  else return null;  // mesh files are not drawn by the viewer yet (docs/serve.md)
  const material = new THREE.MeshLambertMaterial();
  material.color.setRGB(o.albedo[0], o.albedo[1], o.albedo[2], THREE.LinearSRGBColorSpace);
  const mesh = new THREE.Mesh(geometry, material);
  mesh.position.set(...o.position);
  // scene.json: R = Rz·Ry·Rx, which three.js calls the order 'ZYX'.
  const d = Math.PI / 180;
  mesh.rotation.set(o.rotation_deg[0] * d, o.rotation_deg[1] * d, o.rotation_deg[2] * d, 'ZYX');
  mesh.scale.set(...o.scale);
  mesh.castShadow = true;
  mesh.receiveShadow = true;
  return mesh;
}

async function main() {
  const scene = await (await fetch('/scene')).json();
  window.daylit.scene = scene;
  const cam = scene.camera;
  view.style.width = `${cam.width}px`;
  view.style.height = `${cam.height}px`;
  background.width = cam.width;
  background.height = cam.height;
  background.src = '/video.mjpg';

  const renderer = new THREE.WebGLRenderer({ alpha: true, antialias: true, preserveDrawingBuffer: true });
  renderer.setPixelRatio(window.devicePixelRatio);
  renderer.setSize(cam.width, cam.height);
  renderer.setClearColor(0x000000, 0);
  renderer.shadowMap.enabled = true;
  renderer.shadowMap.type = THREE.PCFSoftShadowMap;
  view.appendChild(renderer.domElement);

  const world = new THREE.Scene();
  const camera = new THREE.Camera();
  camera.matrixAutoUpdate = false;
  camera.matrix.copy(cameraMatrix(cam));
  camera.matrixWorldNeedsUpdate = true;
  camera.projectionMatrix.copy(projectionFromIntrinsics(cam, 0.05, 500));
  camera.projectionMatrixInverse.copy(camera.projectionMatrix).invert();

  const objects = new THREE.Group();
  for (const o of scene.objects) {
    const mesh = objectMesh(o);
    if (mesh) objects.add(mesh);
  }
  world.add(objects);
  const bounds = new THREE.Box3().setFromObject(objects);
  const centre = bounds.isEmpty() ? new THREE.Vector3() : bounds.getCenter(new THREE.Vector3());
  const reach = bounds.isEmpty() ? 5 : bounds.getSize(new THREE.Vector3()).length() + 4;

  // The shadow catcher: the ground (z = 0) shows only the objects' shadows, darkening the frame.
  const catcherMaterial = new THREE.ShadowMaterial({ opacity: 0 });
  const catcher = new THREE.Mesh(new THREE.PlaneGeometry(4 * reach, 4 * reach), catcherMaterial);
  catcher.position.set(centre.x, centre.y, 0);
  catcher.receiveShadow = true;
  world.add(catcher);

  const sun = new THREE.DirectionalLight(0xffffff, 1);
  sun.castShadow = true;
  sun.shadow.mapSize.set(2048, 2048);
  Object.assign(sun.shadow.camera, { left: -reach, right: reach, top: reach, bottom: -reach, near: 0.1, far: 4 * reach });
  sun.shadow.camera.updateProjectionMatrix();
  sun.shadow.bias = -0.0005;
  sun.shadow.normalBias = 0.01;
  sun.target.position.copy(centre);
  world.add(sun, sun.target);
  const probe = new THREE.LightProbe();
  world.add(probe);

  let pending = null;
  function apply(m) {
    const k = m.exposure;
    const s = m.primaryLightDirection, e = m.primaryLightIntensity;
    const lit = m.sunUp && m.hasEstimate;
    sun.position.set(centre.x + 2 * reach * s.x, centre.y + 2 * reach * s.y, centre.z + 2 * reach * s.z);
    sun.color.setRGB(lit ? k * e.x : 0, lit ? k * e.y : 0, lit ? k * e.z : 0, THREE.LinearSRGBColorSpace);
    const c = m.sphericalHarmonicsCoefficients;
    if (c) {
      for (let i = 0; i < 9; ++i) probe.sh.coefficients[i].set(k * c[3 * i], k * c[3 * i + 1], k * c[3 * i + 2]);
      // The catcher keeps the sky's share of the ground's light where the sun is blocked (luminance),
      // as a factor on the sRGB-encoded frame (≈ the linear factor to the 1/2.2).
      const sky = shIrradiance(c, [0, 0, 1]);
      const luma = (v) => 0.2126 * v[0] + 0.7152 * v[1] + 0.0722 * v[2];
      const direct = lit ? Math.max(s.z, 0) * luma([e.x, e.y, e.z]) : 0;
      const kept = luma(sky) / Math.max(luma(sky) + direct, 1e-9);
      catcherMaterial.opacity = 1 - Math.pow(Math.min(Math.max(kept, 0), 1), 1 / 2.2);
    }
    status.textContent = `frame ${m.frame}  ${m.time_utc}  sun ${m.sunElevationDeg.toFixed(1)}° up  ` +
      `E_sun ${e.x.toFixed(1)} ${e.y.toFixed(1)} ${e.z.toFixed(1)}  confidence ${m.confidence.toFixed(2)}`;
  }
  function draw() {
    if (pending) {
      apply(pending);
      renderer.render(world, camera);
      window.daylit.message = pending;
      window.daylit.renderedFrame = pending.frame;
      pending = null;
    }
    requestAnimationFrame(draw);
  }
  requestAnimationFrame(draw);

  const stream = new EventSource('/stream');
  stream.onmessage = (event) => { pending = JSON.parse(event.data); };
  stream.addEventListener('dropped', () => {});  // only the newest matters here
  stream.onerror = () => { status.textContent = 'daylit is not serving (the run ended?)'; };
}

main().catch((error) => { status.textContent = `viewer: ${error}`; });
