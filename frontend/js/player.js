// Playback at the take's true rate: each animation frame shows the frame due at that instant
// (so a slow redraw drops frames rather than slowing time), and pausing stops at once.
// A loop range [in, out] keeps playback inside those frames.

/**
 * The frame due `advance` frames after playback started at `startFrame`: the take wraps at its
 * end; with a loop range [a, b] playback starts at a when it started outside, and wraps at b.
 */
export function playbackFrame(startFrame, advance, nFrames, range = null) {
  if (!range) return (startFrame + advance) % nFrames;
  const [a, b] = range;
  const start = startFrame < a || startFrame > b ? a : startFrame;
  return a + ((start - a + advance) % (b - a + 1));
}

/**
 * @param fps       the take's frame rate
 * @param nFrames   frames in the take
 * @param onFrame   called with the frame due now (only when it changed)
 * @param getFrame  the frame shown now (where playback starts)
 */
export function createPlayer({ fps, nFrames, onFrame, getFrame }) {
  let handle = 0, startTime = 0, startFrame = 0, speed = 1, playing = false, last = -1, range = null;
  const stats = { ticks: 0, shown: 0, startedAt: 0 };
  const tick = (now) => {
    if (!playing) return;
    stats.ticks += 1;
    const frame = playbackFrame(startFrame, Math.floor(((now - startTime) / 1000) * fps * speed), nFrames, range);
    if (frame !== last) { last = frame; stats.shown += 1; onFrame(frame); }
    handle = requestAnimationFrame(tick);
  };
  const restart = () => {
    startTime = performance.now();
    startFrame = playbackFrame(getFrame(), 0, nFrames, range);
    last = -1;
  };
  return {
    get playing() { return playing; },
    get loop() { return range ? [...range] : null; },
    stats,
    play() {
      if (playing) return;
      playing = true; restart();
      stats.ticks = 0; stats.shown = 0; stats.startedAt = startTime;
      handle = requestAnimationFrame(tick);
    },
    pause() { playing = false; cancelAnimationFrame(handle); },
    setSpeed(value) { speed = value; if (playing) restart(); },
    /** Loop over [a, b] (frames, both shown), or over the whole take with null. */
    setLoop(next) { range = next ? [Math.min(...next), Math.max(...next)] : null; if (playing) restart(); },
  };
}
