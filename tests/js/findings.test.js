// Unit tests of the findings list's pure functions, the time bar's helpers, loop playback and
// the camera's focus (node --test).
import assert from "node:assert/strict";
import { test } from "node:test";
import * as findings from "../../frontend/js/findings.js";
import { focusDistance, focusTarget } from "../../frontend/js/geometry.js";
import { playbackFrame } from "../../frontend/js/player.js";
import { frameAtX, runsOf, spanOf, withIn, withOut } from "../../frontend/js/timebar.js";

const f = (kind, joint, start, end, value, readout) => ({ kind, joint, start_frame: start, end_frame: end, value, unit: "deg", confidence: 0.5, readout });
const rows = [
  f("twist", "R_Calf", 10, 20, -77), f("limits", "R_Calf", 50, 60, 5), f("twist", "L_Calf", 30, 35, 12),
  f("limits", "Spine", 5, 8, 40, "flexion 40° past"), f("limits", "L_Calf", 70, 71, null),
];

test("filters keep kinds, one joint, a smallest magnitude and words", () => {
  assert.equal(findings.filterFindings(rows, {}).length, 5);
  assert.deepEqual(findings.filterFindings(rows, { kinds: new Set(["twist"]) }).map((x) => x.start_frame), [10, 30]);
  assert.deepEqual(findings.filterFindings(rows, { joint: "L_Calf" }).map((x) => x.start_frame), [30, 70]);
  // −77° is 77° away: magnitude, not the signed value; a finding without a value drops out.
  assert.deepEqual(findings.filterFindings(rows, { minValue: 12 }).map((x) => x.start_frame), [10, 30, 5]);
  assert.deepEqual(findings.filterFindings(rows, { text: "calf TWIST" }).map((x) => x.start_frame), [10, 30]);
  assert.deepEqual(findings.filterFindings(rows, { text: "flexion" }).map((x) => x.joint), ["Spine"]);
  assert.deepEqual(findings.filterFindings(rows, { text: "50–60" }).map((x) => x.start_frame), [50]);
  assert.equal(findings.filterFindings(rows, { kinds: new Set(["twist"]), joint: "Spine" }).length, 0);
});

test("groups by joint carry counts, the worst magnitude and the kinds, sorted alike", () => {
  const byStart = findings.groupByJoint(rows);
  assert.deepEqual(byStart.map((g) => g.joint), ["Spine", "R_Calf", "L_Calf"]);
  const calf = byStart.find((g) => g.joint === "R_Calf");
  assert.equal(calf.count, 2);
  assert.equal(calf.worst, 77);
  assert.deepEqual([...calf.kinds], ["twist", "limits"]);
  assert.equal(byStart.find((g) => g.joint === "L_Calf").worst, 12);
  // Sorted by magnitude, largest first: the joint of the worst finding leads, rows in order.
  const worst = findings.groupByJoint(rows, "value", -1);
  assert.deepEqual(worst.map((g) => g.joint), ["R_Calf", "Spine", "L_Calf"]);
  assert.deepEqual(worst[0].rows.map((x) => x.value), [-77, 5]);
  assert.deepEqual(worst[2].rows.map((x) => x.value), [12, null]);
  assert.deepEqual(findings.listOrder(worst).map((x) => x.start_frame), [10, 50, 5, 30, 70]);
});

test("the finding at a frame, its loop with a margin, kinds and joints", () => {
  assert.equal(findings.findingAt(rows, 15).joint, "R_Calf");
  assert.equal(findings.findingAt(rows, 25), null);
  assert.deepEqual(findings.loopOfFinding(rows[0], 30, 100), [0, 50]);
  assert.deepEqual(findings.loopOfFinding(rows[4], 30, 90), [40, 89]);
  assert.deepEqual(findings.kindsOf(rows), ["twist", "limits"]);
  assert.deepEqual(findings.jointsOf(rows), ["L_Calf", "R_Calf", "Spine"]);
});

test("playback wraps at the take's end, or inside the loop range", () => {
  assert.equal(playbackFrame(90, 15, 100), 5);
  assert.equal(playbackFrame(10, 0, 100, [20, 29]), 20); // started outside: from the in point
  assert.equal(playbackFrame(25, 4, 100, [20, 29]), 29);
  assert.equal(playbackFrame(25, 5, 100, [20, 29]), 20); // past the out point: back to in
  assert.equal(playbackFrame(20, 1000, 100, [20, 29]), 20);
  for (let k = 0; k < 50; k++) { const x = playbackFrame(22, k, 100, [20, 29]); assert.ok(x >= 20 && x <= 29); }
});

