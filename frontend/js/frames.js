// Packed frame windows (`/runs/{id}/frames.f32`) read into views of one buffer: no number is
// parsed or copied. Pure: an ArrayBuffer in, the window out (unit-tested with node --test).

/**
 * Read a packed window: a little-endian uint32 n, an n-byte JSON header, then float32 arrays
 * of shape (count, points, components) in the header's order.
 *
 * @param buffer ArrayBuffer of the whole answer
 * @returns {{frames: number[], n_frames: number, step: number, points: number}} plus one entry
 *   per array, as the JSON window has them: positions and rotations as
 *   frames[k][point] → Float32Array(3 or 4) (NaN where missing), one-component arrays
 *   (confidence, bridged) as frames[k] → Float32Array(points).
 */
export function unpackFrames(buffer) {
  const length = new DataView(buffer).getUint32(0, true);
  const header = JSON.parse(new TextDecoder().decode(new Uint8Array(buffer, 4, length)));
  const { start, step, count, points } = header;
  const window = { frames: Array.from({ length: count }, (_, k) => start + k * step), n_frames: header.n_frames, step, points };
  let offset = 4 + length;
  for (const [name, components] of header.arrays) {
    const all = new Float32Array(buffer, offset, count * points * components);
    offset += all.byteLength;
    const perFrame = points * components;
    window[name] = Array.from({ length: count }, (_, k) => {
      const frame = all.subarray(k * perFrame, (k + 1) * perFrame);
      if (components === 1) return frame;
      return Array.from({ length: points }, (_, p) => frame.subarray(p * components, (p + 1) * components));
    });
  }
  return window;
}

/** The index of the sample of a window (`frames`, `step`) nearest frame `f`, clamped to it. */
export const sampleOf = (source, f) => Math.max(0, Math.min(source.frames.length - 1, Math.round((f - source.frames[0]) / source.step)));
