// Pure skeleton geometry for the 3D views: oriented (octahedral) bones, axis triads, framing.
// Data arrive Y-up in file units; the views are Plotly scenes (Z-up), so every drawn point goes
// through `toScene` (x, y, z) -> (x, -z, y), a rotation (not a mirror) about the x axis.

/** A point that was seen: null (JSON) and NaN (packed windows) mark a missing one. */
export const present = (p) => p != null && Number.isFinite(p[0]) && Number.isFinite(p[1]) && Number.isFinite(p[2]);
export const toScene = (p) => [p[0], -p[2], p[1]];
/** Data coordinates unchanged (three.js scenes are Y-up like the data). */
export const identity = (p) => p;

const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
const scale = (a, s) => [a[0] * s, a[1] * s, a[2] * s];
const add = (a, b) => [a[0] + b[0], a[1] + b[1], a[2] + b[2]];
const sub = (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
const norm = (a) => Math.hypot(a[0], a[1], a[2]);

/** Rotate vector v by the unit quaternion q = [x, y, z, w] (scalar-last, active). */
export function rotate(q, v) {
  const u = [q[0], q[1], q[2]];
  const t = scale(cross(u, v), 2);
  return add(add(v, scale(t, q[3])), cross(u, t));
}
const conjugate = (q) => [-q[0], -q[1], -q[2], q[3]];

/** Bones as [parent, child] point pairs, in point order (roots have no bone). */
export const bonesOf = (parents) => parents.flatMap((p, c) => (p >= 0 ? [[p, c]] : []));

/**
 * Per bone, the side of the bone that is marked, as a unit vector in the parent joint's frame:
 * the local axis most perpendicular to the bone, made exactly perpendicular. Chosen once from
 * one frame so it never jumps between frames (a BVH bone's direction is fixed in its parent).
 */
export function boneSides(points, rotations, bones) {
  return bones.map(([p, c]) => {
    const d = sub(points[c], points[p]);
    const length = norm(d);
    if (!(length > 1e-9) || !rotations[p]) return [1, 0, 0];
    const local = rotate(conjugate(rotations[p]), scale(d, 1 / length));
    const axis = [0, 1, 2].reduce((best, a) => (Math.abs(local[a]) < Math.abs(local[best]) ? a : best), 0);
    const e = [0, 0, 0]; e[axis] = 1;
    const side = sub(e, scale(local, dot(e, local)));
    return scale(side, 1 / norm(side));
  });
}

// Vertices of one octahedral bone: head, four corners of the widest square, tail. Corner 1 is
// the marked side (+u), corner 2 is +v = bone × u.
export const BONE_FACES = [[0, 1, 2], [0, 2, 3], [0, 3, 4], [0, 4, 1], [5, 2, 1], [5, 3, 2], [5, 4, 3], [5, 1, 4]];
/** The two faces between the marked corner (+u) and +v, head side and tail side: one quarter
 * of the bone in the marking colour, so a roll about the bone turns the stripe away. */
export const MARKED_FACES = new Set([0, 4]);
const WIDEST = 0.15; // the square sits at this fraction of the bone's length (Blender: 0.1)
const WIDTH = 0.16; // half-width of the square as a fraction of the bone's length (Blender: 0.1)

/**
 * Octahedral bones of one frame as Plotly mesh3d arrays (scene coordinates).
 *
 * @param points   (P, 3) positions, Y-up
 * @param rotations (P, 4) world unit quaternions, scalar-last
 * @param bones    [parent, child] pairs (bonesOf)
 * @param sides    marked side per bone in the parent's frame (boneSides)
 * @returns {{x: number[], y: number[], z: number[]}} 6 vertices per bone; a degenerate bone
 *          (zero length or a missing end) collapses onto its head so the faces stay the same.
 */
export function boneVertices(points, rotations, bones, sides, map = toScene) {
  const x = [], y = [], z = [];
  const put = (p) => { const s = map(p); x.push(s[0]); y.push(s[1]); z.push(s[2]); };
  bones.forEach(([p, c], b) => {
    const head = points[p], tail = points[c];
    if (!present(head) || !present(tail)) { for (let k = 0; k < 6; k++) put(present(head) ? head : [0, 0, 0]); return; }
    const d = sub(tail, head);
    const length = norm(d);
    if (!(length > 1e-9)) { for (let k = 0; k < 6; k++) put(head); return; }
    const along = scale(d, 1 / length);
    let u = rotate(rotations[p], sides[b]);
    u = sub(u, scale(along, dot(u, along)));
    const n = norm(u);
    u = n > 1e-9 ? scale(u, 1 / n) : [0, 0, 0];
    const v = cross(along, u);
    const mid = add(head, scale(d, WIDEST));
    const w = WIDTH * length;
    put(head);
    put(add(mid, scale(u, w))); put(add(mid, scale(v, w)));
    put(sub(mid, scale(u, w))); put(sub(mid, scale(v, w)));
    put(tail);
  });
  return { x, y, z };
}

/**
 * The octahedral bones of one frame written straight into `out` as triangle soup (8 faces × 3
 * vertices × xyz per bone, data coordinates): the same vertices as boneVertices followed by
 * triangleSoup, without allocating anything, for the 3D views' per-frame update.
 *
 * @param out Float32Array of at least bones.length * 72 values
 * @returns out
 */
export function boneSoup(points, rotations, bones, sides, out) {
  const v = SCRATCH; // 6 vertices × xyz of the bone being written
  let o = 0;
  for (let b = 0; b < bones.length; b++) {
    const [p, c] = bones[b];
    const head = points[p], tail = points[c];
    const headOk = present(head);
    if (!headOk || !present(tail)) {
      const at = headOk ? head : ORIGIN;
      for (let k = 0; k < 6; k++) { v[3 * k] = at[0]; v[3 * k + 1] = at[1]; v[3 * k + 2] = at[2]; }
    } else {
      const dx = tail[0] - head[0], dy = tail[1] - head[1], dz = tail[2] - head[2];
      const length = Math.hypot(dx, dy, dz);
      if (!(length > 1e-9)) {
        for (let k = 0; k < 6; k++) { v[3 * k] = head[0]; v[3 * k + 1] = head[1]; v[3 * k + 2] = head[2]; }
      } else {
        const ax = dx / length, ay = dy / length, az = dz / length;
        // u: the marked side turned by the parent's rotation, made perpendicular to the bone.
        const q = rotations[p], s0 = sides[b];
        const tx = 2 * (q[1] * s0[2] - q[2] * s0[1]), ty = 2 * (q[2] * s0[0] - q[0] * s0[2]), tz = 2 * (q[0] * s0[1] - q[1] * s0[0]);
        let ux = s0[0] + q[3] * tx + (q[1] * tz - q[2] * ty);
        let uy = s0[1] + q[3] * ty + (q[2] * tx - q[0] * tz);
        let uz = s0[2] + q[3] * tz + (q[0] * ty - q[1] * tx);
        const along = ux * ax + uy * ay + uz * az;
        ux -= along * ax; uy -= along * ay; uz -= along * az;
        const n = Math.hypot(ux, uy, uz);
        if (n > 1e-9) { ux /= n; uy /= n; uz /= n; } else { ux = 0; uy = 0; uz = 0; }
        const vx = ay * uz - az * uy, vy = az * ux - ax * uz, vz = ax * uy - ay * ux;
        const mx = head[0] + dx * WIDEST, my = head[1] + dy * WIDEST, mz = head[2] + dz * WIDEST;
        const w = WIDTH * length;
        v[0] = head[0]; v[1] = head[1]; v[2] = head[2];
        v[3] = mx + ux * w; v[4] = my + uy * w; v[5] = mz + uz * w;
        v[6] = mx + vx * w; v[7] = my + vy * w; v[8] = mz + vz * w;
        v[9] = mx - ux * w; v[10] = my - uy * w; v[11] = mz - uz * w;
        v[12] = mx - vx * w; v[13] = my - vy * w; v[14] = mz - vz * w;
        v[15] = tail[0]; v[16] = tail[1]; v[17] = tail[2];
      }
    }
    for (let f = 0; f < 8; f++) {
      const face = BONE_FACES[f];
      for (let k = 0; k < 3; k++) { const i = 3 * face[k]; out[o++] = v[i]; out[o++] = v[i + 1]; out[o++] = v[i + 2]; }
    }
  }
  return out;
}
const SCRATCH = new Float64Array(18);

/**
 * Flat shading baked into vertex colours, so the bones need no lit material (a CPU rasteriser
 * draws an unlit one faster, and compiles it sooner): every face of `count` bones of triangle
 * soup (boneSoup) takes `colorOf(bone, face)` ([r, g, b], linear) × (ambient + direct ×
 * max(0, n · light)) / π, as a Lambert material lit by an ambient and a directional light of
 * those intensities would show it. n is the face's normal turned away from its bone's centre.
 *
 * @param light unit vector toward the directional light
 * @returns out (Float32Array, 72 values per bone)
 */
export function shadeSoup(soup, count, colorOf, light, ambient, direct, out) {
  for (let b = 0; b < count; b++) {
    const base = 72 * b;
    let cx = 0, cy = 0, cz = 0;
    for (let k = 0; k < 24; k++) { cx += soup[base + 3 * k]; cy += soup[base + 3 * k + 1]; cz += soup[base + 3 * k + 2]; }
    cx /= 24; cy /= 24; cz /= 24;
    for (let f = 0; f < 8; f++) {
      const o = base + 9 * f;
      const ax = soup[o + 3] - soup[o], ay = soup[o + 4] - soup[o + 1], az = soup[o + 5] - soup[o + 2];
      const bx = soup[o + 6] - soup[o], by = soup[o + 7] - soup[o + 1], bz = soup[o + 8] - soup[o + 2];
      let nx = ay * bz - az * by, ny = az * bx - ax * bz, nz = ax * by - ay * bx;
      const n = Math.hypot(nx, ny, nz);
      let lit = 0;
      if (n > 0) {
        nx /= n; ny /= n; nz /= n;
        const outward = nx * ((soup[o] + soup[o + 3] + soup[o + 6]) / 3 - cx) + ny * ((soup[o + 1] + soup[o + 4] + soup[o + 7]) / 3 - cy) + nz * ((soup[o + 2] + soup[o + 5] + soup[o + 8]) / 3 - cz);
        const facing = (nx * light[0] + ny * light[1] + nz * light[2]) * (outward < 0 ? -1 : 1);
        lit = Math.max(0, facing);
      }
      const k = (ambient + direct * lit) / Math.PI;
      const c = colorOf(b, f);
      for (let v = 0; v < 3; v++) { out[o + 3 * v] = c[0] * k; out[o + 3 * v + 1] = c[1] * k; out[o + 3 * v + 2] = c[2] * k; }
    }
  }
  return out;
}
const ORIGIN = [0, 0, 0];

/** Face index arrays (i, j, k) of `count` bones, 6 vertices and 8 faces each. */
export function boneFaces(count) {
  const i = [], j = [], k = [];
  for (let b = 0; b < count; b++) for (const [a, c, e] of BONE_FACES) { i.push(6 * b + a); j.push(6 * b + c); k.push(6 * b + e); }
  return { i, j, k };
}

/**
 * Colour of every face: the marked side in `marked`, the rest in `body`; bones whose parent
 * joint is in `flagged` (a Map joint index -> colour) take that colour for the body.
 */
export function faceColors(bones, flagged, body, marked) {
  const colors = [];
  for (const [p] of bones) {
    const own = flagged.get(p) || body;
    for (let f = 0; f < 8; f++) colors.push(MARKED_FACES.has(f) ? marked : own);
  }
  return colors;
}

const AXIS_COLORS = ["#d62728", "#2ca02c", "#1f77b4"]; // x red, y green, z blue (as in Blender)

/** Per-joint axis triads as one line trace: 3 segments per joint with per-vertex colours. */
export function triads(points, rotations, joints, length, map = toScene) {
  const x = [], y = [], z = [], color = [];
  for (let j = 0; j < joints; j++) {
    const o = points[j], q = rotations[j];
    for (let a = 0; a < 3; a++) {
      const e = [0, 0, 0]; e[a] = length;
      const ok = present(o) && q;
      const s = ok ? map(o) : [null, null, null];
      const t = ok ? map(add(o, rotate(q, e))) : [null, null, null];
      x.push(s[0], t[0], null); y.push(s[1], t[1], null); z.push(s[2], t[2], null);
      color.push(AXIS_COLORS[a], AXIS_COLORS[a], AXIS_COLORS[a]);
    }
  }
  return { x, y, z, color };
}

/** Bones as line segments (keypoint takes, or the raw ghost), scene coordinates. */
export function boneLines(points, bones, map = toScene) {
  const x = [], y = [], z = [];
  for (const [p, c] of bones) {
    const a = points[p], b = points[c];
    if (!present(a) || !present(b)) continue;
    const s = map(a), t = map(b);
    x.push(s[0], t[0], null); y.push(s[1], t[1], null); z.push(s[2], t[2], null);
  }
  return { x, y, z };
}

/** Joint markers in scene coordinates (missing points as null: Plotly leaves them out). */
export function markers(points, map = toScene) {
  const x = [], y = [], z = [];
  for (const p of points) {
    const s = present(p) ? map(p) : [null, null, null];
    x.push(s[0]); y.push(s[1]); z.push(s[2]);
  }
  return { x, y, z };
}

/**
 * Scene ranges that hold every frame given (the whole take's motion), padded by `pad` of the
 * largest extent, with the floor at the lowest point: [[x0, x1], [y0, y1], [z0, z1]] in scene
 * coordinates, and the aspect ratio that keeps metres square.
 */
export function frameTake(frameSets, pad = 0.08) {
  const lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
  for (const frames of frameSets) for (const points of frames) for (const p of points) {
    if (!present(p)) continue;
    const s = toScene(p);
    for (let a = 0; a < 3; a++) { if (s[a] < lo[a]) lo[a] = s[a]; if (s[a] > hi[a]) hi[a] = s[a]; }
  }
  if (!Number.isFinite(lo[0])) return { ranges: [[-1, 1], [-1, 1], [0, 2]], aspect: { x: 1, y: 1, z: 1 } };
  const extent = Math.max(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]) || 1;
  const margin = pad * extent;
  const ranges = [0, 1, 2].map((a) => [lo[a] - (a === 2 ? 0 : margin), hi[a] + margin]);
  const sizes = ranges.map(([a, b]) => b - a);
  const largest = Math.max(...sizes);
  return { ranges, aspect: { x: sizes[0] / largest, y: sizes[1] / largest, z: sizes[2] / largest } };
}

