// Unit tests of the 3D views' pure data: the joints drawn, the buffers written, the orbit's
// moves and the hover label (node --test).
import assert from "node:assert/strict";
import { test } from "node:test";
import { dragged, drawnSkeleton, floorLabel, floorPlane, hoverLabel, writePoints, writeSegments, writeTriads, zoomed } from "../../frontend/js/scene-data.js";

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
  // y down (MediaPipe's world, origin at the hips): `floor` is the floor's coordinate on the axis,
  // the feet's y (0.9, below the hips), not their height (-0.9).
  const yDown = floorPlane({ up_axis: "-Y", floor: 0.9 }, [frames]);
  assert.equal(yDown.axis, 1);
  assert.ok(Math.abs(yDown.level - 0.9) < 1e-9);
  for (let c = 0; c < 4; c++) assert.ok(Math.abs(yDown.positions[3 * c + 1] - 0.9) < 1e-6);
});

/** The four corners of a plane as [x, y, z] lists. */
const cornersOf = (plane) => [0, 1, 2, 3].map((c) => [...plane.positions.slice(3 * c, 3 * c + 3)]);

test("a level floor stays level, whatever its check says besides", () => {
  const frames = [[[0, 5, 0], [4, 9, -3]]];
  const bare = floorPlane({ up_axis: "Y", floor: 0.8 }, [frames]);
  const level = { up_axis: "Y", floor: 0.8, floor_check: { tilted: false, tilt_deg: 0.1, plane_gradient: null, plane_origin: [1, 2] } };
  // A gradient of a floor not found tilted is not drawn either.
  const untilted = { ...level, floor_check: { ...level.floor_check, plane_gradient: [0.5, 0.5] } };
  for (const feet of [level, untilted]) {
    const plane = floorPlane(feet, [frames]);
    assert.equal(plane.tilted, false);
    assert.deepEqual([...plane.positions], [...bare.positions]);
  }
  assert.equal(bare.tilted, false);
  for (const c of cornersOf(bare)) assert.ok(Math.abs(c[1] - 0.8) < 1e-6);
  // Tilted but without a fitted plane: drawn level.
  const noPlane = floorPlane({ ...level, floor_check: { tilted: true, tilt_deg: 3, plane_gradient: null, plane_origin: [0, 0] } }, [frames]);
  assert.equal(noPlane.tilted, false);
  assert.deepEqual([...noPlane.positions], [...bare.positions]);
});

test("a tilted floor is drawn as the fitted plane: every corner on it, not level", () => {
  const frames = [[[0, 5, 0], [4, 9, -3]], [[2, 1, 1]]];
  const check = { tilted: true, tilt_deg: 3.2, plane_gradient: [0.05, -0.02], plane_origin: [1.5, -1] };
  const plane = floorPlane({ up_axis: "Y", floor: 0.8, floor_check: check }, [frames]);
  assert.equal(plane.tilted, true);
  assert.equal(plane.axis, 1);
  assert.ok(Math.abs(plane.level - 0.8) < 1e-9);
  const corners = cornersOf(plane);
  // u = x, w = z (the axes other than Y, in order): y = floor + (x - 1.5) 0.05 + (z + 1) (-0.02).
  for (const [x, y, z] of corners) assert.ok(Math.abs(y - (0.8 + (x - 1.5) * 0.05 - (z + 1) * 0.02)) < 1e-6);
  const heights = corners.map((c) => c[1]);
  assert.ok(Math.max(...heights) - Math.min(...heights) > 0.1);
  // The horizontal extent is the level plane's.
  const level = floorPlane({ up_axis: "Y", floor: 0.8 }, [frames]);
  for (const [k, c] of cornersOf(level).entries()) { assert.equal(c[0], corners[k][0]); assert.equal(c[2], corners[k][2]); }
});

test("a tilted floor on a Z-up or downward axis follows the axis' sign", () => {
  const frames = [[[0, 0, 10], [3, 6, 20]]];
  const check = { tilted: true, tilt_deg: 2, plane_gradient: [0.1, 0.03], plane_origin: [1, 2] };
  // Z up: u = x, w = y.
  const zUp = floorPlane({ up_axis: "Z", floor: 10, floor_check: check }, [frames]);
  assert.equal(zUp.axis, 2);
  for (const [x, y, z] of cornersOf(zUp)) assert.ok(Math.abs(z - (10 + (x - 1) * 0.1 + (y - 2) * 0.03)) < 1e-5);
  // y down: heights are -y, so a floor rising (in height) along +x has y falling along +x.
  const yDown = floorPlane({ up_axis: "-Y", floor: 0.9, floor_check: check }, [frames]);
  assert.equal(yDown.axis, 1);
  assert.equal(yDown.tilted, true);
  for (const [x, y, z] of cornersOf(yDown)) assert.ok(Math.abs(y - (0.9 - ((x - 1) * 0.1 + (z - 2) * 0.03))) < 1e-6);
  const byX = cornersOf(yDown).sort((a, b) => a[0] - b[0]);
  assert.ok(byX[3][1] < byX[0][1]);
  // X up: u = y, w = z.
  const xUp = floorPlane({ up_axis: "X", floor: -1, floor_check: check }, [frames]);
  assert.equal(xUp.axis, 0);
  for (const [x, y, z] of cornersOf(xUp)) assert.ok(Math.abs(x - (-1 + (y - 1) * 0.1 + (z - 2) * 0.03)) < 1e-5);
});

test("the floor's label says when the floor is tilted, by how much", () => {
  assert.equal(floorLabel(null), "floor");
  assert.equal(floorLabel({ up_axis: "Y", floor: 0 }), "floor");
  assert.equal(floorLabel({ floor_check: { tilted: false, tilt_deg: 0.4 } }), "floor");
  assert.equal(floorLabel({ floor_check: { tilted: true, tilt_deg: 3.24 } }), "floor (tilted 3.2°)");
  assert.equal(floorLabel({ floor_check: { tilted: true, tilt_deg: null } }), "floor (tilted)");
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
