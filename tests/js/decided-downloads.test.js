// Unit tests of the reviewed download links' pure helpers (node --test).
import { test } from "node:test";
import assert from "node:assert/strict";
import { decidedLinks, downloadText, reviewedFormat, reviewedFormats } from "../../frontend/js/lock-decisions.js";

const markersDone = { markers: { state: "done", message: "" } };

test("a marker take's reviewed download: a TRC take's as TRC, a C3D take's as C3D then TRC", () => {
  assert.deepEqual(reviewedFormats({ kind: "motion" }), ["bvh"]);
  // A C3D take: the run wrote its corrected C3D.
  assert.deepEqual(reviewedFormats({ kind: "keypoints", downloads: ["c3d", "csv", "trc"], steps: markersDone }, { format: "c3d" }), ["c3d", "trc"]);
  // A TRC take whose markers check ran (its filtered TRC is another download).
  const trcRun = { kind: "keypoints", downloads: ["csv", "trc"], steps: markersDone };
  assert.deepEqual(reviewedFormats(trcRun, { format: "trc" }), ["trc"]);
  assert.equal(reviewedFormat(trcRun, { format: "trc" }), "trc");
  // Without the markers check, or a keypoint take of another format, or no take known: none.
  assert.deepEqual(reviewedFormats({ ...trcRun, steps: { markers: { state: "skipped" } } }, { format: "trc" }), []);
  assert.deepEqual(reviewedFormats({ kind: "keypoints", downloads: ["csv", "trc"], steps: {} }, { format: "csv" }), []);
  assert.deepEqual(reviewedFormats(trcRun), []);
  assert.equal(reviewedFormat({ kind: "keypoints", downloads: ["csv"] }, { format: "openpose" }), null);
});

test("the links: the take's own format first as #download-decided, named for marker takes", () => {
  assert.deepEqual(decidedLinks(["bvh"]), [{ format: "bvh", id: "download-decided", named: null }]);
  assert.deepEqual(decidedLinks(["c3d", "trc"]), [
    { format: "c3d", id: "download-decided", named: "c3d" },
    { format: "trc", id: "download-decided-trc", named: "trc" },
  ]);
  assert.deepEqual(decidedLinks(["trc"]), [{ format: "trc", id: "download-decided", named: "trc" }]);
  assert.deepEqual(decidedLinks([]), []);
});

test("a named link says its format, and its foot locks when the run has any", () => {
  assert.equal(downloadText(0, 0, "trc"), "Download reviewed take as TRC");
  assert.equal(downloadText(0, 0, "c3d"), "Download reviewed take as C3D");
  assert.equal(downloadText(2, 1, "trc"), "Download reviewed take as TRC (1 of 2 foot locks applied)");
  assert.equal(downloadText(2, 0, null), "Download reviewed take (0 of 2 foot locks applied)");
});
