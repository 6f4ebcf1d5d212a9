// Pure Plotly figure builders: data in, {data, layout} out. No DOM, no fetches.

const FLAG = "#c0392b";
const BONE = "#1f4e79";
const JOINT = "#2b6cb0";
const COLORS = ["#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2", "#7f7f7f", "#bcbd22", "#17becf"];

// A missing point (keypoint not detected) arrives as [null, null, null]; it is left out of the
// drawing (Plotly draws null coordinates as gaps) and of the bounds.
const present = (p) => p != null && p[0] != null && p[1] != null && p[2] != null;

// Data are Y-up; Plotly's scene is Z-up: plot (x, z, y).
// The box follows the body: a fixed size (the largest body extent over the take, so the scale
// never changes) centred on the current frame's centre of the points, floor height fixed.
export function bodyExtent(frameSets) {
  let extent = 0, floor = Infinity, ceiling = -Infinity;
  for (const frames of frameSets) {
    for (const points of frames) {
      const lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
      for (const p of points) if (present(p)) for (let a = 0; a < 3; a++) { lo[a] = Math.min(lo[a], p[a]); hi[a] = Math.max(hi[a], p[a]); }
      extent = Math.max(extent, ...hi.map((v, a) => v - lo[a]));
      floor = Math.min(floor, lo[1]); ceiling = Math.max(ceiling, hi[1]);
    }
  }
  if (!Number.isFinite(floor)) { floor = 0; ceiling = 1; }
  return { half: (extent || 1) * 0.6, floor, ceiling };
}

export function sceneBounds(points, extent) {
  const shown = points.filter(present);
  const n = shown.length || 1;
  const mid = [0, 1, 2].map((a) => shown.reduce((s, p) => s + p[a], 0) / n);
  const half = Math.max(extent.half, (extent.ceiling - extent.floor) / 2);
  const yMid = (extent.floor + extent.ceiling) / 2;
  return [[mid[0] - half, mid[0] + half], [yMid - half, yMid + half], [mid[2] - half, mid[2] + half]];
}

export function skeletonFigure(points, parents, flagged, bounds, title, camera) {
  const xs = [], ys = [], zs = [];
  parents.forEach((parent, child) => {
    if (parent < 0) return;
    const a = points[parent], b = points[child];
    if (!present(a) || !present(b)) return;
    xs.push(a[0], b[0], null); ys.push(a[2], b[2], null); zs.push(a[1], b[1], null);
  });
  const colors = points.map((_, i) => (flagged.has(i) ? FLAG : JOINT));
  const base = parents.some((p) => p >= 0) ? 3 : 5;
  const sizes = points.map((_, i) => (flagged.has(i) ? 8 : base));
  const data = [
    { type: "scatter3d", mode: "lines", x: xs, y: ys, z: zs, line: { color: BONE, width: 5 }, hoverinfo: "skip", name: "bones" },
    { type: "scatter3d", mode: "markers", x: points.map((p) => p[0]), y: points.map((p) => p[2]), z: points.map((p) => p[1]),
      marker: { color: colors, size: sizes }, name: "joints", hoverinfo: "text" },
  ];
  const axis = (range, label) => ({ range, title: { text: label }, showspikes: false });
  const layout = {
    title: { text: title, font: { size: 14 } },
    margin: { l: 0, r: 0, t: 30, b: 0 },
    showlegend: false,
    uirevision: "keep",
    scene: {
      aspectmode: "cube",
      xaxis: axis(bounds[0], "X"), yaxis: axis(bounds[2], "Z"), zaxis: axis(bounds[1], "Y (up)"),
      camera: camera || { eye: { x: 0.2, y: -1.9, z: 0.5 }, up: { x: 0, y: 0, z: 1 } },
    },
  };
  return { data, layout };
}

function cursorShape(timeS) {
  return { type: "line", xref: "x", yref: "paper", x0: timeS, x1: timeS, y0: 0, y1: 1, line: { color: "#111", width: 1, dash: "dot" } };
}

export function cursorLayout(timeS) {
  return { shapes: [cursorShape(timeS)] };
}

function intervalBars(intervals, fps, yBase, yTop, yaxis) {
  return {
    type: "bar", name: "flagged intervals", yaxis,
    x: intervals.map((i) => (i.start_frame + i.end_frame + 1) / 2 / fps),
    width: intervals.map((i) => Math.max((i.end_frame - i.start_frame + 1) / fps, 2 / fps)),
    y: intervals.map(() => yTop - yBase), base: intervals.map(() => yBase),
    marker: { color: FLAG, opacity: 0.22 },
    customdata: intervals.map((i) => [i.start_frame, i.end_frame, i.joint]),
    hovertemplate: "%{customdata[2]}: frames %{customdata[0]}–%{customdata[1]}<extra>flagged</extra>",
  };
}

