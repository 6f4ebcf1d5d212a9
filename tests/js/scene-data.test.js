// Unit tests of the 3D views' pure data: the joints drawn, the buffers written, the orbit's
// moves and the hover label (node --test).
import assert from "node:assert/strict";
import { test } from "node:test";
import { dragged, drawnSkeleton, floorPlane, hoverLabel, writePoints, writeSegments, writeTriads, zoomed } from "../../frontend/js/scene-data.js";

test("bones come from the take, else from the parents", () => {
  const parents = [-1, 0, 1];
  assert.deepEqual(drawnSkeleton({ names: ["a", "b", "c"], parents, oriented: false }).bones, [[0, 1], [1, 2]]);
  const given = drawnSkeleton({ names: ["a", "b", "c"], parents, bones: [[0, 2]], oriented: false });
  assert.deepEqual(given.bones, [[0, 2]]);
  // Keypoints (not oriented): no joint is loose, even outside every bone.
  assert.equal(given.loose.size, 0);
  assert.equal(given.drawnRoot, 0);
});

test("a BVH root joined by no bone is not drawn, and the root followed is its child", () => {
  const skeleton = { names: ["joint_Root", "Hips", "Spine"], parents: [-1, 0, 1], bones: [[1, 2]], oriented: true };
  const drawn = drawnSkeleton(skeleton);
  assert.deepEqual([...drawn.loose], [0]);
  assert.equal(drawn.drawnRoot, 1);
  // A root in a bone stays the root.
  assert.equal(drawnSkeleton({ ...skeleton, bones: [[0, 1], [1, 2]] }).drawnRoot, 0);
});

test("points kept are written, others are NaN, and counted", () => {
  const out = new Float32Array(9);
  const kept = writePoints(out, [[1, 2, 3], [4, 5, 6], [7, 8, 9]], (j) => j !== 1);
  assert.equal(kept, 2);
  assert.deepEqual([...out.slice(0, 3)], [1, 2, 3]);
  assert.ok(out.slice(3, 6).every(Number.isNaN));
  assert.deepEqual([...out.slice(6)], [7, 8, 9]);
});

test("a segment with a missing end collapses to the origin", () => {
  const out = new Float32Array(12);
  writeSegments(out, [[1, 1, 1], [2, 2, 2], [NaN, 0, 0]], [[0, 1], [1, 2]]);
  assert.deepEqual([...out.slice(0, 6)], [1, 1, 1, 2, 2, 2]);
  assert.deepEqual([...out.slice(6)], [0, 0, 0, 0, 0, 0]);
});

test("axes are written as segments, each coloured by its axis", () => {
  // One joint: three segments (origin → tip), each followed by a null separator.
  const t = { x: [0, 1, null, 0, 0, null, 0, 0, null], y: [0, 0, null, 0, 1, null, 0, 0, null], z: [0, 0, null, 0, 0, null, 0, 1, null] };
  const axes = [{ r: 1, g: 0, b: 0 }, { r: 0, g: 1, b: 0 }, { r: 0, g: 0, b: 1 }];
  const positions = new Float32Array(18), colors = new Float32Array(18);
  writeTriads(t, positions, colors, axes);
  assert.deepEqual([...positions], [0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 1]);
  assert.deepEqual([...colors], [1, 0, 0, 1, 0, 0, 0, 1, 0, 0, 1, 0, 0, 0, 1, 0, 0, 1]);
});

test("a drag turns the orbit and keeps its elevation in range; the wheel zooms within limits", () => {
  const turned = dragged({ azimuth: 0, elevation: 0.5 }, 100, 20);
  assert.ok(Math.abs(turned.azimuth + 1) < 1e-12);
  assert.ok(Math.abs(turned.elevation - 0.7) < 1e-12);
  assert.equal(dragged({ azimuth: 0, elevation: 1.5 }, 0, 100).elevation, 1.55);
  assert.equal(dragged({ azimuth: 0, elevation: 0 }, 0, -100).elevation, -0.2);
  assert.ok(zoomed(2, 100, 1) > 2);
  assert.equal(zoomed(2, 1e5, 1), 8);
  assert.equal(zoomed(2, -1e5, 1), 0.3);
});

