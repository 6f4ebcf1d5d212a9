import { test } from "node:test";
import assert from "node:assert/strict";
import { decidedElsewhere } from "../../frontend/js/decisions.js";

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

test("nothing to point at: no other run has decisions, or the request fails", async () => {
  assert.equal(await decidedElsewhere({ runs: [{ id: "r3", status: "done" }, { id: "r4", status: "done" }] }, { id: "r4" }, getDecisions), null);
  const failing = async () => { throw new Error("offline"); };
  assert.equal(await decidedElsewhere(take, { id: "r4" }, failing), null);
  assert.equal(await decidedElsewhere(null, { id: "r4" }, getDecisions), null);
});
