// The two 3D views drawn with three.js: one camera (one orbit state, one THREE camera) renders
// both views, so they cannot drift apart nor re-trigger each other. One WebGL canvas, laid over
// both panels, draws them in two scissored viewports: the browser's compositor reads a WebGL
// canvas back once per frame, and with two canvases those reads were most of a frame's cost.
// A frame update rewrites vertex buffers and asks for one render on the next animation frame;
// nothing queues.
import * as THREE from "/static/vendor/three/three.module.min.js";
import * as geo from "./geometry.js";
import { canvasLayout, sameLayout } from "./viewports.js";
import { dragged, drawnSkeleton, hoverLabel, writePoints, writeSegments, writeTriads, zoomed } from "./scene-data.js";
import { floorControls, floorMesh } from "./scene-floor.js";

const BODY = new THREE.Color("#5b84b1");
const MARKED = new THREE.Color("#f39c12");
const JOINT = new THREE.Color("#1f4e79");
const SELECTED = new THREE.Color("#f1c40f");
const BRIDGED = new THREE.Color("#8e44ad"); // a keypoint the filter bridged (no valid input)
const FILLED = new THREE.Color("#16a085"); // a marker sample written by a gap fill
const AXES = ["#d62728", "#2ca02c", "#1f77b4"].map((c) => new THREE.Color(c));

const LIGHT_AMBIENT = 1.6, LIGHT_DIRECT = 1.6; // intensities of a white ambient and directional light
const LIGHT = [1, 2, 3].map((v) => v / Math.hypot(1, 2, 3)); // toward the directional light
const FOV = 35; // the camera's vertical field of view, degrees

function viewScene(bonesCount, nPoints, nJoints, oriented) {
  const scene = new THREE.Scene();
  scene.background = new THREE.Color("#ffffff");
  const soup = new THREE.BufferGeometry();
  soup.setAttribute("position", new THREE.BufferAttribute(new Float32Array(bonesCount * 24 * 3), 3));
  soup.setAttribute("color", new THREE.BufferAttribute(new Float32Array(bonesCount * 24 * 3), 3));
  const bones = oriented
    ? new THREE.Mesh(soup, new THREE.MeshBasicMaterial({ vertexColors: true, side: THREE.DoubleSide })) // lit in shadeSoup
    : new THREE.LineSegments(lineGeometry(bonesCount * 2), new THREE.LineBasicMaterial({ color: BODY }));
  const jointsGeometry = new THREE.BufferGeometry();
  jointsGeometry.setAttribute("position", new THREE.BufferAttribute(new Float32Array(nPoints * 3), 3));
  jointsGeometry.setAttribute("color", new THREE.BufferAttribute(new Float32Array(nPoints * 3), 3));
  const joints = new THREE.Points(jointsGeometry, new THREE.PointsMaterial({ size: oriented ? 4 : 7, sizeAttenuation: false, vertexColors: true }));
  const axes = new THREE.LineSegments(lineGeometry(nJoints * 6, true), new THREE.LineBasicMaterial({ vertexColors: true }));
  axes.visible = false;
  const ghost = new THREE.LineSegments(lineGeometry(bonesCount * 2), new THREE.LineBasicMaterial({ color: 0x7f8c8d, transparent: true, opacity: 0.45 }));
  ghost.visible = false;
  // Filled samples (marker takes): a hollow ring drawn around the point.
  const rings = new THREE.Points(lineGeometry(nPoints), new THREE.PointsMaterial({ size: 15, sizeAttenuation: false, map: ringTexture(), transparent: true, alphaTest: 0.5, color: FILLED }));
  rings.visible = false;
  for (const o of [bones, joints, axes, ghost, rings]) { o.frustumCulled = false; scene.add(o); }
  return { scene, bones, joints, axes, ghost, rings };
}

let ring = null;
/** A ring on a transparent square: the point sprite of a filled sample. */
function ringTexture() {
  if (ring) return ring;
  const canvas = document.createElement("canvas");
  canvas.width = canvas.height = 32;
  const g = canvas.getContext("2d");
  g.strokeStyle = "#ffffff";
  g.lineWidth = 6;
  g.beginPath();
  g.arc(16, 16, 12, 0, 2 * Math.PI);
  g.stroke();
  ring = new THREE.CanvasTexture(canvas);
  return ring;
}