test("the hover label adds the confidence, and in the corrected view bridged or filled", () => {
  const frame = { confidence: [0.456, 1], bridged: [1, 0], filled: [0, 2] };
  assert.equal(hoverLabel("nose", {}, 0, true), "nose");
  assert.equal(hoverLabel("nose", frame, 0, true), "nose · confidence 0.46 · bridged");
  assert.equal(hoverLabel("nose", frame, 0, false), "nose · confidence 0.46");
  assert.equal(hoverLabel("LFHD", frame, 1, true), "LFHD · confidence 1.00 · filled");
});

test("the floor plane lies at the floor's height across the up axis, over the take's horizontal extent", () => {
  const frames = [[[0, 5, 0], [2, 9, 1], null], [[4, 1, -3], [NaN, NaN, NaN]]];
  const plane = floorPlane({ up_axis: "Y", floor: 0.8 }, [frames], 0.1);
  assert.equal(plane.axis, 1);
  assert.ok(Math.abs(plane.level - 0.8) < 1e-9);
  assert.deepEqual(plane.index, [0, 1, 2, 0, 2, 3]);
  const corners = [0, 1, 2, 3].map((c) => [...plane.positions.slice(3 * c, 3 * c + 3)]);
  for (const c of corners) assert.ok(Math.abs(c[1] - 0.8) < 1e-6);
  // x spans 0..4 and z -3..1 (the larger span, 4, sets a margin of 0.4 on each side).
  const xs = corners.map((c) => c[0]), zs = corners.map((c) => c[2]);
  assert.ok(Math.abs(Math.min(...xs) + 0.4) < 1e-6 && Math.abs(Math.max(...xs) - 4.4) < 1e-6);
  assert.ok(Math.abs(Math.min(...zs) + 3.4) < 1e-6 && Math.abs(Math.max(...zs) - 1.4) < 1e-6);
});

test("a Z-up or downward axis moves the plane onto that axis, signed", () => {
  const frames = [[[0, 0, 10], [3, 6, 20]]];
  const zUp = floorPlane({ up_axis: "Z", floor: 10 }, [frames]);
  assert.equal(zUp.axis, 2);
  for (let c = 0; c < 4; c++) assert.equal(zUp.positions[3 * c + 2], 10);
  // y down (MediaPipe's world): heights are -y, so the floor at height 0.9 is the plane y = -0.9.
  const yDown = floorPlane({ up_axis: "-Y", floor: 0.9 }, [frames]);
  assert.equal(yDown.axis, 1);
  assert.ok(Math.abs(yDown.level + 0.9) < 1e-9);
  for (let c = 0; c < 4; c++) assert.ok(Math.abs(yDown.positions[3 * c + 1] + 0.9) < 1e-6);
});

test("no plane without a feet step, a floor or a present point; a flat take still gets an area", () => {
  const frames = [[[0, 0, 0], [1, 2, 0]]];
  assert.equal(floorPlane(null, [frames]), null);
  assert.equal(floorPlane(undefined, [frames]), null);
  assert.equal(floorPlane({ up_axis: "Y", floor: null }, [frames]), null);
  assert.equal(floorPlane({ up_axis: "W", floor: 0 }, [frames]), null);
  assert.equal(floorPlane({ up_axis: "Y", floor: 0 }, [[[null, [NaN, 0, 0]]]]), null);
  // A 2D take (z = 0 throughout), Y up: the plane still spans some depth.
  const flat = floorPlane({ up_axis: "Y", floor: 0 }, [frames]);
  const zs = [0, 1, 2, 3].map((c) => flat.positions[3 * c + 2]);
  assert.ok(Math.max(...zs) - Math.min(...zs) > 0);
});
