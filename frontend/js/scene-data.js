// Pure data of the 3D views (scene3d.js): which joints are drawn and which root is followed,
// the vertex buffers a frame's points and axes are written into, the orbit's moves, a joint's
// hover label and the feet step's floor plane and its label. No three.js, no DOM: unit-tested
// with node --test.
import { bonesOf, present } from "./geometry.js";

/** Orbit limits: the elevation range (radians) and the zoom range (shares of the body's size). */
export const ELEVATION = [-0.2, 1.55];
export const ZOOM = [0.3, 8];

/**
 * The bones drawn, the joints left out and the root the camera follows.
 *
 * @param skeleton {names, parents, bones?, oriented}: keypoint takes of a known layout come with
 *   their bones; others are joined by parents
 * @returns {{bones: number[][], loose: Set<number>, drawnRoot: number}} A BVH joint the server
 *   joined by no bone (a static root left at the origin while its child carries the travel, as
 *   Bandai's joint_Root) is loose: not drawn, and the root followed is its child.
 */
export function drawnSkeleton(skeleton) {
  const { names, parents, oriented } = skeleton;
  const given = Boolean(skeleton.bones && skeleton.bones.length);
  const bones = given ? skeleton.bones : bonesOf(parents);
  const inBone = new Set(bones.flat());
  const loose = new Set(oriented && given ? names.map((_, j) => j).filter((j) => !inBone.has(j)) : []);
  const firstRoot = parents.indexOf(-1);
  const drawnRoot = loose.has(firstRoot) ? parents.findIndex((p, j) => p === firstRoot && !loose.has(j)) : firstRoot;
  return { bones, loose, drawnRoot };
}

/**
 * Write each point `j` kept by `keep(j, point)` into `out` (x, y, z at 3j), NaN where not kept
 * (a NaN vertex is not drawn).
 *
 * @returns the number of points kept
 */
export function writePoints(out, points, keep) {
  let kept = 0;
  points.forEach((p, j) => {
    const on = Boolean(keep(j, p));
    kept += on;
    out[3 * j] = on ? p[0] : NaN; out[3 * j + 1] = on ? p[1] : NaN; out[3 * j + 2] = on ? p[2] : NaN;
  });
  return kept;
}

/** Write line segments between the point pairs `pairs` into `out` (two vertices each); a pair
 * with a missing end is written at the origin, collapsed (not drawn). */
export function writeSegments(out, points, pairs) {
  let o = 0;
  for (const [p, c] of pairs) {
    const ok = present(points[p]) && present(points[c]);
    for (const q of [points[p], points[c]]) {
      out[o++] = ok ? q[0] : 0; out[o++] = ok ? q[1] : 0; out[o++] = ok ? q[2] : 0;
    }
  }
}

/**
 * Write joint axes (geometry.triads: x, y, z with a null after each segment) as line segments:
 * positions into `positions`, each segment's two vertices coloured by its axis (`axes`: three
 * {r, g, b}, x, y and z in turn) into `colors`.
 */
export function writeTriads(t, positions, colors, axes) {
  let o = 0, n = 0;
  for (let k = 0; k < t.x.length; k++) {
    if (t.x[k] === null && k % 3 === 2) continue;
    positions[o++] = t.x[k] ?? 0; positions[o++] = t.y[k] ?? 0; positions[o++] = t.z[k] ?? 0;
    const c = axes[Math.floor(n / 2) % 3]; n += 1;
    colors[3 * (n - 1)] = c.r; colors[3 * (n - 1) + 1] = c.g; colors[3 * (n - 1) + 2] = c.b;
  }
}

/** The orbit after a drag of (dx, dy) pixels: turned, its elevation kept in ELEVATION. */
export function dragged(orbit, dx, dy) {
  return { azimuth: orbit.azimuth - dx * 0.01, elevation: Math.max(ELEVATION[0], Math.min(ELEVATION[1], orbit.elevation + dy * 0.01)) };
}

/** The camera's distance after a wheel turn of `deltaY`, kept in ZOOM shares of `size`. */
export function zoomed(distance, deltaY, size) {
  return Math.max(size * ZOOM[0], Math.min(size * ZOOM[1], distance * Math.exp(deltaY * 0.001)));
}

/** A joint's hover label: its name, and with detection confidences the confidence, and (in the
 * corrected view) whether the filter bridged it or a gap fill wrote it. */