function lineGeometry(vertices, colored = false) {
  const g = new THREE.BufferGeometry();
  g.setAttribute("position", new THREE.BufferAttribute(new Float32Array(vertices * 3), 3));
  if (colored) g.setAttribute("color", new THREE.BufferAttribute(new Float32Array(vertices * 3), 3));
  return g;
}

function writeLines(attribute, points, pairs) {
  writeSegments(attribute.array, points, pairs);
  attribute.needsUpdate = true;
}

/** The one WebGL canvas, absolutely placed in `row` (the element that holds both panels) over
 * the union of the shown views; it takes no pointer events (each view's own element does) and is
 * transparent between the views, where the panels' borders and gap show through. */
function sharedCanvas(row) {
  const canvas = document.createElement("canvas");
  canvas.className = "view-canvas";
  canvas.setAttribute("aria-hidden", "true");
  row.append(canvas);
  // No multisampling: on a CPU rasteriser (SwiftShader, headless) it cost 40 % of the frame
  // rate (15.6 → 25.7 frames/s in playback); the pixel ratio still smooths HiDPI screens.
  // A transparent canvas: between the views, the panels' borders and the page show through (an
  // opaque one, which would have to paint them, measured no faster).
  const renderer = new THREE.WebGLRenderer({ canvas, antialias: false, alpha: true });
  renderer.setPixelRatio(Math.min(2, window.devicePixelRatio || 1));
  // No depth sorting of objects: it needs bounding spheres, which a missing keypoint (NaN, not
  // drawn) would spoil; opaque parts go before the transparent ghost all the same.
  renderer.sortObjects = false;
  return { canvas, renderer };
}

/** Each view's scene (viewScene) with the floor's grid, for an oriented take the root's path on
 * the floor, and the feet step's floor plane (hidden until setFloor). */
function buildViews(divs, v, overview) {
  const views = {};
  for (const [name, div] of Object.entries(divs)) {
    div.setAttribute("role", "img");
    div.setAttribute("aria-label", `${name} skeleton, drag to orbit, wheel to zoom`);
    const parts = viewScene(v.bones.length, v.names.length, v.nJoints, v.oriented);
    const grid = new THREE.GridHelper(v.size * 3, 12, 0xc0c7cf, 0xe3e7ec);
    grid.position.y = v.floorY;
    parts.scene.add(grid);
    if (v.oriented) {
      const path = overview.raw.map((points) => points[v.drawnRoot]).filter(geo.present);
      const line = new THREE.Line(new THREE.BufferGeometry().setFromPoints(path.map((p) => new THREE.Vector3(p[0], v.floorY + v.size * 0.002, p[2]))),
        new THREE.LineBasicMaterial({ color: 0x95a5a6 }));
      parts.scene.add(line);
    }
    views[name] = { div, ...parts, floor: floorMesh(parts.scene) };
  }
  return views;
}

/** The shown views' rectangles (inside their borders, from the row's padding edge, where the
 * absolutely placed canvas is measured from) → the canvas box and the viewports. */
function place(v) {
  const r0 = v.row.getBoundingClientRect();
  const originLeft = r0.left + v.row.clientLeft, originTop = r0.top + v.row.clientTop;
  const shown = Object.values(v.views).map((view) => {
    if (view.div.offsetParent === null) return null;
    const r = view.div.getBoundingClientRect();
    return { left: r.left + view.div.clientLeft - originLeft, top: r.top + view.div.clientTop - originTop, width: view.div.clientWidth, height: view.div.clientHeight };
  });
  const next = canvasLayout(shown);
  if (!sameLayout(v.layout, next)) {
    Object.assign(v.canvas.style, { left: `${next.box.left}px`, top: `${next.box.top}px` });
    v.renderer.setSize(next.box.width, next.box.height, true);
    v.layout = next;
  }
  return v.layout;
}

/** Point the camera along the orbit. */
function aim(v) {
  const { orbit, camera } = v;
  camera.position.set(...geo.orbitPosition(orbit.target, orbit.azimuth, orbit.elevation, orbit.distance));
  camera.up.set(0, 1, 0);
  camera.lookAt(...orbit.target);
}

