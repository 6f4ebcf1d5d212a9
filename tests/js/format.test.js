// Unit tests of the pure formatting and ordering helpers (node --test).
import assert from "node:assert/strict";
import { test } from "node:test";
import * as format from "../../frontend/js/format.js";

const finding = (start, value) => ({ kind: "twist", joint: "knee", start_frame: start, end_frame: start + 2, value, confidence: 0.5 });

test("offsets sort by magnitude: −77° is larger than +2°", () => {
  const rows = [finding(1, 2), finding(2, -77), finding(3, 10), finding(4, null)];
  assert.deepEqual(format.sortFindings(rows, "value", 1).map((f) => f.value), [2, 10, -77, null]);
  assert.deepEqual(format.sortFindings(rows, "value", -1).map((f) => f.value), [-77, 10, 2, null]);
});

test("seconds carry the precision one frame needs", () => {
  assert.equal(format.seconds(61, 60), "1.02 s");
  assert.equal(format.seconds(5, 10), "0.5 s");
  assert.equal(format.seconds(1, 240), "0.004 s");
});

test("the run label names the steps that ran, not the ones requested", () => {
  const run = { status: "done", options: { checks: ["twist", "limits", "filter"] }, summary: { steps: { twist: "done", limits: "skipped", filter: "skipped" } } };
  assert.equal(format.stepsRan(run), "twist");
  assert.equal(format.stepsRan({ ...run, summary: { steps: { twist: "skipped" } } }), "no step ran");
});

test("each kind of take is offered the checks the server says it can run", () => {
  const described = {
    take_checks: { motion: ["twist", "limits", "filter"], markers: ["markers", "filter"], keypoints: ["filter"] },
    marker_formats: ["c3d", "trc"],
  };
  assert.deepEqual(format.checksFor({ kind: "keypoints", format: "openpose" }, described), ["filter"]);
  assert.deepEqual(format.checksFor({ kind: "keypoints", format: "c3d" }, described), ["markers", "filter"]);
  assert.deepEqual(format.checksFor({ kind: "keypoints", format: "trc" }, described), ["markers", "filter"]);
  assert.deepEqual(format.checksFor({ kind: "motion", format: "bvh" }, described), ["twist", "limits", "filter"]);
});

test("N/P walk the findings one at a time in time order, two on one frame included", () => {
  const [a, b, c] = [finding(30, 1), finding(10, 1), finding(30, 2)];
  const list = [a, b, c];
  assert.equal(format.nextFinding(list, null, 0, 1), b);
  assert.equal(format.nextFinding(list, b, 10, 1), a);
  assert.equal(format.nextFinding(list, a, 30, 1), c); // same start frame: its own stop
  assert.equal(format.nextFinding(list, c, 30, 1), null);
  assert.equal(format.nextFinding(list, c, 30, -1), a);
  assert.equal(format.nextFinding(list, a, 30, -1), b);
  assert.equal(format.nextFinding(list, b, 10, -1), null);
  // Moved away from the current finding's start: from the frame, not from the finding.
  assert.equal(format.nextFinding(list, b, 20, 1), a);
  assert.equal(format.nextFinding(list, a, 40, -1), c);
  assert.equal(format.nextFinding(list, null, 5, -1), null);
  assert.equal(format.nextFinding([], null, 5, 1), null);
});

test("findings of two runs are matched by kind, joint and overlapping frames", () => {
  const a = [finding(10, 5), { ...finding(40, 2), joint: "hip" }, finding(100, 1)];
  const b = [finding(11, 4), finding(60, 3)];
  const m = format.matchFindings(a, b);
  assert.deepEqual(m.both.map(([x, y]) => [x.start_frame, y.start_frame]), [[10, 11]]);
  assert.deepEqual(m.onlyA.map((f) => f.start_frame), [40, 100]);
  assert.deepEqual(m.onlyB.map((f) => f.start_frame), [60]);
});

test("the options diff lists only what differs, as readable values", () => {
  const a = { checks: ["twist", "limits"], twist_method: "robust", filter_params: { beta: 1 } };
  const b = { checks: ["twist"], twist_method: "robust", filter_params: { beta: 2 }, filter_method: "butterworth" };
  assert.deepEqual(format.optionsDiff(a, b), [
    ["checks", "twist, limits", "twist"],
    ["filter_method", "–", "butterworth"],
    ["filter_params.beta", "1", "2"],
  ]);
});

