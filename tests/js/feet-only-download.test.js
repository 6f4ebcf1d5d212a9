// Unit tests: a marker take's run with the feet check and no markers check offers the reviewed
// download (the raw take with the accepted foot locks pinned) when it has foot locks.
import { test } from "node:test";
import assert from "node:assert/strict";
import { reviewedFormat, reviewedFormats } from "../../frontend/js/lock-decisions.js";

const skate = { kind: "skate", id: "skate-left-12", foot: "left", start_frame: 12, end_frame: 40 };
const feetOnly = (findings) => ({
  kind: "keypoints",
  downloads: ["csv", "trc"],
  steps: { markers: { state: "not requested" }, feet: { state: "done" } },
  findings,
});

test("a feet-only marker run with foot locks has a reviewed download in the take's format", () => {
  assert.deepEqual(reviewedFormats(feetOnly([skate]), { format: "trc" }), ["trc"]);
  assert.deepEqual(reviewedFormats(feetOnly([skate]), { format: "c3d" }), ["c3d", "trc"]);
  assert.equal(reviewedFormat(feetOnly([skate]), { format: "c3d" }), "c3d");
});

test("without a foot lock, a feet step that did not finish, or a non-marker take: none", () => {
  assert.deepEqual(reviewedFormats(feetOnly([]), { format: "trc" }), []);
  assert.deepEqual(reviewedFormats(feetOnly([{ ...skate, id: null }]), { format: "c3d" }), []);
  const skipped = { ...feetOnly([skate]), steps: { feet: { state: "skipped" } } };
  assert.deepEqual(reviewedFormats(skipped, { format: "trc" }), []);
  assert.deepEqual(reviewedFormats(feetOnly([skate]), { format: "csv" }), []);
  assert.deepEqual(reviewedFormats(feetOnly([skate])), []);
});