/**
 * The size of the box that follows the body: the largest extent of the body in any frame, the
 * floor and ceiling over the take, and the radius of the sphere that holds every point of every
 * frame about the body's target: that frame's centre (centreOf) across the floor, half-way
 * between floor and ceiling in height (scene coordinates).
 */
export function bodyBox(frameSets, pad = 0.15) {
  let extent = 0, floor = Infinity, ceiling = -Infinity;
  for (const frames of frameSets) for (const points of frames) {
    const lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
    for (const p of points) {
      if (!present(p)) continue;
      const s = toScene(p);
      for (let a = 0; a < 3; a++) { if (s[a] < lo[a]) lo[a] = s[a]; if (s[a] > hi[a]) hi[a] = s[a]; }
    }
    if (!Number.isFinite(lo[0])) continue;
    extent = Math.max(extent, hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]);
    floor = Math.min(floor, lo[2]); ceiling = Math.max(ceiling, hi[2]);
  }
  if (!Number.isFinite(floor)) return { half: 1, floor: 0, ceiling: 2, radius: 1 };
  const middle = (floor + ceiling) / 2;
  let radius = 0;
  for (const frames of frameSets) for (const points of frames) {
    const c = centreOf(points);
    if (!c) continue;
    for (const p of points) if (present(p)) { const s = toScene(p); radius = Math.max(radius, Math.hypot(s[0] - c[0], s[1] - c[1], s[2] - middle)); }
  }
  return { half: (extent || 1) * (0.5 + pad), floor, ceiling, radius };
}