test("the options diff compares the checks as sets: their order is no difference", () => {
  const a = { checks: ["twist", "limits", "feet", "filter"], twist_method: "robust" };
  const b = { checks: ["twist", "limits", "filter", "markers", "feet"], twist_method: "robust" };
  assert.deepEqual(format.optionsDiff(a, { ...a, checks: ["filter", "feet", "twist", "limits"] }), []);
  // markers is a difference, unless its step did nothing (a motion take has no markers).
  assert.deepEqual(format.optionsDiff(a, b), [["checks", "twist, limits, feet, filter", "twist, limits, filter, markers, feet"]]);
  assert.deepEqual(format.optionsDiff(a, b, ["markers"]), []);
  assert.deepEqual(format.optionsDiff({ checks: ["twist"] }, { checks: ["twist", "twist"] }), []);
  assert.deepEqual(format.optionsDiff({ checks: ["twist", "limits"] }, { checks: ["twist", "feet"] }), [["checks", "twist, limits", "twist, feet"]]);
});

test("idleChecks names the checks skipped in every run that asked for them", () => {
  const run = (checks, steps) => ({ options: { checks }, steps: Object.fromEntries(Object.entries(steps).map(([k, state]) => [k, { state }])) });
  const a = run(["twist", "limits", "feet", "filter"], { twist: "done", limits: "done", feet: "done", filter: "skipped" });
  const b = run(["twist", "limits", "filter", "markers", "feet"], { twist: "done", limits: "done", feet: "done", filter: "skipped", markers: "skipped" });
  assert.deepEqual(format.idleChecks(a, b).sort(), ["filter", "markers"]);
  // A check that ran in one run and is missing from the other is a difference.
  const c = run(["twist", "feet"], { twist: "done", feet: "done" });
  assert.deepEqual(format.idleChecks(a, c), ["filter"]);
  // Shown without the idle checks: what is compared.
  assert.deepEqual(format.optionsDiff(a.options, c.options, format.idleChecks(a, c)), [["checks", "twist, limits, feet", "twist, feet"]]);
});

test("sortFindings takes other sort keys alike", () => {
  const rows = [{ start_frame: 1, confidence: 0.9 }, { start_frame: 2, confidence: 0.1, moved: 0.95 }];
  const keys = { ...format.FINDING_KEYS, confidence: (f) => f.moved ?? f.confidence };
  assert.deepEqual(format.sortFindings(rows, "confidence", 1).map((f) => f.start_frame), [2, 1]);
  assert.deepEqual(format.sortFindings(rows, "confidence", 1, keys).map((f) => f.start_frame), [1, 2]);
});

test("runOptionsLabel tells two runs of a take apart by what differs", () => {
  const done = (options, steps) => ({ status: "done", options, summary: { steps } });
  const ran = { twist: "done", limits: "done", filter: "skipped" };
  const described = { groups: [{ name: "twist", fields: [{ name: "twist_apply", type: "choice", default: "confident" }] }] };
  assert.equal(format.runOptionsLabel(done({ checks: ["twist", "limits"], twist_apply: "confident" }, ran), described), "twist+limits");
  assert.equal(format.runOptionsLabel(done({ checks: ["twist", "limits"], twist_apply: "all" }, ran), described), "twist+limits · apply all");
  assert.equal(format.runOptionsLabel(done({ checks: ["twist", "limits", "filter"], twist_apply: "none", filter_method: "quat-pd" }, { ...ran, filter: "done" }), described), "twist+limits+filter · apply none · quat-pd");
  const withFeet = { groups: [...described.groups, { name: "feet", fields: [{ name: "feet_apply", type: "choice", default: "none" }] }] };
  assert.equal(format.runOptionsLabel(done({ checks: ["twist", "limits"], twist_apply: "confident", feet_apply: "none" }, ran), withFeet), "twist+limits");
  assert.equal(format.runOptionsLabel(done({ checks: ["twist", "limits", "feet"], twist_apply: "confident", feet_apply: "confident" }, { ...ran, feet: "done" }), withFeet), "twist+limits+feet · feet locked confident");
  // Without the feet step the choice locked nothing, and the label does not claim it did.
  assert.equal(format.runOptionsLabel(done({ checks: ["twist", "limits"], twist_apply: "confident", feet_apply: "confident" }, ran), withFeet), "twist+limits");
  assert.equal(format.runOptionsLabel(done({ checks: ["feet"], feet_apply: "skates" }, { feet: "skipped" }), withFeet), "no step ran");
});
