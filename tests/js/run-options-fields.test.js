import assert from "node:assert/strict";
import { test } from "node:test";
import { formOptions } from "../../frontend/js/run-options.js";

// The re-run form reads every field the server serves (GET /run-options) by its type: a field
// it has never seen reaches the run's options, checked against its served bounds.
const served = {
  twist_method: { name: "twist_method", type: "choice", choices: ["robust", "paper"], default: "robust" },
  max_points: { name: "max_points", type: "int", minimum: 10, maximum: 100000, default: 2000 },
  filter_method: { name: "filter_method", type: "filter", default: null },
  smoothing_frames: { name: "smoothing_frames", type: "int", minimum: 1, maximum: 9, default: 3 },
};
const base = { checks: ["twist"], filter_method: "", filter_preset: "", params: [] };

test("a field the server adds reaches the run's options, checked against its bounds", () => {
  const built = formOptions({ ...base, twist_method: "paper", max_points: "", smoothing_frames: "5" }, served);
  assert.deepEqual(built.options, {
    checks: ["twist"], filter_method: null, filter_preset: null, filter_params: {}, twist_method: "paper", smoothing_frames: 5,
  });
  assert.deepEqual(formOptions({ ...base, smoothing_frames: "12" }, served).errors, ["smoothing_frames: expected at most 9, got 12"]);
});

test("a field the take's form does not show is left to its default", () => {
  // A keypoint take has no twist group: no twist control, so no twist option is sent.
  const built = formOptions({ ...base, checks: ["filter"], max_points: "300" }, served);
  assert.deepEqual(built.options, { checks: ["filter"], filter_method: null, filter_preset: null, filter_params: {}, max_points: 300 });
});
