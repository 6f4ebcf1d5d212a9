// Unit tests of the pure drawing functions (node --test).
import assert from "node:assert/strict";
import { test } from "node:test";
import * as geo from "../../frontend/js/geometry.js";

const close = (a, b, tol = 1e-9) => a.forEach((v, k) => assert.ok(Math.abs(v - b[k]) < tol, `${a} vs ${b}`));
const quarterAboutY = [0, Math.SQRT1_2, 0, Math.SQRT1_2]; // 90° about +Y (scalar-last)

test("rotate turns x into -z by a quarter turn about y", () => {
  close(geo.rotate(quarterAboutY, [1, 0, 0]), [0, 0, -1]);
  close(geo.rotate([0, 0, 0, 1], [1, 2, 3]), [1, 2, 3]);
});

test("toScene is a rotation (keeps handedness): x × y = z holds after it", () => {
  const [x, y, z] = [[1, 0, 0], [0, 1, 0], [0, 0, 1]].map(geo.toScene);
  const cross = [x[1] * y[2] - x[2] * y[1], x[2] * y[0] - x[0] * y[2], x[0] * y[1] - x[1] * y[0]];
  close(cross, z);
});

test("a 90° roll about the bone moves the marked corner of its octahedron", () => {
  // Parent at the origin, child 1 unit up (+Y); the bone is drawn in the parent's frame.
  const points = [[0, 0, 0], [0, 1, 0]];
  const bones = geo.bonesOf([-1, 0]);
  assert.deepEqual(bones, [[0, 1]]);
  const identity = [[0, 0, 0, 1], [0, 0, 0, 1]];
  const sides = geo.boneSides(points, identity, bones);
  const still = geo.boneVertices(points, identity, bones, sides);
  const rolled = geo.boneVertices(points, [quarterAboutY, quarterAboutY], bones, sides);
  assert.equal(still.x.length, 6);
  // Head and tail stay where they are: a stick figure would show nothing.
  for (const k of [0, 5]) close([rolled.x[k], rolled.y[k], rolled.z[k]], [still.x[k], still.y[k], still.z[k]]);
  // The marked corner (vertex 1) moves by the bone's half-width times √2.
  const moved = Math.hypot(rolled.x[1] - still.x[1], rolled.y[1] - still.y[1], rolled.z[1] - still.z[1]);
  assert.ok(Math.abs(moved - 0.16 * Math.SQRT2) < 1e-9, moved);
});

test("a missing or zero-length bone collapses and keeps 6 vertices", () => {
  const points = [[0, 0, 0], [null, null, null], [0, 0, 0]];
  const bones = geo.bonesOf([-1, 0, 0]);
  const rotations = [[0, 0, 0, 1], [0, 0, 0, 1], [0, 0, 0, 1]];
  const v = geo.boneVertices(points, rotations, bones, [[1, 0, 0], [1, 0, 0]]);
  assert.equal(v.x.length, 12);
  assert.ok(v.x.every((x) => x === 0));
});

test("faces index 6 vertices per bone; the marked faces touch corner 1", () => {
  const f = geo.boneFaces(2);
  assert.equal(f.i.length, 16);
  assert.equal(Math.max(...f.i, ...f.j, ...f.k), 11);
  for (const face of geo.MARKED_FACES) assert.ok(geo.BONE_FACES[face].includes(1));
  const colors = geo.faceColors([[0, 1], [1, 2]], new Map([[1, "red"]]), "blue", "orange");
  assert.equal(colors.length, 16);
  assert.equal(colors[1], "blue");
  assert.equal(colors[9], "red");
  assert.equal(colors[8], "orange");
});

test("triads draw three coloured axes per joint", () => {
  const t = geo.triads([[0, 0, 0]], [[0, 0, 0, 1]], 1, 2);
  assert.equal(t.x.length, 9);
  close([t.x[1], t.y[1], t.z[1]], geo.toScene([2, 0, 0]));
  assert.deepEqual([t.color[0], t.color[3], t.color[6]], ["#d62728", "#2ca02c", "#1f77b4"]);
});

test("the follow box keeps its size, sits on the floor and re-centres only on drift", () => {
  const frames = [[[0, 0, 0], [0, 2, 0]], [[10, 0, 0], [10, 2, 0]]];
  const box = geo.bodyBox([frames], 0);
  assert.equal(box.half, 1);
  assert.equal(box.floor, 0);
  const ranges = geo.followRanges([0, 0, 1], box);
  assert.deepEqual(ranges[2], [0, 2]);
  assert.equal(geo.drifted([0.1, 0, 1], ranges), false);
  assert.equal(geo.drifted([0.5, 0, 1], ranges), true);
});

// Where a point lands on a square view (normalised: ±1 at the edges) of a camera at `eye`
// looking at `target`, Y up, of vertical field of view `fovDeg`.
function onScreen(point, eye, target, fovDeg) {
  const sub = (a, b) => a.map((v, k) => v - b[k]);
  const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
  const unit = (a) => a.map((v) => v / Math.hypot(...a));
  const crossOf = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
  const forward = unit(sub(target, eye));
  const right = unit(crossOf(forward, [0, 1, 0]));
  const up = crossOf(right, forward);
  const q = sub(point, eye), depth = dot(q, forward), t = Math.tan((fovDeg * Math.PI) / 360);
  return [dot(q, right) / (depth * t), dot(q, up) / (depth * t)];
}