function render(v) {
  v.scheduled = 0;
  aim(v);
  const { viewports } = place(v);
  // Each view's viewport is cleared to its scene's white and drawn; the rest of the canvas stays
  // transparent: WebGL clears the drawing buffer after each composite (preserveDrawingBuffer
  // is false), so no clear of the whole canvas is needed.
  const { renderer, camera } = v;
  renderer.setScissorTest(true);
  Object.values(v.views).forEach((view, k) => {
    const port = viewports[k];
    if (!port) return;
    renderer.setViewport(port.x, port.y, port.width, port.height);
    renderer.setScissor(port.x, port.y, port.width, port.height);
    camera.aspect = port.width / Math.max(1, port.height);
    camera.updateProjectionMatrix();
    renderer.render(view.scene, camera);
  });
  if (v.frame && !v.marked) { v.marked = true; performance.mark("skeletons-drawn"); }
  v.renders += 1;
}

const rgb = (c) => [c.r, c.g, c.b];
const [markedRgb, bodyRgb, selectedRgb] = [MARKED, BODY, SELECTED].map(rgb);

/** A CSS colour as a THREE colour, made once per colour. */
function colorFrom(v, css) {
  let c = v.colorCache.get(css);
  if (!c) { c = new THREE.Color(css); v.colorCache.set(css, c); }
  return c;
}

/** The bones of one view: a lit triangle soup (oriented takes) or plain lines. The bones' light
 * (the scene's ambient and directional light, as a Lambert material would show it) is baked into
 * their vertex colours by shadeSoup: an unlit material draws and compiles faster on a CPU
 * rasteriser. */
function writeBones(v, view, points, rotations, flagged, selected) {
  const { bones } = v;
  if (!v.oriented) { writeLines(view.bones.geometry.attributes.position, points, bones); return; }
  const position = view.bones.geometry.attributes.position;
  geo.boneSoup(points, rotations, bones, v.sides, position.array);
  position.needsUpdate = true;
  const own = bones.map(([p]) => (p === selected ? selectedRgb : flagged.has(p) ? rgb(colorFrom(v, flagged.get(p))) : bodyRgb));
  const color = view.bones.geometry.attributes.color;
  geo.shadeSoup(position.array, bones.length, (b, f) => (geo.MARKED_FACES.has(f) ? markedRgb : own[b]), LIGHT, LIGHT_AMBIENT, LIGHT_DIRECT, color.array);
  color.needsUpdate = true;
}

/** The joints of one view, coloured: selected, flagged, filled, bridged, else the joint colour
 * faded by the detection confidence. */
function writeJoints(v, view, points, { flagged, selected, confidence, bridged, filled }) {
  const colorOf = (j) => (j === selected ? SELECTED : flagged.has(j) ? colorFrom(v, flagged.get(j)) : null);
  const jp = view.joints.geometry.attributes.position, jc = view.joints.geometry.attributes.color;
  writePoints(jp.array, points, (j, p) => geo.present(p) && !v.loose.has(j));
  points.forEach((p, j) => {
    // A bridged keypoint is drawn purple at full strength (the filter's value, not a detection).
    const isBridged = bridged && bridged[j];
    const isFilled = filled && filled[j] > 0;
    let c = colorOf(j) || (isFilled ? FILLED : isBridged ? BRIDGED : JOINT);
    if (confidence && !colorOf(j) && !isBridged && !isFilled) c = new THREE.Color(...geo.fade([c.r, c.g, c.b], confidence[j]));
    jc.array[3 * j] = c.r; jc.array[3 * j + 1] = c.g; jc.array[3 * j + 2] = c.b;
  });
  jp.needsUpdate = true; jc.needsUpdate = true;
}

/** One view's vertex buffers for a frame. Per frame, they are rewritten in place and nothing is
 * allocated. */
function write(v, view, points, rotations, marks) {
  writeBones(v, view, points, rotations, marks.flagged, marks.selected);
  writeJoints(v, view, points, marks);
  const { filled } = marks;
  view.rings.visible = Boolean(filled);
  if (filled) {
    const rp = view.rings.geometry.attributes.position;
    v.filledShown = writePoints(rp.array, points, (j, p) => filled[j] > 0 && geo.present(p));
    rp.needsUpdate = true;
  }
  if (v.triadsOn && v.oriented) {
    const t = geo.triads(points, rotations, v.nJoints, 0.05 * v.size, geo.identity);
    const ap = view.axes.geometry.attributes.position, ac = view.axes.geometry.attributes.color;
    writeTriads(t, ap.array, ac.array, AXES);
    ap.needsUpdate = true; ac.needsUpdate = true;
  }
}

