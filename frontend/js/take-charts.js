// The take view's charts under the player, drawn once the skeletons are on screen: the twist
// chains, the joint-limit heat map, and for keypoints the raw vs filtered trajectory and the
// filter's weights. Each chart in a task of its own: a key press or a drag waits for one chart,
// not all.
import * as charts from "./charts.js";
import { h } from "./dom.js";
import { loadPlotly } from "./plotly.js";
import * as store from "./state.js";
import { focusCharts, jump } from "./take-controls.js";
import { createTimeline } from "./timeline.js";

const breathe = () => new Promise((r) => setTimeout(r, 0));

/** The twist chains (θP and the removed offset), their intervals and the limb spins. */
function twistChart(t) {
  const { result } = t;
  const twist = result.series.twist;
  const spins = result.findings.filter((f) => f.kind === "spin");
  return t.timeline.add("chart-twist", `Twist θP and removed offset (${twist.intervals.length} flagged interval(s)${spins.length ? `, ${spins.length} limb spin(s)` : ""})`,
    charts.twistFigure(twist, spins), (p) => {
      if (p.customdata) return p.customdata[0];
      const inside = twist.intervals.find((i) => i.start_frame <= p.x && p.x <= i.end_frame + 1);
      return inside ? inside.start_frame : p.x;
    });
}

/** The joint-limit heat map; a cell selects its joint as well as its frame. Without one, the
 * limits step's message (unless it was skipped). */
async function limitsChart(t) {
  const { result } = t;
  if (result.series.limits) {
    await t.timeline.add("chart-limits", "Joint-limit violations (joint × frame, degrees outside the limits)", charts.limitsFigure(result.series.limits),
      (p) => { if (t.jointIndex.has(p.y)) { store.set({ joint: p.y }); focusCharts(t); } return p.x; });
  } else if (result.steps.limits && result.steps.limits.state !== "skipped") {
    t.timelines.append(h("p", { class: "muted", id: "limits-note" }, `Joint limits: ${result.steps.limits.message}`));
  }
}

/** A keypoint take's chosen keypoint: its raw vs filtered trajectory and the filter's weights.
 * The trajectory waits for the full overview (which the views then draw too). */
async function keypointCharts(t) {
  const { result, names, timeline } = t;
  const series = result.series;
  const choice = h("select", { id: "keypoint-pick", "aria-label": "keypoint" }, names.map((n, i) => h("option", { value: i }, n)));
  t.timelines.append(h("div", { class: "controls" }, "keypoint ", choice));
  const k = () => Number(choice.value);
  t.overview = await t.fuller;
  const trajectory = () => charts.trajectoryFigure(t.overview.frames, t.overview.raw.map((p) => p[k()]), t.overview.corrected.map((p) => p[k()]), result.summary.length_unit);
  await breathe();
  await timeline.add("chart-trajectory", "Raw vs filtered trajectory (one panel per axis)", trajectory(), (p) => p.x);
  const weights = series.filter && Object.keys(series.filter.weights).length ? series.filter.weights : null;
  await breathe();
  if (weights) await timeline.add("chart-weights", "Filter weights (stacked: Kalman / One Euro / EMA)", charts.weightsFigure(series.frames, weights, k()), (p) => p.x);
  choice.addEventListener("change", () => {
    timeline.replace("chart-trajectory", trajectory());
    if (weights) timeline.replace("chart-weights", charts.weightsFigure(series.frames, weights, k()));
  });
}

/** Load the charting library (a long script to evaluate) once the skeletons are on screen, then
 * draw the run's charts into `t.timelines`. */
export async function drawCharts(t) {
  await new Promise((r) => requestAnimationFrame(() => setTimeout(r, 0)));
  t.Plotly = await loadPlotly();
  t.timeline = createTimeline(t.Plotly, t.timelines, (f) => jump(t, f));
  window.mocapqaCharts = t.timeline; // the browser tests compare the drawn charts with their full data
  await breathe();
  if (t.result.series.twist) await twistChart(t);
  await breathe();
  await limitsChart(t);
  if (t.result.kind === "keypoints") await keypointCharts(t);
  t.timeline.setFrame(store.state.frame);
  focusCharts(t);
}