test("the time bar maps pixels to frames and frames to spans; in/out points keep order", () => {
  assert.equal(frameAtX(0, 500, 101), 0);
  assert.equal(frameAtX(250, 500, 101), 50);
  assert.equal(frameAtX(900, 500, 101), 100);
  assert.equal(frameAtX(-5, 500, 101), 0);
  assert.deepEqual(spanOf(10, 19, 100), [10, 10]);
  assert.deepEqual(spanOf(19, 10, 100), [10, 10]);
  assert.deepEqual(withIn(null, 30, 100), [30, 99]);
  assert.deepEqual(withIn([10, 50], 30, 100), [30, 50]);
  assert.deepEqual(withIn([10, 20], 30, 100), [30, 99]); // an out point before the new in point goes
  assert.deepEqual(withOut(null, 30), [0, 30]);
  assert.deepEqual(withOut([10, 50], 30), [10, 30]);
  assert.deepEqual(withOut([40, 50], 30), [0, 30]);
  assert.deepEqual(runsOf([0, 1, 2, 3, 4, 5], [false, true, true, false, true, true]), [[1, 2], [4, 5]]);
  assert.deepEqual(runsOf([0, 2, 4], [true, false, false]), [[0, 0]]);
  assert.deepEqual(runsOf([], []), []);
});

test("the camera's focus: body centre over the floor, the root, the selected joint", () => {
  const points = [[0, 10, 0], [2, 14, 4], [4, 2, 8], null];
  const target = [9, 7, 9];
  assert.deepEqual(focusTarget("body", points, 0, 2, target), [2, 7, 4]); // height kept
  assert.deepEqual(focusTarget("root", points, 0, 2, target), [0, 10, 0]);
  assert.deepEqual(focusTarget("joint", points, 0, 2, target), [4, 2, 8]);
  // No point for the joint: the root; no root: the whole body's centre.
  assert.deepEqual(focusTarget("joint", points, 0, 3, target), [0, 10, 0]);
  assert.deepEqual(focusTarget("root", points, -1, null, target), [2, 26 / 3, 4]);
  assert.ok(focusDistance("joint", 2) < focusDistance("body", 2));
});

test("compare: B's frame is the one at A's instant, moved by the offset, inside B", async () => {
  const { syncedFrame } = await import("../../frontend/js/compare3d.js");
  const { sampleOf } = await import("../../frontend/js/frames.js");
  assert.equal(syncedFrame(60, 60, 120, 0, 1000), 120);
  assert.equal(syncedFrame(60, 60, 30, 5, 1000), 35);
  assert.equal(syncedFrame(60, 60, 30, -100, 1000), 0);
  assert.equal(syncedFrame(900, 60, 60, 0, 500), 499);
  assert.equal(sampleOf({ frames: [0, 4, 8, 12], step: 4 }, 9), 2);
  assert.equal(sampleOf({ frames: [0, 4, 8, 12], step: 4 }, 99), 3);
});

test("the joints inside a finding at a frame take its colour, the later finding winning", () => {
  const jointIndex = new Map([["R_Calf", 0], ["L_Calf", 1]]);
  const colorOf = (x) => (x.kind === "twist" ? "red" : "orange");
  assert.deepEqual([...findings.flaggedAt(rows, jointIndex, 55, colorOf)], [[0, "orange"]]);
  assert.deepEqual([...findings.flaggedAt(rows, jointIndex, 15, colorOf)], [[0, "red"]]);
  // Spine is no joint of the index: left out; no finding at frame 40.
  assert.deepEqual([...findings.flaggedAt(rows, jointIndex, 6, colorOf)], []);
  assert.deepEqual([...findings.flaggedAt(rows, jointIndex, 40, colorOf)], []);
  const overlapping = [f("limits", "L_Calf", 0, 9, 1), f("twist", "L_Calf", 5, 6, 1)];
  assert.deepEqual([...findings.flaggedAt(overlapping, jointIndex, 5, colorOf)], [[1, "red"]]);
});

