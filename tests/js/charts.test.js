// The limits heat map shows each flagged cell's anatomical read-out on hover (node --test).
import assert from "node:assert/strict";
import { test } from "node:test";
import { limitsFigure } from "../../frontend/js/charts.js";

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
