"""Off-screen pyvista canvases: start-up, drawing one skeleton pose, reading the pixels back.

Conventions
-----------
* pyvista is imported here, lazily, by :func:`load_pyvista`. ``VTK_DEFAULT_OPENGL_WINDOW`` is
  set to ``vtkEGLRenderWindow`` (unless already set) so VTK goes straight to Mesa's EGL
  software renderer on machines with no display and no GPU instead of first trying X.
* VTK is not thread-safe: two threads rendering at once corrupt its heap. Every function of
  this package that draws must run on one thread; :class:`mocapqa.render.service.RenderService`
  owns that thread for servers.
* Images are ``(H, W, 3)`` uint8 RGB arrays, row 0 at the top.
"""

from __future__ import annotations

import os
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

import numpy as np
from numpy.typing import NDArray

from mocapqa.core.arrays import BoolArray, FloatArray
from mocapqa.errors import RenderUnavailableError
from mocapqa.render.scene import CameraView, SkeletonTrack

__all__ = [
    "BACKGROUND",
    "BONE_COLOR",
    "FIXED_COLOR",
    "FLAG_COLOR",
    "JOINT_COLOR",
    "Canvas",
    "CanvasPool",
    "ImageArray",
    "load_pyvista",
    "png_bytes",
    "pool_or_own",
]

# An RGB image, shape (H, W, 3), row 0 at the top.
ImageArray = NDArray[np.uint8]

# Colours of the background, bones, joints, flagged and fixed joints, and the floor grid.
BACKGROUND = "white"
BONE_COLOR = "#5b6c80"
JOINT_COLOR = "#2f3b4a"
FLAG_COLOR = "#d62728"
FIXED_COLOR = "#2ca02c"
FLOOR_COLOR = "#c4c4c4"
MULTI_SAMPLES = 0


def load_pyvista() -> Any:
    """Import pyvista for off-screen use.

    Raises
    ------
    RenderUnavailableError
        If pyvista or VTK cannot be imported.
    """
    os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")
    try:
        import pyvista
    except Exception as e:
        raise RenderUnavailableError(
            f"Expected pyvista with VTK to import for off-screen rendering, got {e!r}; "
            "install pyvista and Mesa's EGL (Debian: libegl1 libegl-mesa0 libgl1-mesa-dri)"
        ) from e
    pyvista.OFF_SCREEN = True
    return pyvista


def png_bytes(image: ImageArray) -> bytes:
    """Encode an ``(H, W, 3)`` uint8 image as PNG bytes."""
    import imageio.v3 as iio

    return bytes(iio.imwrite("<bytes>", image, extension=".png"))


def _nice_spacing(length: float) -> float:
    exponent = np.floor(np.log10(max(length, 1e-12)))
    for step in (1.0, 2.0, 5.0, 10.0):
        if step * 10**exponent >= length:
            return float(step * 10**exponent)
    return float(10 ** (exponent + 1))


def _segment_cells(n_segments: int) -> NDArray[np.int64]:
    """VTK line cells of ``n_segments`` two-point segments over points ``2k`` and ``2k + 1``:
    ``[2, 0, 1, 2, 2, 3, …]``, shape (3 · n_segments,)."""
    return np.column_stack(
        [
            np.full(n_segments, 2),
            np.arange(0, 2 * n_segments, 2),
            np.arange(1, 2 * n_segments, 2),
        ]
    ).ravel()