function show(v, next) {
  v.frame = next;
  const { views } = v;
  write(v, views.raw, next.raw, next.rawRotations, { flagged: next.rawFlagged || next.flagged, selected: next.selected, confidence: next.confidence });
  write(v, views.corrected, next.corrected, next.correctedRotations,
    { flagged: next.flagged, selected: next.selected, confidence: next.confidence, bridged: next.bridged, filled: next.filled });
  if (v.overlayOn) writeLines(views.corrected.ghost.geometry.attributes.position, next.raw, v.bones);
  // Auto-framing: the orbit's target follows the body over the floor, the root (follow) or
  // the selected joint (close-in).
  v.orbit.target = geo.focusTarget(v.focus, next.corrected, v.root, next.selected, v.orbit.target);
  v.drawn += 1;
  v.requestRender();
}

/** Screen position (page pixels) of a point in one view. */
function project(v, view, point) {
  const p = new THREE.Vector3(point[0], point[1], point[2]).project(v.camera);
  const rect = view.div.getBoundingClientRect();
  const left = rect.left + view.div.clientLeft, top = rect.top + view.div.clientTop;
  return [left + ((p.x + 1) / 2) * view.div.clientWidth, top + ((1 - p.y) / 2) * view.div.clientHeight];
}

function aspectFor(v, view) {
  const w = view.div.clientWidth, ht = view.div.clientHeight;
  v.camera.aspect = w / Math.max(1, ht);
  v.camera.updateProjectionMatrix();
}

/** The joint of the shown frame nearest the pointer in one view (within 10 px), or null. */
function nearest(v, view, e) {
  if (!v.frame) return null;
  aspectFor(v, view);
  const points = view === v.views.raw ? v.frame.raw : v.frame.corrected;
  let best = null, bestDistance = 10;
  points.forEach((p, j) => {
    if (!geo.present(p) || v.loose.has(j)) return;
    const [x, y] = project(v, view, p);
    const d = Math.hypot(x - e.clientX, y - e.clientY);
    if (d < bestDistance) { best = j; bestDistance = d; }
  });
  return best;
}

/** Hover: the joint nearest the pointer (within 10 px) names itself. */
function hover(v, view, e) {
  const best = nearest(v, view, e);
  v.tooltip.hidden = best == null;
  if (best != null) {
    v.tooltip.textContent = hoverLabel(v.names[best], v.frame, best, view === v.views.corrected);
    v.tooltip.style.left = `${e.pageX + 12}px`;
    v.tooltip.style.top = `${e.pageY + 12}px`;
  }
}

/** Orbit: drag to turn, wheel to zoom; both views move the one camera. Each view's element
 * (under the canvas, which lets the pointer through) takes its own events, so a click picks
 * among the joints of the view it landed in. */
function listenOrbit(v, view, onSelect) {
  const target = view.div;
  let last = null, travelled = 0;
  target.addEventListener("pointerdown", (e) => { last = [e.clientX, e.clientY]; travelled = 0; target.setPointerCapture(e.pointerId); });
  target.addEventListener("pointerup", (e) => {
    last = null;
    target.releasePointerCapture(e.pointerId);
    if (travelled < 4) { const j = nearest(v, view, e); if (j != null) onSelect(j); } // a click, not a drag
  });
  target.addEventListener("pointermove", (e) => {
    if (last) {
      travelled += Math.abs(e.clientX - last[0]) + Math.abs(e.clientY - last[1]);
      Object.assign(v.orbit, dragged(v.orbit, e.clientX - last[0], e.clientY - last[1]));
      last = [e.clientX, e.clientY];
      v.requestRender();
    } else hover(v, view, e);
  });
  target.addEventListener("pointerleave", () => { v.tooltip.hidden = true; });
  target.addEventListener("wheel", (e) => {
    e.preventDefault();
    v.orbit.distance = zoomed(v.orbit.distance, e.deltaY, v.size);
    v.requestRender();
  }, { passive: false });
}

/** The views' state: the skeleton drawn, the body's size and framing, the one camera. */
function viewsState(skeleton, overview) {
  const { names, nJoints, oriented } = skeleton;
  const { bones, loose, drawnRoot } = drawnSkeleton(skeleton);
  const sides = oriented ? geo.boneSides(overview.raw[0], overview.raw_rotations[0], bones) : null;
  // bodyBox answers in Z-up terms: its floor is the lowest data Y, its half the body's size.
  const box = geo.bodyBox([overview.raw, overview.corrected], 0.1);
  const size = 2 * box.half;
  // The whole body in view, every keypoint with a margin (the head too, seen from above).
  const framing = geo.bodyFraming(box, FOV);
  return {
    names, nJoints, oriented, bones, loose, drawnRoot, sides, size, framing, floorY: box.floor,
    orbit: { ...geo.PRESETS.front, distance: framing.distance, target: [0, framing.height, 0] },
    camera: new THREE.PerspectiveCamera(FOV, 1, size / 100, size * 200),
    root: oriented ? drawnRoot : -1,
    focus: "body", frame: null, triadsOn: false, overlayOn: false, floorPlane: null, floorOn: true,
    renders: 0, drawn: 0, scheduled: 0, marked: false, filledShown: 0, layout: null, colorCache: new Map(),
  };
}

