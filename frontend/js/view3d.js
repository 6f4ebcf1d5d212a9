// The two 3D views (raw, corrected): one shared camera, per-frame updates of only the moving
// data (Plotly.restyle of coordinates), at most one redraw in flight (later frames replace
// pending ones, so a slow machine drops frames instead of queueing them).
import * as geo from "./geometry.js";

const BODY = "#5b84b1";
const MARKED = "#f39c12";
const GHOST = "#7f8c8d";
const JOINT = "#1f4e79";
export const CAMERAS = {
  front: { eye: { x: 0, y: -2.1, z: 0.35 }, center: { x: 0, y: 0, z: 0 }, up: { x: 0, y: 0, z: 1 } },
  side: { eye: { x: 2.1, y: 0, z: 0.35 }, center: { x: 0, y: 0, z: 0 }, up: { x: 0, y: 0, z: 1 } },
  top: { eye: { x: 0, y: -0.01, z: 2.4 }, center: { x: 0, y: 0, z: 0 }, up: { x: 0, y: 1, z: 0 } },
};

const sameCamera = (a, b) => !!a && !!b && ["eye", "center", "up"].every((k) =>
  ["x", "y", "z"].every((c) => Math.abs(((a[k] || {})[c] ?? 0) - ((b[k] || {})[c] ?? 0)) < 1e-9));

/**
 * @param Plotly   the loaded library
 * @param divs     {raw, corrected} elements
 * @param skeleton {names, parents, nJoints, oriented} (oriented: rotations are served)
 * @param overview {raw, corrected, raw_rotations?, corrected_rotations?} frames of the whole take
 */
