// Where the 3D views go on the one canvas that draws them all: the panels' rectangles in, the
// canvas's box and each panel's WebGL viewport out. Pure, no DOM. One canvas, not one per view:
// a software compositor reads every WebGL canvas back once per frame, and that read, not the
// drawing, was most of a frame's cost (docs/dashboard.md, "One canvas for both views").

/**
 * The canvas box holding every shown panel, and each panel's viewport inside it.
 *
 * @param panels  per view, its rectangle {left, top, width, height} in CSS pixels (any common
 *                origin, fractional allowed), or null for a hidden view
 * @returns {{box: {left: number, top: number, width: number, height: number},
 *            viewports: Array<{x: number, y: number, width: number, height: number} | null>}}
 *   `box` is the smallest whole-pixel rectangle holding every shown panel, in the panels'
 *   coordinates (all zero when none is shown); `viewports[k]` is panel k inside the box in whole
 *   CSS pixels, x from the box's left and y from its BOTTOM (WebGL's origin), null when hidden.
 *   Neighbouring panels round to viewports that neither overlap nor leave a gap between them.
 */
export function canvasLayout(panels) {
  const shown = panels.filter((p) => p && p.width > 0 && p.height > 0);
  if (!shown.length) return { box: { left: 0, top: 0, width: 0, height: 0 }, viewports: panels.map(() => null) };
  const left = Math.floor(Math.min(...shown.map((p) => p.left)));
  const top = Math.floor(Math.min(...shown.map((p) => p.top)));
  const right = Math.ceil(Math.max(...shown.map((p) => p.left + p.width)));
  const bottom = Math.ceil(Math.max(...shown.map((p) => p.top + p.height)));
  const box = { left, top, width: right - left, height: bottom - top };
  const viewports = panels.map((p) => {
    if (!p || !(p.width > 0 && p.height > 0)) return null;
    const x0 = Math.round(p.left - left), x1 = Math.round(p.left + p.width - left);
    const y0 = Math.round(p.top - top), y1 = Math.round(p.top + p.height - top);
    return { x: x0, y: box.height - y1, width: x1 - x0, height: y1 - y0 };
  });
  return { box, viewports };
}

/** Whether two layouts place the canvas and every viewport alike (nothing to resize). */
export function sameLayout(a, b) {
  if (!a || !b || a.viewports.length !== b.viewports.length) return false;
  const same = (p, q) => (p === null || q === null ? p === q : p.x === q.x && p.y === q.y && p.width === q.width && p.height === q.height);
  return a.box.left === b.box.left && a.box.top === b.box.top && a.box.width === b.box.width && a.box.height === b.box.height
    && a.viewports.every((v, k) => same(v, b.viewports[k]));
}
