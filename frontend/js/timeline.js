// The 2D charts under the 3D views: one time axis in frames, zoom linked across charts (double-
// click resets all), and a time cursor per chart drawn as an HTML line over the plot area, so
// moving it costs no Plotly redraw. Each chart keeps its full figure and hands Plotly only as
// many points as its plot has pixel columns (decimate.js); a zoom or pan re-decimates the
// shown range from the full data, so zooming in shows every sample.
import { decimateFigure, decimateTrace, decimated } from "./decimate.js";
import { h } from "./dom.js";
import { untabbableModebar } from "./plotly.js";

/** The zoom of one chart as the update that puts the others on the same x-range, or null when
 * a relayout event changes no x-range (`e`: Plotly's plotly_relayout event data). */
export function zoomUpdate(e) {
  if (e["xaxis.autorange"]) return { "xaxis.autorange": true };
  if (e["xaxis.range[0]"] !== undefined) return { "xaxis.range": [e["xaxis.range[0]"], e["xaxis.range[1]"]] };
  if (e["xaxis.range"]) return { "xaxis.range": e["xaxis.range"] };
  return null;
}

/** Place a chart's time cursor at `frame` (hidden when the frame is outside the shown range). */
function placeCursor(chart, frame) {
  const axis = chart.div._fullLayout && chart.div._fullLayout.xaxis;
  if (!axis) return;
  const [a, b] = axis.range;
  const inside = frame >= Math.min(a, b) && frame <= Math.max(a, b);
  chart.cursor.style.display = inside ? "block" : "none";
  if (!inside) return;
  const size = chart.div._fullLayout._size;
  chart.cursor.style.left = `${axis._offset + axis.l2p(frame)}px`;
  chart.cursor.style.top = `${size.t}px`;
  chart.cursor.style.height = `${size.h}px`;
}

/** The plot's width in pixels (before the first plot: the box less the figure's margins). */
function columnsOf(div, layout) {
  const size = div._fullLayout && div._fullLayout._size;
  const width = size ? size.w : div.clientWidth - layout.margin.l - layout.margin.r;
  return Math.max(50, Math.round(width));
}

/** Re-decimate a chart's lines and heat maps for the x-range it now shows. */
function redecimate(Plotly, chart) {
  const axis = chart.div._fullLayout && chart.div._fullLayout.xaxis;
  if (!axis) return;
  const range = axis.autorange ? null : axis.range.slice();
  const columns = columnsOf(chart.div, chart.figure.layout);
  const key = `${columns}:${range}`;
  if (key === chart.decimatedFor) return;
  chart.decimatedFor = key;
  // Lines get new x and y, heat maps new x and z: one restyle each.
  for (const kind of ["scatter", "heatmap"]) {
    const indices = [], update = { x: [], [kind === "heatmap" ? "z" : "y"]: [] };
    chart.figure.data.forEach((trace, i) => {
      if (trace.type !== kind || !decimated(trace)) return;
      const part = decimateTrace(trace, columns, range);
      indices.push(i);
      update.x.push(part.x);
      if (kind === "heatmap") update.z.push(part.z); else update.y.push(part.y);
    });
    if (indices.length) Plotly.restyle(chart.div, update, indices);
  }
}

export function createTimeline(Plotly, container, onJump) {
  const charts = [];
  let frame = 0, syncing = false;

  // A zoom or pan of one chart moves the others (not back again while they follow).
  const link = (source) => (e) => {
    const update = syncing ? null : zoomUpdate(e);
    if (!update) return;
    syncing = true;
    Promise.all(charts.filter((c) => c.div !== source).map((c) => Plotly.relayout(c.div, update)))
      .finally(() => { syncing = false; });
  };

  return {
    charts,
    async add(id, heading, figure, onClickFrame) {
      const div = h("div", { id, class: "chart" });
      const cursor = h("div", { class: "time-cursor", "aria-hidden": "true" });
      container.append(h("div", { class: "panel" }, h("h2", {}, heading), h("div", { class: "chart-box" }, div, cursor)));
      const began = performance.now();
      const columns = columnsOf(div, figure.layout);
      const shown = decimateFigure(figure, columns);
      await Plotly.newPlot(div, shown.data, shown.layout, { displaylogo: false, responsive: true });
      performance.measure(`plot ${id}`, { start: began });
      untabbableModebar(div);
      const chart = { div, cursor, figure, decimatedFor: `${columns}:null` };
      charts.push(chart);
      div.on("plotly_click", (e) => {
        const bar = e.points.find((p) => p.customdata !== undefined);
        const f = onClickFrame(bar || e.points[0]);
        if (f != null) onJump(Math.round(f));
      });
      div.on("plotly_relayout", link(div));
      div.on("plotly_relayout", () => redecimate(Plotly, chart));
      div.on("plotly_afterplot", () => placeCursor(chart, frame));
      placeCursor(chart, frame);
      return div;
    },
    /** Show a new figure in chart `id` (full data kept, decimated for its plot width). */
    replace(id, figure) {
      const chart = charts.find((c) => c.div.id === id);
      const columns = columnsOf(chart.div, figure.layout);
      chart.figure = figure;
      chart.decimatedFor = `${columns}:null`;
      const shown = decimateFigure(figure, columns);
      return Plotly.react(chart.div, shown.data, shown.layout);
    },
    setFrame(value) {
      frame = value;
      for (const chart of charts) placeCursor(chart, frame);
    },
  };
}
