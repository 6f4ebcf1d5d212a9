import assert from "node:assert/strict";
import { test } from "node:test";
import { runOptionsLabel } from "../../frontend/js/format.js";
import { optionDefaults, takeFilters } from "../../frontend/js/run-options.js";

// The defaults come from the served description (GET /run-options), whatever they are: these
// descriptions serve other defaults than the product's, so a default typed into the page fails.
const describedWith = (applyDefault, takeFilterDefaults) => ({
  groups: [
    { name: "twist", fields: [
      { name: "twist_method", type: "choice", choices: ["robust", "paper"], default: "robust" },
      { name: "twist_apply", type: "choice", choices: ["confident", "all", "none"], default: applyDefault },
    ] },
    { name: "advanced", fields: [{ name: "max_points", type: "int", default: 700 }] },
  ],
  take_filters: takeFilterDefaults,
});
const served = describedWith("confident", {
  motion: { target: "rotations", default: null },
  markers: { target: "keypoints", default: "adaptive" },
  keypoints: { target: "keypoints", default: "adaptive" },
});

test("each field's default is the served one", () => {
  assert.deepEqual(optionDefaults(served), { twist_method: "robust", twist_apply: "confident", max_points: 700 });
  assert.equal(optionDefaults(describedWith("none", {})).twist_apply, "none");
});

test("a run's label names its twist choice only when it is not the served default", () => {
  const run = (apply) => ({ status: "done", options: { checks: ["twist"], twist_apply: apply }, summary: { steps: { twist: "done" } } });
  assert.equal(runOptionsLabel(run("confident"), served), "twist");
  assert.equal(runOptionsLabel(run("all"), served), "twist · apply all");
  const allByDefault = describedWith("all", {});
  assert.equal(runOptionsLabel(run("all"), allByDefault), "twist");
  assert.equal(runOptionsLabel(run("confident"), allByDefault), "twist · apply confident");
});

test("a take is offered the filters of its kind's target, and its kind's served default", () => {
  const filters = [
    { name: "adaptive", applies_to: ["keypoints"] },
    { name: "kalman", applies_to: ["keypoints"] },
    { name: "quat-pd", applies_to: ["rotations"] },
    { name: "both-ways", applies_to: ["keypoints", "rotations"] },
  ];
  const names = (found) => found.usable.map((f) => f.name);
  assert.deepEqual(names(takeFilters("motion", served, filters)), ["quat-pd", "both-ways"]);
  assert.equal(takeFilters("motion", served, filters).fallback, null);
  assert.deepEqual(names(takeFilters("markers", served, filters)), ["adaptive", "kalman", "both-ways"]);
  assert.equal(takeFilters("keypoints", served, filters).fallback, "adaptive");
  const other = describedWith("confident", { motion: { target: "rotations", default: "quat-pd" }, keypoints: { target: "keypoints", default: "kalman" } });
  assert.equal(takeFilters("motion", other, filters).fallback, "quat-pd");
  assert.equal(takeFilters("keypoints", other, filters).fallback, "kalman");
});
