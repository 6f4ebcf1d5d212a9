// The one place the take view's shared state lives: frame, playback, selection, view options.
// Views read `state` and change it only through `set`, which tells every subscriber.

const INITIAL = {
  frame: 0, playing: false, speed: 1, joint: null,
  triads: false, overlay: false, floor: true, // the view options: joint axes, raw as ghost, the floor plane
  loop: null, looping: false, // the in/out range [a, b] (frames) and whether playback loops over it
  focus: "body", // what the camera centres: "body", "joint" (close-in) or "root" (follow)
};
export const state = { ...INITIAL };
const listeners = new Set();

export function set(patch) {
  Object.assign(state, patch);
  for (const listener of listeners) listener(state, patch);
}

export function subscribe(listener) {
  listeners.add(listener);
  return () => listeners.delete(listener);
}

export function reset() {
  listeners.clear();
  Object.assign(state, INITIAL);
}

// The view options in the link, each written only when it differs from its default:
// axes=1 (joint axes), overlay=1 (raw as ghost), floor=0 (the floor plane hidden).
const VIEW_OPTIONS = [["triads", "axes"], ["overlay", "overlay"], ["floor", "floor"]];

/** The link parameters of the view options of `current` (a state), as [name, "0" | "1"] pairs:
 * only those that differ from the defaults. */
export function viewOptionParams(current) {
  return VIEW_OPTIONS.filter(([key]) => Boolean(current[key]) !== INITIAL[key])
    .map(([key, name]) => [name, current[key] ? "1" : "0"]);
}

/** The view options a link's parameters (URLSearchParams) carry, as a patch of the state: a
 * parameter absent, or neither "0" nor "1", leaves its option at its default. */
export function viewOptionsOf(params) {
  const patch = {};
  for (const [key, name] of VIEW_OPTIONS) {
    const value = params.get(name);
    if (value === "0" || value === "1") patch[key] = value === "1";
  }
  return patch;
}
