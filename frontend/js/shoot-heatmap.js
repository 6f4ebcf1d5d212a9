// The shoot view's heat map: the share of frames outside the joint limits, joint × take, for
// the take table's takes (its filters, sort and order) `limit` at a time. The chart scrolls
// inside its box, and the pager keeps its place across polls. A redraw started later wins over
// one still waiting for its answer (typing in the search).
import * as api from "./api.js";
import { h } from "./dom.js";
import { fmt } from "./format.js";
import { loadPlotly, untabbableModebar } from "./plotly.js";
import {
  HEATMAP_COLORSCALE, HEATMAP_SIZES, HEATMAP_TICK_ANGLE, heatmapFigure, heatmapKeyGradient, heatmapPage, heatmapPager, heatmapQuery,
  isFiltered, scoreRangeProblem,
} from "./shoot-format.js";

/** Plotly's traces and layout of a heat map figure (heatmapFigure): the cells, and an unseen
 * trace that only gives the joints' axis above the cells its categories. */
export function heatmapPlot(figure) {
  const joints = { ...figure.xaxis, tickangle: HEATMAP_TICK_ANGLE, automargin: true };
  const data = [{
    type: "heatmap", x: figure.x, y: figure.y, z: figure.z, text: figure.text,
    colorscale: HEATMAP_COLORSCALE, zmin: 0, zmax: figure.zmax, hoverongaps: false, showscale: false,
    hovertemplate: "%{text}<br>%{x}: %{z:.1f} % of frames outside<extra></extra>",
  }, { // no data to draw: it only gives the joints' axis above the cells its categories
    type: "scatter", mode: "markers", x: figure.x, y: figure.x.map(() => figure.y[0]), xaxis: "x2",
    marker: { opacity: 0 }, hoverinfo: "skip", showlegend: false,
  }];
  const layout = {
    height: figure.height, margin: figure.margin,
    yaxis: { ...figure.yaxis, automargin: true },
    xaxis: { ...joints, side: "bottom" },
    xaxis2: { ...joints, side: "top", overlaying: "x", matches: "x" },
  };
  return { data, layout };
}

/** The heat map's pager: previous, the page's takes, next, and the page size. */
function heatmapControls(heat, pager, go, resize) {
  const previous = h("button", { type: "button", id: "heatmap-previous", disabled: pager.previous == null, onclick: () => go(pager.previous) }, "‹ previous");
  const next = h("button", { type: "button", id: "heatmap-next", disabled: pager.next == null, onclick: () => go(pager.next) }, "next ›");
  const size = h("select", { id: "heatmap-size", "aria-label": "takes per heat map page", onchange: (e) => resize(e.target.value) },
    HEATMAP_SIZES.map((n) => h("option", { value: n, selected: n === heat.limit }, `${n} takes a page`)));
  return h("div", { class: "controls", id: "heatmap-pager" }, previous, h("span", { id: "heatmap-page", "aria-live": "polite" }, pager.text), next, size);
}

/** The scrolling box of the chart. The colour key stays in view at its top (the chart's own
 * colour bar would scroll away with a tall page); the joints are labelled above and below the
 * cells. */
function heatmapBox(figure, chart) {
  chart.style.minWidth = `${figure.minWidth}px`; // every joint column keeps its room: the box scrolls sideways instead
  const bar = h("span", { class: "heatmap-key-bar" });
  bar.style.background = heatmapKeyGradient();
  const key = h("div", { class: "heatmap-key", id: "heatmap-key" }, "share of frames outside the limits: ",
    h("span", {}, "0 %"), bar, h("span", { id: "heatmap-key-max" }, `${fmt(figure.zmax, 1)} %`));
  return h("div", { class: "heatmap-scroll", id: "heatmap-scroll", tabindex: "0", "aria-label": "heat map, scrolls" }, key, chart);
}

/**
 * @param shootId   the shoot
 * @param getState  the take table's state now (tableState)
 * @param isAlive   false once the view is gone: a late answer draws nothing
 * @returns {el, draw(), show(), firstPage()} the panel; draw it again (a promise that fails
 *   with the request); the same, an error said in the panel; back to its first page and show it
 */
export function createHeatmap(shootId, getState, isAlive) {
  const el = h("div", { id: "shoot-heatmap", class: "panel" });
  let heat = heatmapPage(0, 200);
  let heatDrawn = 0;
  const showError = (e) => el.replaceChildren(h("p", { class: "error" }, e.message));
  const empty = (why, ...above) => el.replaceChildren(...above, h("p", { class: "muted", id: "heatmap-empty" }, why));
  const draw = async () => {
    const ticket = ++heatDrawn;
    const shown = getState();
    const problem = scoreRangeProblem(shown);
    if (problem) { empty(`No take matches the table's filters: ${problem.text}.`, h("h2", {}, "Joint limits")); return; } // as the table: no request, the reason in words
    const [Plotly, first] = await Promise.all([loadPlotly(), api.shootHeatmap(shootId, heatmapQuery(heat, shown))]);
    let data = first;
    const safe = heatmapPage(heat.offset, heat.limit, data.total);
    if (safe.offset !== heat.offset) { // the shoot shrank under the page: show its last page
      heat = safe;
      data = await api.shootHeatmap(shootId, heatmapQuery(heat, shown));
    }
    if (!isAlive() || ticket !== heatDrawn) return;
    el.dataset.query = heatmapQuery(heat, shown);
    const title = h("h2", {}, "Share of frames outside the joint limits (joint × take, in the table's order and filters)");
    if (!data.total) { empty(isFiltered(shown) ? "No take matches the table's filters." : "No joint-limit results yet.", h("h2", {}, "Joint limits")); return; }
    const redraw = (offset, limit) => { heat = heatmapPage(offset, limit, data.total); draw().catch(showError); };
    const controls = heatmapControls(heat, heatmapPager(heat, data.total), (offset) => redraw(offset, heat.limit), (limit) => redraw(heat.offset, limit));
    if (!data.joints.length) { empty("No joint outside its limits in these takes.", title, controls); return; }
    const figure = heatmapFigure(data, heat.offset);
    const chart = h("div", { id: "heatmap-chart", "data-offset": heat.offset });
    el.replaceChildren(title, controls, heatmapBox(figure, chart));
    const { data: traces, layout } = heatmapPlot(figure);
    await Plotly.newPlot(chart, traces, layout, { responsive: true, displaylogo: false });
    untabbableModebar(chart);
  };
  return {
    el,
    draw,
    show: () => draw().catch(showError),
    firstPage() { heat = heatmapPage(0, heat.limit); draw().catch(showError); },
  };
}
