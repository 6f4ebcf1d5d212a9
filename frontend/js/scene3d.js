// The two 3D views drawn with three.js: one camera (one orbit state, one THREE camera) renders
// both views, so they cannot drift apart nor re-trigger each other. One WebGL canvas, laid over
// both panels, draws them in two scissored viewports: the browser's compositor reads a WebGL
// canvas back once per frame, and with two canvases those reads were most of a frame's cost.
// A frame update rewrites vertex buffers and asks for one render on the next animation frame;
// nothing queues.
import * as THREE from "/static/vendor/three/three.module.min.js";
import * as geo from "./geometry.js";
import { canvasLayout, sameLayout } from "./viewports.js";

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
  const a = attribute.array;
  let o = 0;
  for (const [p, c] of pairs) {
    for (const q of [points[p], points[c]]) {
      const ok = geo.present(points[p]) && geo.present(points[c]);
      a[o++] = ok ? q[0] : 0; a[o++] = ok ? q[1] : 0; a[o++] = ok ? q[2] : 0;
    }
  }
  attribute.needsUpdate = true;
}

/**
 * @param divs     {raw, corrected} containers
 * @param skeleton {names, parents, bones?, nJoints, oriented}
 * @param overview {raw, corrected, raw_rotations?, corrected_rotations?}
 */
