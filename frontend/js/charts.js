// Pure Plotly figure builders for the 2D charts: data in, {data, layout} out. No DOM.
// Time is in frames everywhere (as in the findings table); every chart has the same left and
// right margins so the plot areas, and the time cursors drawn over them, line up.

import { PALETTE } from "./format.js";

// The top margin holds the chart's toolbar (shown on hover), so it covers no data.
export const MARGIN = { l: 170, r: 120, t: 30, b: 40 };
/** Limb spins and flips (reported, never corrected), on the charts and the time bar. */
export const SPIN_COLOR = "#8e44ad";
const frameAxis = () => ({ title: { text: "frame" }, tickformat: "d" });

function intervalBars(intervals, yBase, yTop, yaxis, color, name) {
  return {
    type: "bar", name, yaxis, legendgroup: name, showlegend: false,
    x: intervals.map((i) => (i.start_frame + i.end_frame + 1) / 2),
    width: intervals.map((i) => Math.max(i.end_frame - i.start_frame + 1, 2)),
    y: intervals.map(() => yTop - yBase), base: intervals.map(() => yBase),
    marker: { color, opacity: 0.25 },
    customdata: intervals.map((i) => [i.start_frame, i.end_frame, i.joint]),
    hovertemplate: "%{customdata[2]}: frames %{customdata[0]}–%{customdata[1]}<extra>flagged</extra>",
  };
}

/** Chain colours: one per twist chain (joint name), in the order of the chains. */
// Purple and orange are the spins' and the limits' colours: a chain never takes them.
const CHAIN_PALETTE = PALETTE.filter((c) => c !== "#9467bd" && c !== "#ff7f0e");
export const chainColors = (twist) => new Map(twist.chains.map((c, k) => [c.joint, CHAIN_PALETTE[k % CHAIN_PALETTE.length]]));

/** The twist chart: θP and the removed offset per chain, the flagged intervals as bands in
 * their chain's colour, and limb spins (`spins`: findings of kind "spin", reported and never
 * corrected) as hatched purple bands on the chain of the limb's upper segment. */
export function twistFigure(twist, spins = []) {
  const frames = twist.frames;
  const colors = chainColors(twist);
  // Drawn at first: the chains with a flagged interval or a limb spin (else the first two).
  const chainJoints = new Set(twist.chains.map((c) => c.joint));
  const affected = new Set([...twist.intervals, ...spins.filter((s) => chainJoints.has(s.joint))].map((i) => i.joint));
  const data = [];
  twist.chains.forEach((chain, k) => {
    const visible = affected.size === 0 ? (k < 2 ? true : "legendonly") : (affected.has(chain.joint) ? true : "legendonly");
    const color = colors.get(chain.joint);
    // One legend entry per chain (its name toggles both of its lines): a 100-joint rig has ten
    // chains, and two entries each filled more of a narrow window than the plot did.
    data.push({ type: "scatter", mode: "lines", x: frames, y: chain.theta_p_deg, name: chain.joint, legendgroup: chain.joint,
      line: { color, width: 1.2 }, visible, hovertemplate: `${chain.joint} θP, frame %{x}: %{y:.1f}°<extra></extra>` });
    data.push({ type: "scatter", mode: "lines", x: frames, y: chain.offset_deg, name: `${chain.joint} offset`, legendgroup: chain.joint,
      showlegend: false, yaxis: "y2", line: { color, width: 1.6, dash: "dash" }, visible,
      hovertemplate: `${chain.joint} removed offset, frame %{x}: %{y:.1f}°<extra></extra>` });
  });
  // One band trace per chain, in that chain's colour.
  for (const joint of affected) {
    const own = twist.intervals.filter((i) => i.joint === joint);
    if (own.length) data.push(intervalBars(own, -180, 180, "y", colors.get(joint) || PALETTE[3], joint));
  }
  const shown = (joint) => data.find((t) => t.legendgroup === joint && t.type === "scatter")?.visible ?? "legendonly";
  for (const joint of new Set(spins.map((s) => s.joint))) {
    if (!colors.has(joint)) continue;
    const own = spins.filter((s) => s.joint === joint);
    data.push({
      ...intervalBars(own, -180, 180, "y", SPIN_COLOR, joint),
      marker: { color: SPIN_COLOR, opacity: 0.3, pattern: { shape: "/", fgcolor: SPIN_COLOR } },
      visible: shown(joint),
      hovertemplate: "%{customdata[2]}: frames %{customdata[0]}–%{customdata[1]}<extra>limb spin (not corrected)</extra>",
    });
  }
  const layout = {
    margin: MARGIN, barmode: "overlay", hovermode: "x",
    xaxis: { ...frameAxis(), anchor: "y2" },
    // Short axis titles: two long ones overlapped each other beside half-height panels.
    yaxis: { domain: [0.52, 1], title: { text: "θP (°)" }, range: [-185, 185] },
    yaxis2: { domain: [0, 0.45], title: { text: "offset (°)" } },
    legend: { orientation: "h", y: -0.3, yanchor: "top", font: { size: 11 },
      title: { text: `solid: twist θP · dashed: removed offset${spins.length ? " · hatched: limb spin (not corrected)" : ""}`, side: "top" } },
  };
  return { data, layout };
}