test("the body's framing keeps every point in view with a margin, the head too, from any side", () => {
  // A keypoint take of a standing figure (Y up, metres): the head's top 1.8 m over the floor,
  // leaning toward the camera, one arm reaching forward; a second frame a step to the side.
  const pose = [[0, 0, 0.12], [0.15, 0, -0.05], [0, 1.0, 0], [-0.2, 1.45, 0.05], [0.2, 1.45, 0.05],
    [0.1, 1.8, 0.15], [0.05, 1.62, 0.2], [-0.3, 1.2, 0.6], [0.3, 1.0, 0.1]];
  const frames = [pose, pose.map(([x, y, z]) => [x + 0.4, y, z])];
  const box = geo.bodyBox([frames], 0.1);
  const fov = 35;
  const { height, distance } = geo.bodyFraming(box, fov);
  assert.ok(Math.abs(height - 0.9) < 1e-9); // half-way between the floor and the head's top
  for (const points of frames) {
    const centre = geo.centreOf(points);
    const target = geo.focusTarget("body", points, -1, null, [0, height, 0]);
    assert.deepEqual(target, [centre[0], height, -centre[1]]);
    for (const preset of Object.values(geo.PRESETS)) for (const turn of [0, 0.5, 1, 1.5, 2, 2.5, 3]) {
      const eye = geo.orbitPosition(target, preset.azimuth + turn, preset.elevation, distance);
      for (const p of points) {
        const [x, y] = onScreen(p, eye, target, fov);
        assert.ok(Math.abs(x) < 0.95 && Math.abs(y) < 0.95, `${p} at ${[x, y]} (${turn} rad round)`);
      }
    }
  }
  // Not so far that the figure is lost: seen from the front it spans most of the view's height.
  const front = geo.focusTarget("body", pose, -1, null, [0, height, 0]);
  const eye = geo.orbitPosition(front, 0, geo.PRESETS.front.elevation, distance);
  const ys = pose.map((p) => onScreen(p, eye, front, fov)[1]);
  assert.ok(Math.max(...ys) - Math.min(...ys) > 1.4);
});

test("an empty take is framed as a body 2 units tall", () => {
  const box = geo.bodyBox([[[null, [NaN, 0, 0]]]]);
  assert.equal(geo.bodyFraming(box, 35).height, 1);
  assert.ok(geo.bodyFraming(box, 35).distance > 1 / Math.sin((17.5 * Math.PI) / 180));
});

test("frameTake holds every frame and keeps the floor at the lowest point", () => {
  const { ranges } = geo.frameTake([[[[0, 0, 0], [1, 2, 3]]]], 0);
  assert.deepEqual(ranges, [[0, 1], [-3, 0], [0, 2]]);
});

test("boneSoup writes the triangles of boneVertices + triangleSoup, missing points included", () => {
  const points = [[0, 0, 0], [0, 1, 0], [0.2, 1.8, 0.1], [NaN, NaN, NaN], [0, 1, 0]];
  const rotations = [quarterAboutY, [0.1, 0.2, 0.3, 0.927], [0, 0, 0, 1], [0, 0, 0, 1], [0, 0, 0, 1]];
  const bones = [[0, 1], [1, 2], [1, 3], [3, 4], [1, 4]]; // a missing tail, a missing head, a zero-length bone
  const sides = geo.boneSides(points, rotations, bones);
  const expected = geo.triangleSoup(geo.boneVertices(points, rotations, bones, sides, geo.identity), bones.length, new Float32Array(bones.length * 72));
  const soup = geo.boneSoup(points, rotations, bones, sides, new Float32Array(bones.length * 72));
  close([...soup], [...expected], 1e-6);
  assert.ok(soup.every(Number.isFinite));
});

test("a NaN point (packed windows) is missing, as a null one (JSON) is", () => {
  assert.equal(geo.present([NaN, NaN, NaN]), false);
  assert.equal(geo.present([null, null, null]), false);
  assert.equal(geo.present(new Float32Array([0, 1, 2])), true);
});

test("shadeSoup lights each face by its outward normal, whatever the winding", () => {
  const points = [[0, 0, 0], [0, 1, 0]];
  const rotations = [[0, 0, 0, 1], [0, 0, 0, 1]];
  const bones = [[0, 1]];
  const soup = geo.boneSoup(points, rotations, bones, geo.boneSides(points, rotations, bones), new Float32Array(72));
  const white = () => [1, 1, 1];
  const light = [1, 0, 0];
  const shaded = geo.shadeSoup(soup, 1, white, light, 1, 2, new Float32Array(72));
  const values = [...shaded];
  assert.ok(values.every((v) => v >= 1 / Math.PI - 1e-6 && v <= 3 / Math.PI + 1e-6));
  assert.ok(values.some((v) => v > 1.5 / Math.PI)); // faces toward +x are lit
  assert.ok(values.some((v) => Math.abs(v - 1 / Math.PI) < 1e-6)); // faces away: ambient only
  // The same triangles wound the other way round are lit the same.
  const flipped = soup.slice();
  for (let t = 0; t < 8; t++) for (let a = 0; a < 3; a++) [flipped[9 * t + 3 + a], flipped[9 * t + 6 + a]] = [soup[9 * t + 6 + a], soup[9 * t + 3 + a]];
  close([...geo.shadeSoup(flipped, 1, white, light, 1, 2, new Float32Array(72))], values, 1e-6);
  // The colour of a face scales its light.
  const red = geo.shadeSoup(soup, 1, () => [1, 0, 0], light, 1, 2, new Float32Array(72));
  close([red[0], red[1], red[2]], [values[0], 0, 0], 1e-6);
});