export function createViews(divs, skeleton, overview, onSelect = () => {}) {
  const { names, parents, nJoints, oriented } = skeleton;
  // Keypoint takes of a known layout come with their bones; others are joined by parents.
  const bones = skeleton.bones && skeleton.bones.length ? skeleton.bones : geo.bonesOf(parents);
  // A BVH joint the server joined by no bone (a static root left at the origin while its child
  // carries the travel, as Bandai's joint_Root) is not drawn; the root followed is its child.
  const inBone = new Set(bones.flat());
  const loose = new Set(oriented && skeleton.bones && skeleton.bones.length ? names.map((_, j) => j).filter((j) => !inBone.has(j)) : []);
  const firstRoot = parents.indexOf(-1);
  const drawnRoot = loose.has(firstRoot) ? parents.findIndex((p, j) => p === firstRoot && !loose.has(j)) : firstRoot;
  const sides = oriented ? geo.boneSides(overview.raw[0], overview.raw_rotations[0], bones) : null;
  // bodyBox answers in Z-up terms: its floor is the lowest data Y, its half the body's size.
  const box = geo.bodyBox([overview.raw, overview.corrected], 0.1);
  const floorY = box.floor;
  const size = 2 * box.half;
  // The whole body in view, every keypoint with a margin (the head too, seen from above).
  const framing = geo.bodyFraming(box, FOV);
  const orbit = { ...geo.PRESETS.front, distance: framing.distance, target: [0, framing.height, 0] };
  const camera = new THREE.PerspectiveCamera(FOV, 1, size / 100, size * 200);
  // The one canvas: absolutely placed in the row that holds both panels, over the union of the
  // shown views; it takes no pointer events (each view's own element does) and is transparent
  // between the views, where the panels' borders and gap show through.
  const row = divs.raw.parentNode.parentNode;
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
  const views = {};
  for (const [name, div] of Object.entries(divs)) {
    div.setAttribute("role", "img");
    div.setAttribute("aria-label", `${name} skeleton, drag to orbit, wheel to zoom`);
    const parts = viewScene(bones.length, names.length, nJoints, oriented);
    const grid = new THREE.GridHelper(size * 3, 12, 0xc0c7cf, 0xe3e7ec);
    grid.position.y = floorY;
    parts.scene.add(grid);
    if (oriented) {
      const path = overview.raw.map((points) => points[drawnRoot]).filter(geo.present);
      const line = new THREE.Line(new THREE.BufferGeometry().setFromPoints(path.map((p) => new THREE.Vector3(p[0], floorY + size * 0.002, p[2]))),
        new THREE.LineBasicMaterial({ color: 0x95a5a6 }));
      parts.scene.add(line);
    }
    views[name] = { div, ...parts };
  }
  const tooltip = document.createElement("div");
  tooltip.className = "joint-tooltip";
  tooltip.hidden = true;
  document.body.append(tooltip);

  const root = oriented ? drawnRoot : -1;
  let focus = "body";
  let frame = null, triadsOn = false, overlayOn = false, renders = 0, drawn = 0, scheduled = 0, marked = false, filledShown = 0;
  const sizeOf = (view) => [view.div.clientWidth, view.div.clientHeight];
  // The shown views' rectangles (inside their borders, from the row's padding edge, where the
  // absolutely placed canvas is measured from) → the canvas box and the viewports.
  let layout = null;
  const place = () => {
    const r0 = row.getBoundingClientRect();
    const originLeft = r0.left + row.clientLeft, originTop = r0.top + row.clientTop;
    const shown = Object.values(views).map((view) => {
      if (view.div.offsetParent === null) return null;
      const r = view.div.getBoundingClientRect();
      return { left: r.left + view.div.clientLeft - originLeft, top: r.top + view.div.clientTop - originTop, width: view.div.clientWidth, height: view.div.clientHeight };
    });
    const next = canvasLayout(shown);
    if (!sameLayout(layout, next)) {
      Object.assign(canvas.style, { left: `${next.box.left}px`, top: `${next.box.top}px` });
      renderer.setSize(next.box.width, next.box.height, true);
      layout = next;
    }
    return layout;
  };
  const render = () => {
    scheduled = 0;
    camera.position.set(...geo.orbitPosition(orbit.target, orbit.azimuth, orbit.elevation, orbit.distance));
    camera.up.set(0, 1, 0);
    camera.lookAt(...orbit.target);
    const { viewports } = place();
    // Each view's viewport is cleared to its scene's white and drawn; the rest of the canvas stays
    // transparent: WebGL clears the drawing buffer after each composite (preserveDrawingBuffer
    // is false), so no clear of the whole canvas is needed.
    renderer.setScissorTest(true);
    Object.values(views).forEach((view, k) => {
      const v = viewports[k];
      if (!v) return;
      renderer.setViewport(v.x, v.y, v.width, v.height);
      renderer.setScissor(v.x, v.y, v.width, v.height);
      camera.aspect = v.width / Math.max(1, v.height);
      camera.updateProjectionMatrix();
      renderer.render(view.scene, camera);
    });
    if (frame && !marked) { marked = true; performance.mark("skeletons-drawn"); }
    renders += 1;
  };
  const requestRender = () => { if (!scheduled) scheduled = requestAnimationFrame(render); };
  const resized = new ResizeObserver(requestRender);
  for (const element of [row, ...Object.values(divs)]) resized.observe(element);

  // Per frame, vertex buffers are rewritten in place and nothing is allocated. The bones' light
  // (the scene's ambient and directional light, as a Lambert material would show it) is baked
  // into their vertex colours by shadeSoup: an unlit material draws and compiles faster on a
  // CPU rasteriser.
  const colorCache = new Map();
  const colorFrom = (css) => { let c = colorCache.get(css); if (!c) { c = new THREE.Color(css); colorCache.set(css, c); } return c; };
  const rgb = (c) => [c.r, c.g, c.b];
  const [markedRgb, bodyRgb, selectedRgb] = [MARKED, BODY, SELECTED].map(rgb);
  const write = (view, points, rotations, flagged, selected, confidence = null, bridged = null, filled = null) => {
    const colorOf = (j) => (j === selected ? SELECTED : flagged.has(j) ? colorFrom(flagged.get(j)) : null);
    if (oriented) {
      const position = view.bones.geometry.attributes.position;
      geo.boneSoup(points, rotations, bones, sides, position.array);
      position.needsUpdate = true;
      const own = bones.map(([p]) => (p === selected ? selectedRgb : flagged.has(p) ? rgb(colorFrom(flagged.get(p))) : bodyRgb));
      const color = view.bones.geometry.attributes.color;
      geo.shadeSoup(position.array, bones.length, (b, f) => (geo.MARKED_FACES.has(f) ? markedRgb : own[b]), LIGHT, LIGHT_AMBIENT, LIGHT_DIRECT, color.array);
      color.needsUpdate = true;
    } else {
      writeLines(view.bones.geometry.attributes.position, points, bones);
    }
    const jp = view.joints.geometry.attributes.position, jc = view.joints.geometry.attributes.color;
    points.forEach((p, j) => {
      const ok = geo.present(p) && !loose.has(j);
      jp.array[3 * j] = ok ? p[0] : NaN; jp.array[3 * j + 1] = ok ? p[1] : NaN; jp.array[3 * j + 2] = ok ? p[2] : NaN;
      // A bridged keypoint is drawn purple at full strength (the filter's value, not a detection).
      const isBridged = bridged && bridged[j];
      const isFilled = filled && filled[j] > 0;
      let c = colorOf(j) || (isFilled ? FILLED : isBridged ? BRIDGED : JOINT);
      if (confidence && !colorOf(j) && !isBridged && !isFilled) c = new THREE.Color(...geo.fade([c.r, c.g, c.b], confidence[j]));
      jc.array[3 * j] = c.r; jc.array[3 * j + 1] = c.g; jc.array[3 * j + 2] = c.b;
    });
    jp.needsUpdate = true; jc.needsUpdate = true;
    view.rings.visible = Boolean(filled);
    if (filled) {
      const rp = view.rings.geometry.attributes.position;
      let shown = 0;
      points.forEach((p, j) => {
        const on = filled[j] > 0 && geo.present(p);
        shown += on;
        rp.array[3 * j] = on ? p[0] : NaN; rp.array[3 * j + 1] = on ? p[1] : NaN; rp.array[3 * j + 2] = on ? p[2] : NaN;
      });
      rp.needsUpdate = true;
      filledShown = shown;
    }
    if (triadsOn && oriented) {
      const t = geo.triads(points, rotations, nJoints, 0.05 * size, geo.identity);
      const ap = view.axes.geometry.attributes.position, ac = view.axes.geometry.attributes.color;
      let o = 0, n = 0;
      for (let k = 0; k < t.x.length; k++) {
        if (t.x[k] === null && k % 3 === 2) continue;
        ap.array[o++] = t.x[k] ?? 0; ap.array[o++] = t.y[k] ?? 0; ap.array[o++] = t.z[k] ?? 0;
        const c = AXES[Math.floor(n / 2) % 3]; n += 1;
        ac.array[3 * (n - 1)] = c.r; ac.array[3 * (n - 1) + 1] = c.g; ac.array[3 * (n - 1) + 2] = c.b;
      }
      ap.needsUpdate = true; ac.needsUpdate = true;
    }
  };
  const show = (next) => {
    frame = next;
    write(views.raw, next.raw, next.rawRotations, next.rawFlagged || next.flagged, next.selected, next.confidence);
    write(views.corrected, next.corrected, next.correctedRotations, next.flagged, next.selected, next.confidence, next.bridged, next.filled);
    if (overlayOn) writeLines(views.corrected.ghost.geometry.attributes.position, next.raw, bones);
    // Auto-framing: the orbit's target follows the body over the floor, the root (follow) or
    // the selected joint (close-in).
    orbit.target = geo.focusTarget(focus, next.corrected, root, next.selected, orbit.target);
    drawn += 1;
    requestRender();
  };

  // Orbit: drag to turn, wheel to zoom; both views move the one camera.
  // Each view's element (under the canvas, which lets the pointer through) takes its own events,
  // so a click picks among the joints of the view it landed in.
  for (const view of Object.values(views)) {
    const target = view.div;
    let last = null, travelled = 0;
    target.addEventListener("pointerdown", (e) => { last = [e.clientX, e.clientY]; travelled = 0; target.setPointerCapture(e.pointerId); });
    target.addEventListener("pointerup", (e) => {
      last = null;
      target.releasePointerCapture(e.pointerId);
      if (travelled < 4) { const j = nearest(view, e); if (j != null) onSelect(j); } // a click, not a drag
    });
    target.addEventListener("pointermove", (e) => {
      if (last) {
        travelled += Math.abs(e.clientX - last[0]) + Math.abs(e.clientY - last[1]);
        orbit.azimuth -= (e.clientX - last[0]) * 0.01;
        orbit.elevation = Math.max(-0.2, Math.min(1.55, orbit.elevation + (e.clientY - last[1]) * 0.01));
        last = [e.clientX, e.clientY];
        requestRender();
      } else hover(view, e);
    });
    target.addEventListener("pointerleave", () => { tooltip.hidden = true; });
    target.addEventListener("wheel", (e) => {
      e.preventDefault();
      orbit.distance = Math.max(size * 0.3, Math.min(size * 8, orbit.distance * Math.exp(e.deltaY * 0.001)));
      requestRender();
    }, { passive: false });
  }
  // Hover: the joint nearest the pointer (within 10 px) names itself.
  const project = (view, point) => {
    const v = new THREE.Vector3(point[0], point[1], point[2]).project(camera);
    const rect = view.div.getBoundingClientRect();
    const left = rect.left + view.div.clientLeft, top = rect.top + view.div.clientTop;
    return [left + ((v.x + 1) / 2) * view.div.clientWidth, top + ((1 - v.y) / 2) * view.div.clientHeight];
  };
  const aspectFor = (view) => { const [w, h] = sizeOf(view); camera.aspect = w / Math.max(1, h); camera.updateProjectionMatrix(); };
  const nearest = (view, e) => {
    if (!frame) return null;
    aspectFor(view);
    const points = view === views.raw ? frame.raw : frame.corrected;
    let best = null, bestDistance = 10;
    points.forEach((p, j) => {
      if (!geo.present(p) || loose.has(j)) return;
      const [x, y] = project(view, p);
      const d = Math.hypot(x - e.clientX, y - e.clientY);
      if (d < bestDistance) { best = j; bestDistance = d; }
    });
    return best;
  };
  const hover = (view, e) => {
    const best = nearest(view, e);
    tooltip.hidden = best == null;
    if (best != null) {
      const corrected = view === views.corrected;
      const marks = frame.confidence ? ` · confidence ${frame.confidence[best].toFixed(2)}${frame.bridged && frame.bridged[best] && corrected ? " · bridged" : ""}${frame.filled && frame.filled[best] > 0 && corrected ? " · filled" : ""}` : "";
      tooltip.textContent = names[best] + marks;
      tooltip.style.left = `${e.pageX + 12}px`;
      tooltip.style.top = `${e.pageY + 12}px`;
    }
  };

  return {
    show,
    requestRender,
    /** Draw now (the first frame must not wait behind the charts' set-up). */
    renderNow() { if (scheduled) cancelAnimationFrame(scheduled); render(); },
    get busy() { return scheduled !== 0; },
    get drawn() { return drawn; },
    get renders() { return renders; },
    get orbit() { return { ...orbit, target: [...orbit.target] }; },
    get cameraPosition() { return camera.position.toArray(); },
    get bones() { return oriented ? bones.length : 0; },
    get points() { return names.length; },
    get lines() { return bones.length; },
    /** Filled samples (marker takes) drawn in the corrected view of the shown frame. */
    get filledShown() { return filledShown; },
    /** Screen position of a point of the shown frame in one view (for tests and focus). */
    screenOf(viewName, index) {
      const view = views[viewName];
      aspectFor(view);
      camera.position.set(...geo.orbitPosition(orbit.target, orbit.azimuth, orbit.elevation, orbit.distance));
      camera.lookAt(...orbit.target);
      return project(view, (viewName === "raw" ? frame.raw : frame.corrected)[index]);
    },
    /** Centre the camera on "body", "joint" (close-in on the selected joint) or "root" (follow). */
    setFocus(mode) {
      const resting = [focus, mode].includes("joint") && focus !== mode; // into or out of close-in
      focus = mode;
      if (resting) orbit.distance = mode === "joint" ? geo.focusDistance(mode, size) : framing.distance;
      if (mode === "body" && frame) orbit.target[1] = framing.height;
      if (frame) show(frame); else requestRender();
    },
    get focus() { return focus; },
    setCamera(name) { Object.assign(orbit, geo.PRESETS[name]); requestRender(); },
    setTriads(on) { triadsOn = on && oriented; for (const v of Object.values(views)) v.axes.visible = triadsOn; if (frame) show(frame); },
    setOverlay(on) { overlayOn = on; views.corrected.ghost.visible = on; if (frame) show(frame); },
    /** The canvas's box and each view's viewport (CSS pixels, y from the bottom), as last drawn. */
    get layout() { return layout && { box: { ...layout.box }, viewports: layout.viewports.map((v) => v && { ...v }) }; },
    dispose() { resized.disconnect(); tooltip.remove(); renderer.dispose(); canvas.remove(); },
  };
}
