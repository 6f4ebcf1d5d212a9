// Unit tests of the take view's pure functions: finding colours and marks, the frame drawn, the
// player's lines and link, and the keyboard's commands (node --test).
import assert from "node:assert/strict";
import { test } from "node:test";
import {
  byKind, clampFrame, findingColors, frameAt, frameText, keyCommand, LIMITS_COLOR, loopText, takeQuery, timeMarks, uncheckedSteps, viewLegend,
} from "../../frontend/js/take-format.js";

const f = (kind, joint, start, end) => ({ kind, joint, start_frame: start, end_frame: end });

test("a twist interval takes its chain's colour, drawn over a spin over a limits run", () => {
  const colorOf = findingColors(new Map([["R_Calf", "#123456"]]));
  assert.equal(colorOf(f("twist", "R_Calf", 0, 1)), "#123456");
  assert.equal(colorOf(f("twist", "L_Calf", 0, 1)), "#c0392b");
  assert.equal(colorOf(f("limits", "Spine", 0, 1)), LIMITS_COLOR);
  assert.notEqual(colorOf(f("gap", "LFHD", 0, 1)), LIMITS_COLOR);
  const ordered = [f("twist", "a", 0, 1), f("limits", "b", 0, 1), f("spin", "c", 0, 1)].sort(byKind);
  assert.deepEqual(ordered.map((x) => x.kind), ["limits", "spin", "twist"]);
  const marks = timeMarks([f("twist", "R_Calf", 3, 9), f("limits", "Spine", 1, 2)], colorOf);
  assert.deepEqual(marks.map((m) => [m.start, m.end, m.color]), [[1, 2, LIMITS_COLOR], [3, 9, "#123456"]]);
  assert.equal(marks[1].label, "twist · R_Calf · 3–9");
});

test("the frame drawn comes from the detail window when it holds the frame, else the overview", () => {
  const window = (start, step, n, tag) => ({
    frames: Array.from({ length: n }, (_, k) => start + k * step), step,
    raw: Array.from({ length: n }, (_, k) => `${tag}raw${k}`), corrected: Array.from({ length: n }, (_, k) => `${tag}cor${k}`),
  });
  const overview = window(0, 10, 10, "o"), detail = window(40, 1, 21, "d");
  const take = { oriented: false, intervals: [f("twist", "Knee", 45, 50)], jointIndex: new Map([["Knee", 2]]), colorOf: () => "red", selected: 2 };
  const inside = frameAt(detail, overview, 47, take);
  assert.deepEqual([inside.shown, inside.raw, inside.corrected], [47, "draw7", "dcor7"]);
  assert.deepEqual([...inside.flagged], [[2, "red"]]);
  assert.equal(inside.selected, 2);
  assert.equal(inside.rawRotations, null);
  assert.equal(inside.confidence, null);
  const outside = frameAt(detail, overview, 84, take);
  assert.deepEqual([outside.shown, outside.raw, outside.flagged.size], [80, "oraw8", 0]);
  assert.equal(frameAt(null, overview, 12, take).shown, 10);
});

test("the player's lines and the link say the frame, the range and the filter", () => {
  assert.equal(frameText(30, 121, 30, 2), "frame 30 / 120 · 1.00 s · 2 flagged joint(s)");
  assert.equal(loopText(null, false), "in/out: none (I / O or drag on the bar)");
  assert.equal(loopText([10, 19], true), "in 10 · out 19 (10 frames) · looping");
  const query = takeQuery("r1", { frame: 5, joint: "Knee", loop: [2, 8] }, { kinds: "twist", q: "calf" });
  assert.equal(String(query), "run=r1&frame=5&joint=Knee&loop=2-8&kinds=twist&q=calf");
  assert.equal(String(takeQuery("r1", { frame: 0, joint: null, loop: null }, {})), "run=r1&frame=0");
  assert.equal(clampFrame(-3, 10), 0);
  assert.equal(clampFrame(9.6, 10), 9);
  assert.equal(clampFrame(4.4, 10), 4);
});

test("steps that could not read the take are listed; the legend follows the take's kind", () => {
  const steps = { twist: { state: "no_roles" }, limits: { state: "no_model" }, filter: { state: "done" } };
  assert.deepEqual(uncheckedSteps(steps).map(([name]) => name), ["twist", "limits"]);
  assert.match(viewLegend(true, false), /parent joint's frame/);
  assert.match(viewLegend(false, true), /^markers/);
  assert.match(viewLegend(false, false), /^keypoints fade/);
});

test("keys map to the take view's commands", () => {
  assert.deepEqual(keyCommand(" ", false), { name: "play" });
  assert.deepEqual(keyCommand("ArrowRight", true), { name: "step", by: 10 });
  assert.deepEqual(keyCommand("ArrowLeft", false), { name: "step", by: -1 });
  assert.deepEqual(keyCommand("N", true), { name: "walk", dir: 1 });
  assert.deepEqual(keyCommand("p", false), { name: "walk", dir: -1 });
  assert.deepEqual([keyCommand("I", true).name, keyCommand("o", false).name], ["in", "out"]);
  // Shift+L loops the finding, l toggles the loop, an L without shift (caps lock) does nothing.
  assert.equal(keyCommand("L", true).name, "loop-finding");
  assert.equal(keyCommand("l", false).name, "loop");
  assert.equal(keyCommand("L", false), null);
  assert.equal(keyCommand("C", false).name, "close");
  assert.equal(keyCommand("y", false).name, "item");
  assert.equal(keyCommand("X", true).name, "item");
  assert.deepEqual(keyCommand("F", true), { name: "review", decision: "needs_fix" });
  assert.deepEqual(keyCommand("a", false), { name: "review", decision: "approved" });
  assert.deepEqual(keyCommand("r", false), { name: "review", decision: "rejected" });
  assert.equal(keyCommand("?", true).name, "help");
  for (const key of ["Enter", "Escape", "Tab", "z", "F1"]) assert.equal(keyCommand(key, false), null);
});