export function twistFigure(twist, fps, timeS) {
  const frames = twist.frames.map((f) => f / fps);
  const affected = new Set(twist.intervals.map((i) => i.joint));
  const data = [];
  twist.chains.forEach((chain, k) => {
    const visible = affected.size === 0 ? (k < 2 ? true : "legendonly") : (affected.has(chain.joint) ? true : "legendonly");
    const color = COLORS[k % COLORS.length];
    data.push({ type: "scatter", mode: "lines", x: frames, y: chain.theta_p_deg, name: `${chain.joint} θP`, legendgroup: chain.joint,
      line: { color, width: 1.2 }, visible, hovertemplate: "%{y:.1f}°" });
    data.push({ type: "scatter", mode: "lines", x: frames, y: chain.offset_deg, name: `${chain.joint} offset`, legendgroup: chain.joint,
      yaxis: "y2", line: { color, width: 1.6, dash: "dash" }, visible, hovertemplate: "%{y:.1f}°" });
  });
  if (twist.intervals.length) data.push(intervalBars(twist.intervals, fps, -180, 180, "y"));
  const layout = {
    margin: { l: 60, r: 10, t: 10, b: 40 }, barmode: "overlay", hovermode: "x",
    xaxis: { title: { text: "time (s)" }, anchor: "y2" },
    yaxis: { domain: [0.52, 1], title: { text: "twist θP (°)" }, range: [-185, 185] },
    yaxis2: { domain: [0, 0.45], title: { text: "removed offset (°)" } },
    legend: { orientation: "h", y: -0.25 },
    shapes: [cursorShape(timeS)],
  };
  return { data, layout };
}

export function limitsFigure(limits, fps, timeS) {
  // A take inside its limits everywhere stays white: the scale starts at 1° at least.
  const zmax = Math.max(1, ...limits.score_deg.map((row) => Math.max(...row)));
  const data = [{
    type: "heatmap", x: limits.frames.map((f) => f / fps), y: limits.joints, z: limits.score_deg,
    colorscale: [[0, "#f7f9fb"], [0.001, "#fde0c5"], [1, "#b30000"]], zmin: 0, zmax,
    colorbar: { title: { text: "outside (°)" } },
    hovertemplate: "%{y} at %{x:.2f} s: %{z:.1f}° outside<extra></extra>",
  }];
  const layout = {
    margin: { l: 120, r: 10, t: 10, b: 40 },
    xaxis: { title: { text: "time (s)" } }, yaxis: { automargin: true },
    shapes: [cursorShape(timeS)],
  };
  return { data, layout };
}

export function trajectoryFigure(frames, fps, raw, filtered, unit, timeS) {
  const t = frames.map((f) => f / fps);
  const data = [];
  ["x", "y", "z"].forEach((axis, a) => {
    data.push({ type: "scatter", mode: "lines", x: t, y: raw.map((p) => p[a]), name: `raw ${axis}`, line: { color: COLORS[a], width: 1, dash: "dot" } });
    data.push({ type: "scatter", mode: "lines", x: t, y: filtered.map((p) => p[a]), name: `filtered ${axis}`, line: { color: COLORS[a], width: 2 } });
  });
  const layout = { margin: { l: 60, r: 10, t: 10, b: 40 }, xaxis: { title: { text: "time (s)" } },
    yaxis: { title: { text: `position (${unit})` } }, legend: { orientation: "h", y: -0.25 }, shapes: [cursorShape(timeS)] };
  return { data, layout };
}

export function weightsFigure(frames, fps, weights, keypointIndex, timeS) {
  const t = frames.map((f) => f / fps);
  const labels = { kalman: "Kalman", one_euro: "One Euro", ema: "EMA" };
  const data = Object.entries(weights).map(([name, w], k) => ({
    type: "scatter", mode: "lines", stackgroup: "weights", x: t, name: labels[name] || name,
    y: keypointIndex == null ? w.mean : w.per_keypoint[keypointIndex], line: { width: 0.5, color: COLORS[k] },
    hovertemplate: "%{y:.2f}",
  }));
  const layout = { margin: { l: 60, r: 10, t: 10, b: 40 }, xaxis: { title: { text: "time (s)" } },
    yaxis: { title: { text: "filter weight (share)" }, range: [0, 1] }, legend: { orientation: "h", y: -0.25 }, shapes: [cursorShape(timeS)] };
  return { data, layout };
}