export function hoverLabel(name, frame, j, corrected) {
  if (!frame.confidence) return name;
  const bridged = frame.bridged && frame.bridged[j] && corrected ? " · bridged" : "";
  const filled = frame.filled && frame.filled[j] > 0 && corrected ? " · filled" : "";
  return `${name} · confidence ${frame.confidence[j].toFixed(2)}${bridged}${filled}`;
}

const AXES_BY_NAME = { X: 0, Y: 1, Z: 2 };

/** The fitted plane's gradient of a tilted floor ([gu, gw], finite), else null: level. */
function tiltOf(check) {
  if (!check || check.tilted !== true) return null;
  const g = check.plane_gradient, o = check.plane_origin;
  const finite = (pair) => Array.isArray(pair) && pair.length === 2 && pair.every(Number.isFinite);
  return finite(g) ? { gradient: g, origin: finite(o) ? o : [0, 0] } : null;
}

/**
 * The floor plane of the run's feet step, in the take's coordinates (as the views draw them),
 * over the take's horizontal extent: perpendicular to the up axis at the floor, or, when the
 * step found the floor tilted, the plane it fitted (its coordinate on the up axis at the
 * horizontal point p = (u, w), the two other axes in increasing order, is
 * `floor + sign(up) × (p − plane_origin) · plane_gradient`).
 *
 * @param feet      the run's `series.feet` ({up_axis: "Y", "-Y", "Z", …, floor: the floor's
 *   coordinate on the up axis (through plane_origin when tilted), take units, floor_check:
 *   {tilted, plane_gradient: [gu, gw] height per unit or null, plane_origin: [ou, ow]}}), or
 *   null / undefined when the feet step did not run or was skipped
 * @param frameSets lists of frames (each frame a list of [x, y, z] points, null or NaN where
 *   missing) whose horizontal extent the plane covers
 * @param pad       share of the larger horizontal extent added around it
 * @returns null without a feet step, a floor or a present point, else {axis (0, 1 or 2, the up
 *   axis), level (the plane's coordinate on that axis: the floor; at plane_origin when tilted),
 *   tilted (whether the fitted tilted plane is drawn), positions (Float32Array of 4 corners × x,
 *   y, z), index ([0, 1, 2, 0, 2, 3]: two triangles)}
 */
export function floorPlane(feet, frameSets, pad = 0.1) {
  const named = feet && typeof feet.up_axis === "string" ? /^([+-]?)([XYZ])$/i.exec(feet.up_axis.trim()) : null;
  if (!named || !Number.isFinite(feet.floor)) return null;
  const axis = AXES_BY_NAME[named[2].toUpperCase()];
  const sign = named[1] === "-" ? -1 : 1;
  const level = feet.floor;
  const tilt = tiltOf(feet.floor_check);
  const across = [0, 1, 2].filter((a) => a !== axis);
  const lo = [Infinity, Infinity], hi = [-Infinity, -Infinity];
  for (const frames of frameSets) for (const points of frames) for (const p of points) {
    if (!present(p)) continue;
    across.forEach((a, k) => { if (p[a] < lo[k]) lo[k] = p[a]; if (p[a] > hi[k]) hi[k] = p[a]; });
  }
  if (!Number.isFinite(lo[0])) return null;
  const margin = pad * Math.max(hi[0] - lo[0], hi[1] - lo[1]) || 1;
  const corners = [[lo[0] - margin, lo[1] - margin], [hi[0] + margin, lo[1] - margin], [hi[0] + margin, hi[1] + margin], [lo[0] - margin, hi[1] + margin]];
  const upAt = tilt
    ? (u, w) => level + sign * ((u - tilt.origin[0]) * tilt.gradient[0] + (w - tilt.origin[1]) * tilt.gradient[1])
    : () => level;
  const positions = new Float32Array(12);
  corners.forEach(([u, w], c) => { positions[3 * c + axis] = upAt(u, w); positions[3 * c + across[0]] = u; positions[3 * c + across[1]] = w; });
  return { axis, level, tilted: Boolean(tilt), positions, index: [0, 1, 2, 0, 2, 3] };
}

/** The floor toggle's label: "floor", or "floor (tilted 3.2°)" when the feet step found the
 * floor tilted (`feet`: the run's `series.feet`; the tilt in degrees when it has one). */
export function floorLabel(feet) {
  const check = feet && feet.floor_check;
  if (!check || check.tilted !== true) return "floor";
  return Number.isFinite(check.tilt_deg) ? `floor (tilted ${check.tilt_deg.toFixed(1)}°)` : "floor (tilted)";
}