/**
 * How the camera frames the whole body (focus "body"): its target's height half-way between
 * the take's floor and ceiling, and its distance, at which the sphere of `box.radius` about the
 * target (every point of every frame) fits a camera of vertical field of view `fovDeg` with
 * `margin` of the radius to spare, whichever way the camera turns about the target (views wider
 * than tall, as the take view's, have at least that field across). `box` is a bodyBox.
 */
export function bodyFraming(box, fovDeg, margin = 0.08) {
  return { height: (box.floor + box.ceiling) / 2, distance: ((box.radius || 1) * (1 + margin)) / Math.sin((fovDeg * Math.PI) / 360) };
}

/** The centre of the present points (scene coordinates), or null when none is present. */
export function centreOf(points) {
  const sum = [0, 0, 0];
  let n = 0;
  for (const p of points) if (present(p)) { const s = toScene(p); sum[0] += s[0]; sum[1] += s[1]; sum[2] += s[2]; n += 1; }
  return n ? sum.map((v) => v / n) : null;
}

/**
 * Scene ranges of a box of half-size `box.half` around `centre` horizontally, from the floor
 * up: the skeleton fills the view and keeps its scale over the take.
 */
export function followRanges(centre, box) {
  const half = Math.max(box.half, (box.ceiling - box.floor) / 2);
  return [[centre[0] - half, centre[0] + half], [centre[1] - half, centre[1] + half], [box.floor, box.floor + 2 * half]];
}