/**
 * @param divs     {raw, corrected} containers
 * @param skeleton {names, parents, bones?, nJoints, oriented}
 * @param overview {raw, corrected, raw_rotations?, corrected_rotations?}
 */
export function createViews(divs, skeleton, overview, onSelect = () => {}) {
  const v = viewsState(skeleton, overview);
  v.row = divs.raw.parentNode.parentNode;
  Object.assign(v, sharedCanvas(v.row));
  v.views = buildViews(divs, v, overview);
  v.tooltip = document.createElement("div");
  v.tooltip.className = "joint-tooltip";
  v.tooltip.hidden = true;
  document.body.append(v.tooltip);
  v.requestRender = () => { if (!v.scheduled) v.scheduled = requestAnimationFrame(() => render(v)); };
  const resized = new ResizeObserver(v.requestRender);
  for (const element of [v.row, ...Object.values(divs)]) resized.observe(element);
  for (const view of Object.values(v.views)) listenOrbit(v, view, onSelect);
  return viewsApi(v, resized);
}

/** What the take and compare views (and the browser tests) use of the 3D views. */
function viewsApi(v, resized) {
  const { orbit, camera, views, oriented } = v;
  return {
    show: (next) => show(v, next),
    requestRender: v.requestRender,
    /** Draw now (the first frame must not wait behind the charts' set-up). */
    renderNow() { if (v.scheduled) cancelAnimationFrame(v.scheduled); render(v); },
    get busy() { return v.scheduled !== 0; },
    get drawn() { return v.drawn; },
    get renders() { return v.renders; },
    get orbit() { return { ...orbit, target: [...orbit.target] }; },
    get cameraPosition() { return camera.position.toArray(); },
    get bones() { return oriented ? v.bones.length : 0; },
    get points() { return v.names.length; },
    get lines() { return v.bones.length; },
    /** Filled samples (marker takes) drawn in the corrected view of the shown frame. */
    get filledShown() { return v.filledShown; },
    /** Screen position of a point of the shown frame in one view (for tests and focus). */
    screenOf(viewName, index) {
      const view = views[viewName];
      aspectFor(v, view);
      camera.position.set(...geo.orbitPosition(orbit.target, orbit.azimuth, orbit.elevation, orbit.distance));
      camera.lookAt(...orbit.target);
      return project(v, view, (viewName === "raw" ? v.frame.raw : v.frame.corrected)[index]);
    },
    /** Centre the camera on "body", "joint" (close-in on the selected joint) or "root" (follow). */
    setFocus(mode) {
      const resting = [v.focus, mode].includes("joint") && v.focus !== mode; // into or out of close-in
      v.focus = mode;
      if (resting) orbit.distance = mode === "joint" ? geo.focusDistance(mode, v.size) : v.framing.distance;
      if (mode === "body" && v.frame) orbit.target[1] = v.framing.height;
      if (v.frame) show(v, v.frame); else v.requestRender();
    },
    get focus() { return v.focus; },
    setCamera(name) { Object.assign(orbit, geo.PRESETS[name]); v.requestRender(); },
    setTriads(on) { v.triadsOn = on && oriented; for (const view of Object.values(views)) view.axes.visible = v.triadsOn; if (v.frame) show(v, v.frame); },
    setOverlay(on) { v.overlayOn = on; views.corrected.ghost.visible = on; if (v.frame) show(v, v.frame); },
    ...floorControls(v), // setFloor, setFloorShown, floorDrawn
    /** The canvas's box and each view's viewport (CSS pixels, y from the bottom), as last drawn. */
    get layout() { return v.layout && { box: { ...v.layout.box }, viewports: v.layout.viewports.map((port) => port && { ...port }) }; },
    dispose() { resized.disconnect(); v.tooltip.remove(); v.renderer.dispose(); v.canvas.remove(); },
  };
}