class Canvas:
    """One off-screen window of ``columns`` side-by-side viewports, reused across images.

    Parameters
    ----------
    width_px, height_px : int
        Size of the whole image in pixels.
    columns : int
        Number of viewports side by side.

    Raises
    ------
    RenderUnavailableError
        If no off-screen OpenGL context can be created.
    """

    def __init__(self, width_px: int, height_px: int, columns: int = 1) -> None:
        self.pv = load_pyvista()
        self.columns = columns
        self.size = (width_px, height_px)
        try:
            self.plotter = self.pv.Plotter(
                off_screen=True,
                window_size=(width_px, height_px),
                shape=(1, columns),
                border=False,
            )
            # FXAA smooths edges at a fraction of the cost of multisampling in Mesa's
            # software rasteriser (the theme's 8× MSAA doubled the time per frame).
            self.plotter.render_window.SetMultiSamples(MULTI_SAMPLES)
            for renderer in self.plotter.renderers:
                renderer.UseFXAAOn()
        except Exception as e:
            raise RenderUnavailableError(
                f"Expected an off-screen OpenGL window ({os.environ['VTK_DEFAULT_OPENGL_WINDOW']}),"
                f" got {e!r}; install Mesa's EGL (libegl1 libegl-mesa0 libgl1-mesa-dri)"
            ) from e
        self._sphere_cache: dict[float, Any] = {}

    def clear(self) -> None:
        """Remove every actor, text and legend from every viewport."""
        for column in range(self.columns):
            self.plotter.subplot(0, column)
            self.plotter.remove_legend()
            self.plotter.renderer.clear()
            self.plotter.renderer.RemoveAllViewProps()
            self.plotter.set_background(BACKGROUND)

    def _add_actor(self, mesh: Any, color: str, smooth: bool = True) -> None:
        # A bare VTK actor: pyvista's add_mesh costs ~10 ms of Python per call, which
        # dominated clip rendering.
        from vtkmodules.vtkRenderingCore import vtkActor, vtkPolyDataMapper

        mapper = vtkPolyDataMapper()
        mapper.SetInputData(mesh)
        mapper.ScalarVisibilityOff()
        actor = vtkActor()
        actor.SetMapper(mapper)
        prop = actor.GetProperty()
        prop.SetColor(self.pv.Color(color).float_rgb)
        if smooth:
            prop.SetInterpolationToPhong()
        else:
            prop.LightingOff()
        self.plotter.renderer.AddActor(actor)

    def _sphere(self, radius: float) -> Any:
        if radius not in self._sphere_cache:
            self._sphere_cache[radius] = self.pv.Sphere(
                radius=radius, theta_resolution=14, phi_resolution=14
            )
        return self._sphere_cache[radius]

    def _floor(self, track: SkeletonTrack, camera: CameraView) -> Any:
        up_index = "xyz".index(track.up_axis[1])
        a, b = [i for i in range(3) if i != up_index]
        a0, a1, b0, b1 = camera.floor_extent
        step = _nice_spacing(max(a1 - a0, b1 - b0) / 12)
        a_values = np.arange(np.floor(a0 / step), np.ceil(a1 / step) + 1) * step
        b_values = np.arange(np.floor(b0 / step), np.ceil(b1 / step) + 1) * step
        segments = []
        for value in a_values:
            segments.append(((value, b_values[0]), (value, b_values[-1])))
        for value in b_values:
            segments.append(((a_values[0], value), (a_values[-1], value)))
        points = np.zeros((2 * len(segments), 3))
        for k, ((pa, pb), (qa, qb)) in enumerate(segments):
            points[2 * k, [a, b]] = pa, pb
            points[2 * k + 1, [a, b]] = qa, qb
        points[:, up_index] = camera.floor_height
        return self.pv.PolyData(points, lines=_segment_cells(len(segments)))

    def draw(
        self,
        column: int,
        track: SkeletonTrack,
        frame: int,
        camera: CameraView,
        flagged: BoolArray | None = None,
        title: str | None = None,
        flag_color: str = FLAG_COLOR,
        legend: bool = True,
    ) -> None:
        """Draw one pose into viewport ``column``.

        Parameters
        ----------
        column : int
            Viewport index, 0-based from the left.
        track : SkeletonTrack
            The skeleton.
        frame : int
            Frame index, 0-based.
        camera : CameraView
            Where to look from.
        flagged : ndarray of bool, shape (J,), optional
            Joints to colour with ``flag_color`` (and the bones ending at them).
        title : str, optional
            Text in the top-left corner.
        flag_color : str
            Colour of flagged joints.
        legend : bool
            Whether to add a legend naming the flagged joints.
        """
        self.plotter.subplot(0, column)
        points = track.positions[frame]
        valid = np.all(np.isfinite(points), axis=1)
        marks = (
            np.zeros(len(points), dtype=bool)
            if flagged is None
            else np.asarray(flagged, dtype=bool)
        )
        self._add_actor(self._floor(track, camera), FLOOR_COLOR, smooth=False)
        self._bones(track, points, valid, marks, flag_color)
        self._joints(track.height, points, valid, marks, flag_color)
        if title:
            self._title(title)
        flagged_names = [track.names[j] for j in np.flatnonzero(marks)]
        if legend and flagged_names:
            self._legend(flagged_names, flag_color)
        self._aim(camera)

    def _bones(
        self,
        track: SkeletonTrack,
        points: FloatArray,
        valid: BoolArray,
        marks: BoolArray,
        flag_color: str,
    ) -> None:
        """Tubes along the bones whose two ends are known, those ending at a flagged joint in
        ``flag_color``."""
        bones = (
            track.bones[valid[track.bones[:, 0]] & valid[track.bones[:, 1]]]
            if len(track.bones)
            else track.bones
        )
        for selection, color in (
            (~marks[bones[:, 1]], BONE_COLOR),
            (marks[bones[:, 1]], flag_color),
        ):
            chosen = bones[selection]
            if len(chosen) == 0:
                continue
            ends = points[chosen].reshape(-1, 3)
            lines = _segment_cells(len(chosen))
            tubes = self.pv.PolyData(ends, lines=lines).tube(
                radius=0.008 * track.height, n_sides=10
            )
            self._add_actor(tubes, color)

    def _joints(
        self,
        height: float,
        points: FloatArray,
        valid: BoolArray,
        marks: BoolArray,
        flag_color: str,
    ) -> None:
        """A sphere on each known joint, flagged ones twice as large in ``flag_color``."""
        for selection, color, scale in ((~marks, JOINT_COLOR, 0.015), (marks, flag_color, 0.03)):
            chosen_points = points[selection & valid]
            if len(chosen_points) == 0:
                continue
            glyphs = self.pv.PolyData(chosen_points).glyph(
                geom=self._sphere(round(scale * height, 9)), scale=False, orient=False
            )
            self._add_actor(glyphs, color)

    def _legend(self, flagged_names: list[str], flag_color: str) -> None:
        """A legend naming the first three flagged joints, and the bones' colour."""
        shown = (
            "flagged: " + ", ".join(flagged_names[:3]) + (" …" if len(flagged_names) > 3 else "")
        )
        self.plotter.add_legend(
            labels=[[shown, flag_color], ["bones", BONE_COLOR]],
            bcolor="white",
            border=True,
            loc="lower left",
            size=(min(0.95, 0.1 + 0.022 * len(shown)), 0.1),
            face="circle",
        )

    def _aim(self, camera: CameraView) -> None:
        """Point the current viewport's camera as ``camera`` says (30° view angle)."""
        # Setting the camera object's fields directly avoids pyvista's extra render per change.
        plotter = self.plotter
        vtk_camera = plotter.renderer.GetActiveCamera()
        vtk_camera.SetPosition(camera.position)
        vtk_camera.SetFocalPoint(camera.focal_point)
        vtk_camera.SetViewUp(camera.view_up)
        vtk_camera.SetViewAngle(30.0)
        plotter.renderer.camera_set = True
        plotter.renderer.reset_camera_clipping_range()

    def _title(self, title: str) -> None:
        """Text in the top-left corner of the current viewport."""
        self.plotter.add_text(
            title,
            # A multi-line text actor grows upward from its anchor.
            position=(0.02, 0.93 - 0.055 * title.count("\n")),
            viewport=True,
            font_size=9,
            color="black",
            render=False,
        )

    def caption(self, column: int, title: str) -> None:
        """Write ``title`` in the top-left corner of viewport ``column`` and draw nothing else.

        Parameters
        ----------
        column : int
            Viewport index, 0-based from the left.
        title : str
            The text; lines split on ``\\n``.
        """
        self.plotter.subplot(0, column)
        self._title(title)

    def image(self) -> ImageArray:
        """The rendered pixels, shape (H, W, 3) uint8."""
        self.plotter.render()
        image = self.plotter.screenshot(return_img=True)
        return np.ascontiguousarray(np.asarray(image, dtype=np.uint8)[..., :3])

    def close(self) -> None:
        """Free the window."""
        self.plotter.close()


class CanvasPool:
    """Canvases kept open by size, so repeated images skip window creation (one thread only)."""

    def __init__(self) -> None:
        self._canvases: dict[tuple[int, int, int], Canvas] = {}

    def get(self, width_px: int, height_px: int, columns: int = 1) -> Canvas:
        """A cleared canvas of this size, created on first use."""
        key = (width_px, height_px, columns)
        if key not in self._canvases:
            self._canvases[key] = Canvas(width_px, height_px, columns)
        canvas = self._canvases[key]
        canvas.clear()
        return canvas

    def close(self) -> None:
        """Close every canvas."""
        for canvas in self._canvases.values():
            canvas.close()
        self._canvases.clear()


@contextmanager
def pool_or_own(canvases: CanvasPool | None) -> Iterator[CanvasPool]:
    """The caller's pool of canvases, or a pool of this block's own, closed when it ends.

    Parameters
    ----------
    canvases : CanvasPool, optional
        Reused windows; left open.
    """
    pool = canvases or CanvasPool()
    try:
        yield pool
    finally:
        if canvases is None:
            pool.close()