test("the re-run form checks values against their fields and builds the options", async () => {
  const form = await import("../../frontend/js/run-options.js");
  const cutoff = { name: "cutoff_hz", type: "float" }, order = { name: "order", type: "int", minimum: 1, maximum: 8 };
  assert.deepEqual(form.checkValue(cutoff, " 6.5 "), { value: 6.5 });
  assert.deepEqual(form.checkValue(cutoff, ""), { value: undefined });
  assert.match(form.checkValue(cutoff, "fast").error, /^cutoff_hz: expected a number/);
  assert.match(form.checkValue(cutoff, "Infinity").error, /expected a number/);
  assert.match(form.checkValue(order, "2.5").error, /^order: expected a whole number/);
  assert.match(form.checkValue(order, "9").error, /^order: expected at most 8/);
  // A bound GET /filters marks excluded ("> 0", "< 1") is refused itself.
  const confidence = { name: "min_confidence", type: "float", minimum: 0, maximum: 1, maximum_excluded: true };
  assert.match(form.checkValue(confidence, "1").error, /^min_confidence: expected less than 1, got 1/);
  assert.deepEqual(form.checkValue(confidence, "0"), { value: 0 });
  const damping = { name: "damping_ratio", type: "float", minimum: 0, minimum_excluded: true, maximum: 10 };
  assert.match(form.checkValue(damping, "0").error, /expected more than 0/);
  assert.deepEqual(form.checkValue({ name: "on", type: "bool" }, "false"), { value: false });
  assert.match(form.checkValue({ name: "on", type: "bool" }, "yes").error, /true or false/);
  const fields = { max_points: { name: "max_points", type: "int", minimum: 10, maximum: 100000 } };
  const values = { checks: ["filter"], filter_method: "butterworth", filter_preset: "", max_points: "500", params: [[cutoff, "4"], [order, ""]] };
  assert.deepEqual(form.formOptions(values, fields).options,
    { checks: ["filter"], filter_method: "butterworth", filter_preset: null, filter_params: { cutoff_hz: 4 }, max_points: 500 });
  assert.deepEqual(form.formOptions({ ...values, checks: [], max_points: "5", params: [[order, "0"]] }, fields).errors,
    ["order: expected at least 1, got 0", "max_points: expected at least 10, got 5", "checks: tick at least one check"]);
  // Roles named by hand go with the run as its mapping; none named, no mapping option.
  assert.deepEqual(form.formOptions({ ...values, mapping: { left_forearm: "SegA" } }, fields).options.mapping, { left_forearm: "SegA" });
  assert.equal("mapping" in form.formOptions({ ...values, mapping: {} }, fields).options, false);
  const presets = { full: { checks: ["twist", "limits", "filter"] }, twist: { checks: ["twist"] }, filter: { checks: ["filter"] } };
  assert.deepEqual(form.usablePresets(presets, ["filter"]).map(([n, o]) => [n, o.checks]), [["full", ["filter"]], ["filter", ["filter"]]]);
  assert.equal(form.paramLabel("kalman.process_noise"), "kalman · process noise");
});

test("a keypoint fades toward white with its confidence, never to nothing", async () => {
  const { fade } = await import("../../frontend/js/geometry.js");
  assert.deepEqual(fade([0, 0.5, 1], 1), [0, 0.5, 1]);
  const faint = fade([0, 0, 0], 0);
  assert.ok(Math.abs(faint[0] - 0.85) < 1e-12);
  assert.ok(fade([0, 0, 0], 0.5)[0] < faint[0]);
  assert.deepEqual(fade([0, 0, 0], 7), [0, 0, 0]); // clamped to 1
});

test("a link's loop range is read back only when it fits the take", async () => {
  const { parseRange } = await import("../../frontend/js/timebar.js");
  assert.deepEqual(parseRange("100-130", 458), [100, 130]);
  assert.equal(parseRange("130-100", 458), null);
  assert.equal(parseRange("100-458", 458), null);
  assert.equal(parseRange("x-1", 458), null);
  assert.equal(parseRange(null, 458), null);
});

test("a findings filter goes into link parameters and comes back the same", () => {
  const kinds = ["twist", "limits"], joints = ["L_Calf", "R_Calf"];
  const filter = { kinds: new Set(["twist"]), joint: "R_Calf", minValue: 20, unit: "deg", text: "calf 12", sortKey: "confidence", sortDir: -1 };
  const query = findings.filterParams(filter, kinds);
  assert.deepEqual(query, { kinds: "twist", only: "R_Calf", atleast: "20", unit: "deg", q: "calf 12", sort: "confidence", order: "desc" });
  const back = findings.filterFromParams(new URLSearchParams(query), kinds, joints);
  assert.deepEqual(back, filter);
  // Every kind kept, no joint, no minimum, no words: nothing in the link.
  assert.deepEqual(findings.filterParams({ kinds: new Set(kinds), joint: "", minValue: null, unit: "deg", text: "", sortKey: "start_frame", sortDir: 1 }, kinds), {});
  // Unknown kinds, joints and sort keys and a minimum that is not a number are left out.
  const odd = findings.filterFromParams(new URLSearchParams("kinds=twist,bogus&only=Nobody&atleast=abc&sort=bogus"), kinds, joints);
  assert.deepEqual(odd, { kinds: new Set(["twist"]), joint: "", minValue: null, unit: "", text: "", sortKey: "start_frame", sortDir: 1 });
  // The order alone travels too (a reload keeps it).
  assert.deepEqual(findings.filterParams({ kinds: new Set(), sortKey: "value", sortDir: 1 }, kinds), { sort: "value" });
  const sorted = findings.filterFromParams(new URLSearchParams("sort=duration&order=desc"), kinds, joints);
  assert.deepEqual([sorted.sortKey, sorted.sortDir], ["duration", -1]);
});