export async function createViews(Plotly, divs, skeleton, overview) {
  const { names, parents, nJoints, oriented } = skeleton;
  const bones = geo.bonesOf(parents);
  const sides = oriented ? geo.boneSides(overview.raw[0], overview.raw_rotations[0], bones) : null;
  const faces = geo.boneFaces(bones.length);
  const box = geo.bodyBox([overview.raw, overview.corrected]);
  const floor = box.floor;
  const extent = 2 * box.half;
  let ranges = geo.followRanges(geo.centreOf(overview.raw[0]) || [0, 0, 0], box);
  const root = parents.indexOf(-1);
  const path = oriented ? geo.groundPath(overview.raw, root, floor) : { x: [], y: [], z: [] };
  const grid = floorGrid(geo.frameTake([overview.raw]).ranges, floor);
  let camera = CAMERAS.front;
  let triadsOn = false, overlayOn = false;
  let flaggedKey = null;

  const layout = () => ({
    margin: { l: 0, r: 0, t: 0, b: 0 }, showlegend: false, uirevision: "keep",
    hoverlabel: { bgcolor: "#fff" },
    scene: {
      aspectmode: "cube",
      xaxis: { range: ranges[0], title: { text: "X" }, showspikes: false },
      yaxis: { range: ranges[1], title: { text: "−Z" }, showspikes: false },
      zaxis: { range: ranges[2], title: { text: "Y (up)" }, showspikes: false },
      camera,
    },
  });
  const traces = (ghost) => [
    oriented
      ? { type: "mesh3d", ...faces, x: [], y: [], z: [], facecolor: [], flatshading: true, hoverinfo: "skip",
        lighting: { ambient: 0.65, diffuse: 0.6, specular: 0.05 }, name: "bones" }
      : { type: "scatter3d", mode: "lines", x: [], y: [], z: [], line: { color: BODY, width: 5 }, hoverinfo: "skip", name: "bones" },
    { type: "scatter3d", mode: "markers", x: [], y: [], z: [], text: names, name: "joints",
      marker: { size: oriented ? 1.5 : 4, color: JOINT }, hovertemplate: "%{text}<extra></extra>" },
    { type: "scatter3d", mode: "lines", x: [], y: [], z: [], line: { width: 4, color: [] }, visible: false, hoverinfo: "skip", name: "axes" },
    { type: "scatter3d", mode: "lines", ...path, line: { color: "#95a5a6", width: 3 }, hoverinfo: "skip", name: "root path" },
    { type: "scatter3d", mode: "lines", ...grid, line: { color: "#d0d6dd", width: 1 }, hoverinfo: "skip", name: "floor" },
    ...(ghost ? [{ type: "scatter3d", mode: "lines", x: [], y: [], z: [], line: { color: GHOST, width: 6 }, opacity: 0.35,
      visible: false, hoverinfo: "skip", name: "raw (ghost)" }] : []),
  ];
  const config = { displaylogo: false, displayModeBar: false, responsive: true };
  await Plotly.newPlot(divs.raw, traces(false), layout(), config);
  await Plotly.newPlot(divs.corrected, traces(true), layout(), config);

  // One camera for both views. A camera set on one view is copied to the other at most once
  // per animation frame, and an event carrying the camera both views already hold (the echo of
  // that copy) is ignored: no view can re-trigger the other.
  let pendingCamera = null, cameraHandle = 0;
  const applyCamera = () => {
    cameraHandle = 0;
    const { source, value } = pendingCamera;
    pendingCamera = null;
    for (const div of [divs.raw, divs.corrected]) {
      if (div === source) continue;
      const held = div._fullLayout && div._fullLayout.scene && div._fullLayout.scene.camera;
      if (!sameCamera(held, value)) Plotly.relayout(div, { "scene.camera": value });
    }
  };
  const onCamera = (source) => (e) => {
    const value = e && e["scene.camera"];
    if (!value || sameCamera(value, camera)) return;
    camera = value;
    pendingCamera = { source, value };
    if (!cameraHandle) cameraHandle = requestAnimationFrame(applyCamera);
  };
  for (const div of [divs.raw, divs.corrected]) {
    div.on("plotly_relayout", onCamera(div));
    div.on("plotly_relayouting", onCamera(div));
  }

  // Per-frame drawing: coordinates only; colours only when the flagged joints change.
  let busy = false, pending = null, drawn = 0, firstDrawn = null;
  // The box follows the body: re-centred (one relayout) only when the body drifts off-centre.
  const follow = async (points) => {
    const centre = geo.centreOf(points);
    if (!centre || !geo.drifted(centre, ranges)) return;
    ranges = geo.followRanges(centre, box);
    const axes = { "scene.xaxis.range": ranges[0], "scene.yaxis.range": ranges[1], "scene.zaxis.range": ranges[2] };
    await Promise.all([divs.raw, divs.corrected].map((div) => Plotly.relayout(div, axes)));
  };
  const update = async (frame) => {
    await follow(frame.corrected);
    const key = [...frame.flagged.keys()].join(",");
    const recolor = key !== flaggedKey;
    flaggedKey = key;
    const work = [["raw", frame.raw, frame.rawRotations], ["corrected", frame.corrected, frame.correctedRotations]].map(([view, points, rotations]) => {
      const div = divs[view];
      if (view === "raw" && overlayOn) return null;
      const bonesXYZ = oriented ? geo.boneVertices(points, rotations, bones, sides) : geo.boneLines(points, bones);
      const joints = geo.markers(points);
      const update = { x: [bonesXYZ.x, joints.x], y: [bonesXYZ.y, joints.y], z: [bonesXYZ.z, joints.z] };
      const indices = [0, 1];
      if (triadsOn && oriented) {
        const t = geo.triads(points, rotations, nJoints, 0.04 * extent);
        update.x.push(t.x); update.y.push(t.y); update.z.push(t.z); indices.push(2);
      }
      if (view === "corrected" && overlayOn) {
        const ghost = geo.boneLines(frame.raw, bones);
        update.x.push(ghost.x); update.y.push(ghost.y); update.z.push(ghost.z); indices.push(5);
      }
      const done = Plotly.restyle(div, update, indices);
      if (!recolor) return done;
      const jointColors = points.map((_, j) => frame.flagged.get(j) || JOINT);
      return done.then(() => Plotly.restyle(div, { "marker.color": [jointColors] }, [1]))
        .then(() => (oriented ? Plotly.restyle(div, { facecolor: [geo.faceColors(bones, frame.flagged, BODY, MARKED)] }, [0]) : null));
    });
    await Promise.all(work);
  };
  const show = (frame) => {
    pending = frame;
    if (busy) return;
    busy = true;
    const loop = async () => {
      while (pending) {
        const next = pending;
        pending = null;
        const began = performance.now();
        try { await update(next); } catch (e) { console.warn(e); }
        // WebGL in Plotly paints on the next animation frames; leave the page as long again
        // for input before the next redraw, so clicks and keys never queue behind frames.
        await new Promise((resolve) => setTimeout(resolve, Math.min(200, performance.now() - began)));
        drawn += 1;
        if (!firstDrawn) { firstDrawn = performance.now(); performance.mark("skeletons-drawn"); }
      }
      busy = false;
    };
    loop();
  };

  return {
    show,
    get camera() { return camera; },
    setCamera(name) {
      camera = CAMERAS[name];
      return Promise.all([divs.raw, divs.corrected].map((div) => Plotly.relayout(div, { "scene.camera": camera })));
    },
    setTriads(on, frame) {
      triadsOn = on && oriented;
      for (const div of [divs.raw, divs.corrected]) Plotly.restyle(div, { visible: triadsOn }, [2]);
      if (frame) show(frame);
    },
    setOverlay(on, frame) {
      overlayOn = on;
      Plotly.restyle(divs.corrected, { visible: on }, [5]);
      if (frame) show(frame);
    },
    get busy() { return busy; },
    get drawn() { return drawn; },
  };
}

function floorGrid(ranges, floor) {
  const x = [], y = [], z = [];
  const [[x0, x1], [y0, y1]] = ranges;
  const step = niceStep(Math.max(x1 - x0, y1 - y0) / 8);
  for (let v = Math.ceil(x0 / step) * step; v <= x1; v += step) { x.push(v, v, null); y.push(y0, y1, null); z.push(floor, floor, null); }
  for (let v = Math.ceil(y0 / step) * step; v <= y1; v += step) { x.push(x0, x1, null); y.push(v, v, null); z.push(floor, floor, null); }
  return { x, y, z };
}

function niceStep(raw) {
  const power = 10 ** Math.floor(Math.log10(raw || 1));
  for (const m of [1, 2, 5, 10]) if (m * power >= raw) return m * power;
  return 10 * power;
}