/** Whether `centre` has drifted from the middle of `ranges` by more than `share` of the half-size. */
export function drifted(centre, ranges, share = 0.25) {
  return [0, 1].some((a) => {
    const [lo, hi] = ranges[a];
    return Math.abs(centre[a] - (lo + hi) / 2) > share * ((hi - lo) / 2);
  });
}

/** The root's path on the floor (scene coordinates, z at `floor`). */
export function groundPath(frames, root, floor) {
  const x = [], y = [], z = [];
  for (const points of frames) {
    const p = points[root];
    if (!present(p)) continue;
    const s = toScene(p);
    x.push(s[0]); y.push(s[1]); z.push(floor);
  }
  return { x, y, z };
}

/**
 * Where an orbiting camera sits (data coordinates, Y up): `azimuth` about the vertical from +Z
 * towards +X, `elevation` above the floor plane, both in radians, at `distance` from `target`.
 */
export function orbitPosition(target, azimuth, elevation, distance) {
  const flat = Math.cos(elevation) * distance;
  return [target[0] + flat * Math.sin(azimuth), target[1] + Math.sin(elevation) * distance, target[2] + flat * Math.cos(azimuth)];
}

/** Camera presets as orbit angles (radians): front looks along −Z, side along −X, top down. */
/**
 * The camera's target for a focus mode, in the data's (Y-up) coordinates: "joint" the point
 * `joint`, "root" the point `root` (the whole body's centre when it has none), "body" the
 * body's centre over the floor (the height of `target` kept). A missing point keeps `target`.
 */