test("a typed hyphen finds the en dash of a frame range", () => {
  const spun = [{ kind: "spin", joint: "R_Thigh", start_frame: 161, end_frame: 161, value: 170 }];
  assert.equal(findings.filterFindings(spun, { text: "161-161" }).length, 1);
  assert.equal(findings.filterFindings(spun, { text: "161–161" }).length, 1);
  assert.equal(findings.filterFindings(spun, { text: "162-162" }).length, 0);
});

const mixed = [
  { kind: "limits", joint: "L_Foot", start_frame: 0, end_frame: 9, value: 135.3, unit: "deg", confidence: null },
  { kind: "skate", joint: "L_Foot", start_frame: 20, end_frame: 29, value: 4.6, unit: "% height", confidence: 0.7 },
  { kind: "skate", joint: "L_Foot", start_frame: 40, end_frame: 49, value: 1.3, unit: "% height", confidence: 0.8 },
  { kind: "twist", joint: "L_Calf", start_frame: 5, end_frame: 9, value: -40, unit: "deg", confidence: 0.5 },
  { kind: "jitter", joint: "L_Foot", start_frame: 60, end_frame: 61, value: null, unit: null, confidence: null },
];

test("a group's worst value keeps its unit: one worst per unit, largest first", () => {
  const [foot] = findings.groupByJoint(mixed).filter((g) => g.joint === "L_Foot");
  assert.deepEqual(foot.worstByUnit, [["deg", 135.3], ["% height", 4.6]]);
  assert.equal(findings.worstText(foot), "135.3 °, 4.6 % height");
  const calf = findings.groupByJoint(mixed).find((g) => g.joint === "L_Calf");
  assert.equal(findings.worstText(calf), "40.0 °");
  assert.equal(findings.worstText(findings.groupByJoint([mixed[4]])[0]), "");
  assert.deepEqual(findings.unitsOf(mixed), ["deg", "% height"]);
  assert.equal(findings.unitLabel("deg"), "°");
  assert.equal(findings.unitLabel("% height"), "% height");
});

test("a smallest value in one unit keeps only the findings in that unit", () => {
  const starts = (filter) => findings.filterFindings(mixed, filter).map((x) => x.start_frame);
  // 5 % height keeps no skate of 4.6 % height, and hides the findings in degrees.
  assert.deepEqual(starts({ minValue: 5, unit: "% height" }), []);
  assert.deepEqual(starts({ minValue: 2, unit: "% height" }), [20]);
  assert.deepEqual(starts({ minValue: 5, unit: "deg" }), [0, 5]);
  // No minimum: the unit narrows nothing.
  assert.deepEqual(starts({ minValue: null, unit: "deg" }), [0, 20, 40, 5, 60]);
});

test("a twist interval's confidence shows the probability its decision used when a reviewer prior moved it", () => {
  const twist = { kind: "twist", id: 3, confidence: 0.11 };
  const intervals = new Map([[3, { id: 3, evidence: { calibrated: 0.11, reviewer_probability: 0.62 } }], [4, { id: 4, evidence: { calibrated: 0.9 } }]]);
  assert.equal(findings.usedProbability(twist, intervals), 0.62);
  assert.equal(findings.usedProbability({ ...twist, id: 4 }, intervals), null);
  assert.equal(findings.usedProbability(twist, null), null);
  assert.equal(findings.usedProbability({ ...twist, reviewer_probability: 0.3 }, null), 0.3);
  assert.equal(findings.usedProbability({ kind: "skate", id: 3, confidence: 0.5 }, intervals), null);
  assert.equal(findings.confidenceText(twist, 0.62), "11 % → 62 %");
  assert.equal(findings.confidenceText(twist, null), "11 %");
  assert.equal(findings.confidenceText({ kind: "skate", confidence: 0.745 }), "0.74");
  // Sorted by the probability used: the moved interval goes above one of 0.5.
  const rows = [twist, { kind: "twist", id: 5, confidence: 0.5, start_frame: 1 }];
  twist.start_frame = 0;
  const keys = findings.listSortKeys(intervals);
  assert.deepEqual(findings.groupByJoint(rows, "confidence", -1, keys)[0].rows.map((x) => x.id), [3, 5]);
  assert.deepEqual(findings.groupByJoint(rows, "confidence", -1)[0].rows.map((x) => x.id), [5, 3]);
});
