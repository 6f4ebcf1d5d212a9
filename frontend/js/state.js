// The one place the take view's shared state lives: frame, playback, selection, view options.
// Views read `state` and change it only through `set`, which tells every subscriber.

export const state = {
  frame: 0, playing: false, speed: 1, joint: null, triads: false, overlay: false,
};
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
  Object.assign(state, { frame: 0, playing: false, speed: 1, joint: null, triads: false, overlay: false });
}
