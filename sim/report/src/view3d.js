// report.html's 3D view (View3dHtml): three.js loaded from the page's own text blocks, the map's
// cells by class, the truth's surfaces and the sonar's path from #view3d-data, world frame, z up.
// Once drawn it sets window.sonarbenchView = {drawn: true, classes: [{name, colour, count,
// drawn}]}, which the browser test reads; a failure is written on the page and thrown.
const root = document.getElementById('view3d');
const status = root.nextElementSibling;
const text = (id) => document.getElementById(id).textContent;
const moduleUrl = (source) => URL.createObjectURL(new Blob([source], {type: 'text/javascript'}));
const bytes = (base64) => Uint8Array.from(atob(base64), (c) => c.charCodeAt(0)).buffer;

// A unit cube whose faces are shaded by their normal (the top in the class's own colour, the
// sides darker), so that flat colours still show the cells' shape without lights.
function shadedCube(THREE) {
  const cube = new THREE.BoxGeometry(1, 1, 1);
  const normal = cube.getAttribute('normal');
  const shade = new Float32Array(normal.count * 3);
  for (let i = 0; i < normal.count; ++i) {
    const z = normal.getZ(i);
    const s = z > 0.5 ? 1.0 : z < -0.5 ? 0.35 : Math.abs(normal.getX(i)) > 0.5 ? 0.7 : 0.55;
    shade.fill(s, 3 * i, 3 * i + 3);
  }
  cube.setAttribute('color', new THREE.BufferAttribute(shade, 3));
  return cube;
}

// One instanced mesh of cubes per class; `bounds` grows by their centres.
function cellEntries(THREE, data, bounds) {
  const cube = shadedCube(THREE);
  const [ox, oy, oz] = data.origin_m;
  const r = data.resolution_m;
  const matrix = new THREE.Matrix4();
  const centre = new THREE.Vector3();
  return data.classes.map((c) => {
    const keys = new Uint16Array(bytes(c.cells));
    const n = keys.length / 3;
    const material = new THREE.MeshBasicMaterial({color: c.colour, vertexColors: true});
    const mesh = new THREE.InstancedMesh(cube, material, Math.max(n, 1));
    mesh.count = n;
    mesh.frustumCulled = false;
    const edge = c.size * r;
    for (let i = 0; i < n; ++i) {
      centre.set(ox + keys[3 * i] * r, oy + keys[3 * i + 1] * r, oz + keys[3 * i + 2] * r);
      mesh.setMatrixAt(i, matrix.makeScale(edge, edge, edge).setPosition(centre));
      bounds.expandByPoint(centre);
    }
    mesh.instanceMatrix.needsUpdate = true;
    const shown = c.drawn < c.count ? `${c.drawn} of ${c.count} drawn` : `${c.count}`;
    return {name: `${c.name} (${shown})`, colour: c.colour, object: mesh};
  });
}

// The truth's meshes, translucent, with their edges; `bounds` grows by them.
function surfaceEntry(THREE, data, bounds) {
  const group = new THREE.Group();
  const grey = 0xb4b4b4;
  for (const s of data.surfaces) {
    const geometry = new THREE.BufferGeometry();
    geometry.setAttribute('position',
                          new THREE.BufferAttribute(new Float32Array(bytes(s.positions)), 3));
    geometry.setIndex(new THREE.BufferAttribute(new Uint32Array(bytes(s.triangles)), 1));
    geometry.computeBoundingBox();
    bounds.union(geometry.boundingBox);
    group.add(new THREE.Mesh(geometry, new THREE.MeshBasicMaterial({
      color: grey, transparent: true, opacity: 0.12, side: THREE.DoubleSide, depthWrite: false})));
    group.add(new THREE.LineSegments(new THREE.EdgesGeometry(geometry, 20),
                                     new THREE.LineBasicMaterial({color: grey})));
  }
  const omitted = data.surfaces_omitted.length ?
      `; too many triangles to draw: ${data.surfaces_omitted.join(', ')}` : '';
  return {name: `surfaces of the truth${omitted}`, colour: '#b4b4b4', object: group};
}