export function focusTarget(mode, points, root, joint, target) {
  const at = (j) => (j != null && j >= 0 && present(points[j]) ? [points[j][0], points[j][1], points[j][2]] : null);
  const centre = centreOf(points); // Z-up: (x, −z, y)
  if (mode === "joint" && at(joint)) return at(joint);
  if (mode === "root" || mode === "joint") return at(root) || (centre ? [centre[0], centre[2], -centre[1]] : target);
  return centre ? [centre[0], target[1], -centre[1]] : target;
}

/**
 * A colour ([r, g, b] in 0–1) faded toward white by a detection confidence in [0, 1]: full at
 * 1, a pale `floor` share of it at 0 (a missing detection still shows where it was bridged).
 */
export function fade(color, confidence, floor = 0.15) {
  const k = floor + (1 - floor) * Math.max(0, Math.min(1, confidence));
  return color.map((v) => 1 - k * (1 - v));
}

/** Camera distance of a focus mode, for a body `size` across (close-in is nearer). */
export const focusDistance = (mode, size) => size * (mode === "joint" ? 0.7 : 1.5);

export const PRESETS = {
  front: { azimuth: 0, elevation: 0.3 },
  side: { azimuth: Math.PI / 2, elevation: 0.3 },
  top: { azimuth: 0, elevation: 1.55 },
};

/** Expand per-vertex arrays of bones (6 vertices each) into triangle soup (24 vertices each). */
export function triangleSoup(vertices, bones, out) {
  let o = 0;
  for (let b = 0; b < bones; b++) {
    for (const face of BONE_FACES) for (const v of face) {
      const k = 6 * b + v;
      out[o++] = vertices.x[k]; out[o++] = vertices.y[k]; out[o++] = vertices.z[k];
    }
  }
  return out;
}
