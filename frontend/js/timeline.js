// The 2D charts under the 3D views: one time axis in frames, zoom linked across charts (double-
// click resets all), and a time cursor per chart drawn as an HTML line over the plot area, so
// moving it costs no Plotly redraw.
import { h } from "./dom.js";
import { untabbableModebar } from "./plotly.js";

export function createTimeline(Plotly, container, onJump) {
  const charts = [];
  let frame = 0, syncing = false;

  const placeCursor = (chart) => {
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
  };

  const link = (source) => (e) => {
    if (syncing) return;
    let update = null;
    if (e["xaxis.autorange"]) update = { "xaxis.autorange": true };
    else if (e["xaxis.range[0]"] !== undefined) update = { "xaxis.range": [e["xaxis.range[0]"], e["xaxis.range[1]"]] };
    else if (e["xaxis.range"]) update = { "xaxis.range": e["xaxis.range"] };
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
      await Plotly.newPlot(div, figure.data, figure.layout, { displaylogo: false, responsive: true });
      untabbableModebar(div);
      const chart = { div, cursor };
      charts.push(chart);
      div.on("plotly_click", (e) => {
        const bar = e.points.find((p) => p.customdata !== undefined);
        const f = onClickFrame(bar || e.points[0]);
        if (f != null) onJump(Math.round(f));
      });
      div.on("plotly_relayout", link(div));
      div.on("plotly_afterplot", () => placeCursor(chart));
      placeCursor(chart);
      return div;
    },
    setFrame(value) {
      frame = value;
      for (const chart of charts) placeCursor(chart);
    },
  };
}
