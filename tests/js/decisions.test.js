import { test } from "node:test";
import assert from "node:assert/strict";
import { decidable, decidedElsewhere, itemLabel, keyTarget } from "../../frontend/js/decisions.js";

const take = { runs: [{ id: "r1", status: "done" }, { id: "r2", status: "failed" }, { id: "r3", status: "done" }, { id: "r4", status: "done" }] };
const histories = { r1: 2, r2: 5, r3: 0, r4: 0 };
const fetched = [];
const getDecisions = async (id) => { fetched.push(id); return { history: Array(histories[id]).fill({}) }; };

test("a re-run without decisions points at the newest finished run that has some", async () => {
  const found = await decidedElsewhere(take, { id: "r4" }, getDecisions);
  assert.deepEqual([found.run.id, found.number, found.count], ["r1", 1, 2]);
  // Newest first, the failed run and the run shown skipped.
  assert.deepEqual(fetched, ["r3", "r1"]);
});

test("a history longer than its page counts every decision, by its totals", async () => {
  const paged = async () => ({ history: Array(200).fill({}), history_total: 3000, lock_history: [{}], lock_history_total: 7 });
  const found = await decidedElsewhere({ runs: [{ id: "r1", status: "done" }, { id: "r2", status: "done" }] }, { id: "r2" }, paged);
  assert.equal(found.count, 3007);
});

test("nothing to point at: no other run has decisions, or the request fails", async () => {
  assert.equal(await decidedElsewhere({ runs: [{ id: "r3", status: "done" }, { id: "r4", status: "done" }] }, { id: "r4" }, getDecisions), null);
  const failing = async () => { throw new Error("offline"); };
  assert.equal(await decidedElsewhere(take, { id: "r4" }, failing), null);
  assert.equal(await decidedElsewhere(null, { id: "r4" }, getDecisions), null);
});

test("a motion run decides its twist intervals, a marker run its swaps, others nothing", () => {
  const intervals = [{ id: 0, joint: "LeftLeg", start_frame: 3, end_frame: 9 }];
  assert.deepEqual(decidable({ kind: "motion", series: { twist: { intervals } }, findings: [] }), { kind: "twist", items: intervals });
  assert.equal(decidable({ kind: "motion", series: { twist: { intervals: [] } }, findings: [] }), null);
  assert.equal(decidable({ kind: "motion", series: {}, findings: [] }), null);
  const swap = { kind: "swap", id: 0, markers: ["LFHD", "LBHD"], start_frame: 400, end_frame: 429 };
  const findings = [{ kind: "gap", id: 0 }, swap];
  assert.deepEqual(decidable({ kind: "keypoints", series: {}, findings }), { kind: "swap", items: [swap] });
  assert.equal(decidable({ kind: "keypoints", series: {}, findings: [{ kind: "gap" }] }), null);
  assert.equal(itemLabel("swap", swap), "LFHD ↔ LBHD frames 400–429");
  assert.equal(itemLabel("twist", intervals[0]), "LeftLeg frames 3–9");
});

test("Y / X act on the focused decidable row, else on the last opened item, else say why not", () => {
  const ids = new Map([[0, {}], [3, {}]]);
  assert.deepEqual(keyTarget({ kind: "twist", interval: "3" }, 0, "twist", "twist", ids), { id: 3 });
  // Item 0 is an item like any other (not "none").
  assert.deepEqual(keyTarget({ kind: "twist", interval: "0" }, 3, "twist", "twist", ids), { id: 0 });
  assert.deepEqual(keyTarget(null, 0, "twist", "twist", ids), { id: 0 });
  // A focused row of a reported kind (no interval) says so, whatever was opened before.
  assert.match(keyTarget({ kind: "limits", interval: undefined }, 3, "twist", "twist", ids).message, /a limits finding is reported/);
  // Nothing opened, or an unknown id: a hint; another kind opened last: that kind is reported.
  assert.equal(keyTarget(null, null, null, "swap", ids).message, "open or focus a swap finding first");
  assert.equal(keyTarget({ kind: "twist", interval: "9" }, null, "twist", "twist", ids).message, "open or focus a twist finding first");
  assert.match(keyTarget(null, null, "spin", "twist", ids).message, /a spin finding is reported, not corrected/);
});
