"""Rendering that knows no creature: OpenGL, an offscreen renderer, video writers, one recorder,
one viewer loop, cameras and plot helpers.

* :mod:`~lifelike_mj.render.gl`: :func:`ensure_gl_backend` (call before ``mujoco`` is imported on a
  headless machine), :func:`~lifelike_mj.render.gl.gl_context`;
* :mod:`~lifelike_mj.render.offscreen`: :class:`Offscreen`, a model drawn into RGB arrays;
* :mod:`~lifelike_mj.render.video`: :func:`film` (any stepper, or a recorded run played back, into an
  MP4 or GIF), :func:`write_png`, the MP4/GIF writers;
* :mod:`~lifelike_mj.render.viewer`: :func:`view` (the MuJoCo viewer on a live stepper, real time);
* :mod:`~lifelike_mj.render.camera`: tracking, fixed and free cameras;
* :mod:`~lifelike_mj.render.plot`: figures on the Agg canvas (:func:`new_figure`, :func:`save`).

Importing this package does not import ``mujoco``.
"""

from lifelike_mj._lazy import attach

__getattr__, __dir__, __all__ = attach(__name__, {
    "ensure_gl_backend": "gl", "Offscreen": "offscreen", "film": "video", "write_png": "video", "has_display": "viewer",
    "require_display": "viewer", "view": "viewer", "new_figure": "plot", "save": "plot",
    "gl": ".", "offscreen": ".", "video": ".", "viewer": ".", "camera": ".", "plot": ".", "web": ".",
}, globals())
