// Figure builders of the take view's charts (node --test): the limits heat map's hover, the twist legend.
import assert from "node:assert/strict";
import { test } from "node:test";
import { limitsFigure, twistFigure } from "../../frontend/js/charts.js";

const series = {
  joints: ["right_lower_leg", "left_hand"], frames: [0, 10],
  score_deg: [[0, 14.2], [0, 0]],
  readout: [["", "right knee hyperextended 14°"], ["", ""]],
};

test("the heat map's hover carries the read-out of each cell", () => {
  const [trace] = limitsFigure(series).data;
  assert.deepEqual(trace.customdata, series.readout);
  assert.match(trace.hovertemplate, /%\{customdata\}/);
  assert.equal(trace.zmax, 14.2);
});

test("a series without read-outs (an older run) hovers with the degrees only", () => {
  const { readout, ...older } = series;
  assert.ok(readout);
  const [trace] = limitsFigure(older).data;
  assert.equal(trace.customdata, undefined);
  assert.doesNotMatch(trace.hovertemplate, /customdata/);
});

test("the twist chart lists each chain once in its legend; its name toggles both lines", () => {
  const twist = {
    frames: [0, 1, 2],
    chains: ["L_Calf", "R_Calf", "L_Thigh"].map((joint) => ({ joint, theta_p_deg: [0, 1, 2], offset_deg: [0, 0, 0] })),
    intervals: [{ joint: "R_Calf", start_frame: 1, end_frame: 1 }],
  };
  const { data, layout } = twistFigure(twist);
  const listed = data.filter((t) => t.type === "scatter" && t.showlegend !== false).map((t) => t.name);
  assert.deepEqual(listed, ["L_Calf", "R_Calf", "L_Thigh"]);
  for (const joint of listed) {
    const lines = data.filter((t) => t.type === "scatter" && t.legendgroup === joint);
    assert.equal(lines.length, 2);
    assert.equal(new Set(lines.map((t) => t.visible)).size, 1); // shown or hidden together
  }
  // Only the chain with a flagged interval is drawn at first.
  assert.deepEqual(data.filter((t) => t.visible === true).map((t) => t.legendgroup), ["R_Calf", "R_Calf"]);
  assert.match(layout.legend.title.text, /solid.*dashed/);
});

test("limb spins are hatched bands on their limb's chain, shown and hidden with it", () => {
  const twist = {
    frames: [0, 1, 2, 3],
    chains: ["R_Upperarm", "L_Calf"].map((joint) => ({ joint, theta_p_deg: [0, 0, 0, 0], offset_deg: [0, 0, 0, 0] })),
    intervals: [{ joint: "L_Calf", start_frame: 1, end_frame: 1 }],
  };
  const spins = [
    { kind: "spin", joint: "R_Upperarm", start_frame: 2, end_frame: 3 },
    { kind: "spin", joint: "R_Hand", start_frame: 0, end_frame: 0 }, // no chain: not drawn
  ];
  const { data } = twistFigure(twist, spins);
  const bands = data.filter((t) => t.type === "bar" && /spin/.test(t.hovertemplate));
  assert.equal(bands.length, 1);
  assert.equal(bands[0].legendgroup, "R_Upperarm");
  assert.deepEqual(bands[0].customdata, [[2, 3, "R_Upperarm"]]);
  assert.equal(bands[0].marker.pattern.shape, "/");
  // R_Upperarm has no twist interval, but a spin: its chain is drawn at first, band and all.
  assert.equal(bands[0].visible, true);
  assert.deepEqual([...new Set(data.filter((t) => t.visible === true).map((t) => t.legendgroup))].sort(), ["L_Calf", "R_Upperarm"]);
});