export function limitsFigure(limits) {
  // A take inside its limits everywhere stays white: the scale starts at 1° at least.
  const zmax = Math.max(1, ...limits.score_deg.map((row) => Math.max(...row)));
  const data = [{
    type: "heatmap", x: limits.frames, y: limits.joints, z: limits.score_deg,
    colorscale: [[0, "#f7f9fb"], [0.001, "#fde0c5"], [1, "#b30000"]], zmin: 0, zmax,
    // The title runs along the bar: on top it sat under the chart's toolbar.
    colorbar: { title: { text: "outside (°)", side: "right" }, thickness: 14, x: 1.01, xpad: 4 },
    // The anatomical read-out of each flagged cell ("right knee hyperextended 14°"), when sent.
    ...(limits.readout ? { customdata: limits.readout } : {}),
    hovertemplate: `%{y} at frame %{x:.0f}: %{z:.1f}° outside${limits.readout ? "<br>%{customdata}" : ""}<extra></extra>`,
  }];
  const layout = { margin: MARGIN, xaxis: frameAxis(), yaxis: { automargin: false, tickfont: { size: 10 } } };
  return { data, layout };
}

export function trajectoryFigure(frames, raw, filtered, unit) {
  // One panel per axis, each with its own y-range, so the noise the filter removes shows.
  const data = [];
  ["x", "y", "z"].forEach((axis, a) => {
    const yaxis = a === 0 ? "y" : `y${a + 1}`;
    data.push({ type: "scatter", mode: "lines", x: frames, y: raw.map((p) => p[a]), name: `raw ${axis}`, yaxis, line: { color: PALETTE[a], width: 1, dash: "dot" } });
    data.push({ type: "scatter", mode: "lines", x: frames, y: filtered.map((p) => p[a]), name: `filtered ${axis}`, yaxis, line: { color: PALETTE[a], width: 2 } });
  });
  const layout = { margin: MARGIN, xaxis: { ...frameAxis(), anchor: "y3" }, legend: { orientation: "h", y: -0.25 },
    yaxis: { domain: [0.68, 1], title: { text: `x (${unit})` } },
    yaxis2: { domain: [0.34, 0.64], title: { text: `y (${unit})` } },
    yaxis3: { domain: [0, 0.3], title: { text: `z (${unit})` } } };
  return { data, layout };
}

export function weightsFigure(frames, weights, keypointIndex) {
  const labels = { kalman: "Kalman", one_euro: "One Euro", ema: "EMA" };
  const data = Object.entries(weights).map(([name, w], k) => ({
    type: "scatter", mode: "lines", stackgroup: "weights", x: frames, name: labels[name] || name,
    y: keypointIndex == null ? w.mean : w.per_keypoint[keypointIndex], line: { width: 0.5, color: PALETTE[k] },
    hovertemplate: "%{y:.2f}",
  }));
  const layout = { margin: MARGIN, xaxis: frameAxis(),
    yaxis: { title: { text: "filter weight (share)" }, range: [0, 1] }, legend: { orientation: "h", y: -0.25 } };
  return { data, layout };
}