// The sonar's path as a line and a sphere where it starts.
function pathEntry(THREE, data) {
  const group = new THREE.Group();
  const p = new Float32Array(bytes(data.sonar_path));
  const yellow = 0xffdc00;
  if (p.length >= 3) {
    const line = new THREE.BufferGeometry();
    line.setAttribute('position', new THREE.BufferAttribute(p, 3));
    group.add(new THREE.Line(line, new THREE.LineBasicMaterial({color: yellow})));
    const start = new THREE.Mesh(new THREE.SphereGeometry(2 * data.resolution_m, 16, 8),
                                 new THREE.MeshBasicMaterial({color: yellow}));
    start.position.set(p[0], p[1], p[2]);
    group.add(start);
  }
  return {name: 'sonar path', colour: '#ffdc00', object: group};
}

// A grid of 1 m squares under everything.
function gridEntry(THREE, bounds) {
  const size = bounds.getSize(new THREE.Vector3());
  const n = Math.max(2, Math.ceil(Math.max(size.x, size.y)) + 2);
  const grid = new THREE.GridHelper(n, n, 0x808080, 0x484848);
  grid.rotation.x = Math.PI / 2;
  const c = bounds.getCenter(new THREE.Vector3());
  grid.position.set(Math.round(c.x), Math.round(c.y), bounds.min.z);
  return {name: 'grid, 1 m squares', colour: '#808080', object: grid};
}

function legend(entries, render) {
  const box = root.querySelector('.view3d-legend');
  for (const entry of entries) {
    const label = document.createElement('label');
    const toggle = document.createElement('input');
    toggle.type = 'checkbox';
    toggle.checked = true;
    toggle.addEventListener('change', () => {
      entry.object.visible = toggle.checked;
      render();
    });
    const swatch = document.createElement('span');
    swatch.className = 'swatch';
    swatch.style.background = entry.colour;
    label.append(toggle, swatch, entry.name);
    box.append(label);
  }
}

function draw(THREE, OrbitControls, data) {
  const canvas = root.querySelector('canvas');
  const renderer = new THREE.WebGLRenderer({canvas, antialias: true});
  renderer.setPixelRatio(window.devicePixelRatio);
  const scene = new THREE.Scene();
  scene.background = new THREE.Color(0x1e1e1e);
  const cellBounds = new THREE.Box3();
  const surfaceBounds = new THREE.Box3();
  const entries = cellEntries(THREE, data, cellBounds);
  if (data.surfaces.length) entries.push(surfaceEntry(THREE, data, surfaceBounds));
  entries.push(pathEntry(THREE, data));
  // Framed on the map's cells, or on the surfaces when the map has none.
  const bounds = !cellBounds.isEmpty() ? cellBounds : !surfaceBounds.isEmpty() ? surfaceBounds :
      new THREE.Box3(new THREE.Vector3(-1, -1, -1), new THREE.Vector3(1, 1, 1));
  entries.push(gridEntry(THREE, bounds));
  for (const entry of entries) scene.add(entry.object);

  const centre = bounds.getCenter(new THREE.Vector3());
  const radius = Math.max(bounds.getSize(new THREE.Vector3()).length() / 2, 0.5);
  const camera = new THREE.PerspectiveCamera(40, 1, radius / 100, radius * 100);
  camera.up.set(0, 0, 1);
  const from = new THREE.Vector3(0.9, -1.6, 1.9).normalize().multiplyScalar(2.6 * radius);
  camera.position.copy(centre).add(from);
  const controls = new OrbitControls(camera, canvas);
  controls.target.copy(centre);
  controls.update();
  const render = () => renderer.render(scene, camera);
  controls.addEventListener('change', render);
  const resize = () => {
    renderer.setSize(canvas.clientWidth, canvas.clientHeight, false);
    camera.aspect = canvas.clientWidth / Math.max(canvas.clientHeight, 1);
    camera.updateProjectionMatrix();
    render();
  };
  new ResizeObserver(resize).observe(canvas);
  resize();
  legend(entries, render);
  window.sonarbenchView = {
    drawn: true,
    classes: data.classes.map(({name, colour, count, drawn}) => ({name, colour, count, drawn})),
  };
}

try {
  const core = moduleUrl(text('three-core'));
  const three = moduleUrl(text('three-module').replaceAll('./three.core.min.js', core));
  const THREE = await import(three);
  const controls = text('three-orbit-controls').replace(/from\s*['"]three['"]/g, `from '${three}'`);
  const {OrbitControls} = await import(moduleUrl(controls));
  draw(THREE, OrbitControls, JSON.parse(text('view3d-data')));
  status.textContent = '';
} catch (error) {
  status.textContent = `The 3D view could not start: ${error.message}`;
  throw error;
}
