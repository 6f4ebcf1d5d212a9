// The one place the take view's shared state lives: frame, playback, selection, view options.
// Views read `state` and change it only through `set`, which tells every subscriber.

const INITIAL = {
  frame: 0, playing: false, speed: 1, joint: null, triads: false, overlay: false,
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
