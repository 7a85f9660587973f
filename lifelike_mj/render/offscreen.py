"""The offscreen renderer: a compiled MuJoCo model drawn into RGB images, with no window.

:class:`Offscreen` works headless (EGL or OSMesa, chosen by :mod:`lifelike_mj.render.gl`); it is
what the videos, snapshots and frames of every creature draw with. It knows nothing of creatures:
a creature's module dresses its own model (lights, textures) before handing it over.
"""

from __future__ import annotations

import contextlib

import numpy as np

from lifelike_mj.errors import UserError
from lifelike_mj.render.gl import gl_context


class Offscreen:
    """An offscreen renderer (OpenGL context, scene, pixel buffer) of one compiled model.

    ``Offscreen(m, width, height)`` opens a context (:func:`~lifelike_mj.render.gl.gl_context`);
    :meth:`update` builds the scene of an ``MjData`` seen from an ``MjvCamera``, :meth:`draw`
    renders it into an ``(height, width, 3)`` uint8 RGB image, top row first. Sites are hidden
    (they mark points for the physics: centres of pressure, wing tips). Use it as a context
    manager, or call :meth:`close`.
    """

    def __init__(self, m, width: int, height: int, maxgeom: int = 1000) -> None:
        import mujoco

        self.width, self.height = int(width), int(height)
        # the offscreen framebuffer is sized from the model when the MjrContext is made
        m.vis.global_.offwidth = max(int(m.vis.global_.offwidth), self.width)
        m.vis.global_.offheight = max(int(m.vis.global_.offheight), self.height)
        self.ctx, self.backend = gl_context(self.width, self.height)
        try:
            self.con = mujoco.MjrContext(m, mujoco.mjtFontScale.mjFONTSCALE_100)
        except Exception as exc:  # noqa: BLE001 - e.g. glfw without a display leaves no current context
            with contextlib.suppress(Exception):
                self.ctx.free()
            raise UserError(f"the OpenGL backend {self.backend} created no usable context ({exc.__class__.__name__}); "
                            "try MUJOCO_GL=egl or MUJOCO_GL=osmesa.") from None
        mujoco.mjr_setBuffer(mujoco.mjtFramebuffer.mjFB_OFFSCREEN, self.con)
        self.scn = mujoco.MjvScene(m, maxgeom)
        self.opt = mujoco.MjvOption()
        self.opt.sitegroup[:] = 0  # hide the centre-of-pressure and tip markers
        self.pert = mujoco.MjvPerturb()
        self.rect = mujoco.MjrRect(0, 0, self.width, self.height)
        self._rgb = np.empty((self.height, self.width, 3), dtype=np.uint8)

    def set_size(self, width: int, height: int) -> None:
        """Draw ``width`` x ``height`` pixels from now on (at most the size the renderer was made with)."""
        import mujoco

        self.width, self.height = int(width), int(height)
        self.rect = mujoco.MjrRect(0, 0, self.width, self.height)
        self._rgb = np.empty((self.height, self.width, 3), dtype=np.uint8)

    def __enter__(self) -> Offscreen:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def update(self, m, d, cam, moving_only: bool = False) -> None:
        """Build the scene of ``d`` seen from ``cam`` (an ``MjvCamera``); ``moving_only``: no ground."""
        import mujoco

        cat = mujoco.mjtCatBit.mjCAT_DYNAMIC if moving_only else mujoco.mjtCatBit.mjCAT_ALL
        mujoco.mjv_updateScene(m, d, self.opt, self.pert, cam, cat, self.scn)

    def add(self, m, d) -> None:
        """Add the moving geoms of ``d`` to the current scene (for overlays)."""
        import mujoco

        mujoco.mjv_addGeoms(m, d, self.opt, self.pert, mujoco.mjtCatBit.mjCAT_DYNAMIC, self.scn)

    def draw(self) -> np.ndarray:
        """Render the current scene; an ``(height, width, 3)`` uint8 image, top row first."""
        import mujoco

        self.ctx.make_current()
        mujoco.mjr_render(self.rect, self.scn, self.con)
        mujoco.mjr_readPixels(self._rgb, None, self.rect, self.con)
        return np.flipud(self._rgb).copy()

    def project(self, points: np.ndarray) -> np.ndarray:
        """Pixel coordinates ``(u, v)`` (from the top-left) of world points (m) in the last scene."""
        import mujoco

        cam = mujoco.mjv_averageCamera(self.scn.camera[0], self.scn.camera[1])  # mono view: between the eyes
        pos, fwd, up = np.array(cam.pos), np.array(cam.forward), np.array(cam.up)
        right = np.cross(fwd, up)
        rel = np.atleast_2d(points) - pos
        x, y, z = rel @ right, rel @ up, rel @ fwd
        if not cam.orthographic:
            x, y = x * cam.frustum_near / z, y * cam.frustum_near / z
        top, bottom = cam.frustum_top, cam.frustum_bottom
        half_w = cam.frustum_width or 0.5 * (top - bottom) * self.width / self.height
        u = (x - (cam.frustum_center - half_w)) / (2.0 * half_w) * self.width
        v = (top - y) / (top - bottom) * self.height
        return np.stack([u, v], axis=1)

    def close(self) -> None:
        with contextlib.suppress(Exception):
            self.ctx.make_current()
            self.con.free()
        with contextlib.suppress(Exception):
            self.ctx.free()


def gl_renderer_name() -> str:
    """The OpenGL renderer's name (``llvmpipe`` = software, or the GPU's) of the current context."""
    with contextlib.suppress(Exception):
        from OpenGL import GL

        name = GL.glGetString(GL.GL_RENDERER)
        if name:
            return name.decode(errors="replace") if isinstance(name, bytes) else str(name)
    return "unknown"
