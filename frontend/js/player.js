// Playback at the take's true rate: each animation frame shows the frame due at that instant
// (so a slow redraw drops frames rather than slowing time), and pausing stops at once.

/**
 * @param fps       the take's frame rate
 * @param nFrames   frames in the take
 * @param onFrame   called with the frame due now (only when it changed)
 * @param getFrame  the frame shown now (where playback starts)
 */
export function createPlayer({ fps, nFrames, onFrame, getFrame }) {
  let handle = 0, startTime = 0, startFrame = 0, speed = 1, playing = false, last = -1;
  const stats = { ticks: 0, shown: 0, startedAt: 0 };
  const tick = (now) => {
    if (!playing) return;
    stats.ticks += 1;
    const frame = (startFrame + Math.floor(((now - startTime) / 1000) * fps * speed)) % nFrames;
    if (frame !== last) { last = frame; stats.shown += 1; onFrame(frame); }
    handle = requestAnimationFrame(tick);
  };
  const restart = () => { startTime = performance.now(); startFrame = getFrame(); last = startFrame; };
  return {
    get playing() { return playing; },
    stats,
    play() {
      if (playing) return;
      playing = true; restart();
      stats.ticks = 0; stats.shown = 0; stats.startedAt = startTime;
      handle = requestAnimationFrame(tick);
    },
    pause() { playing = false; cancelAnimationFrame(handle); },
    setSpeed(value) { speed = value; if (playing) restart(); },
  };
}
