"""Videos and images out of rendered frames: MP4 and GIF writers, one frame loop, one recorder.

* :func:`film` films any stepper (the shape every creature's simulation has: ``steps``,
  ``step(n)``, ``sync()``, ``model``, ``data``; :mod:`lifelike_mj.stepper`) or a recorded run
  played back in that shape: frame ``j`` shows the state at step ``frames[j]``.
* :func:`write_frames` is the loop under it (advance, draw, encode), timed part by part;
  :func:`video_report` the keys every video reports.
* Every file is written atomically (a temporary file beside it, renamed when complete), so an
  error or Ctrl-C leaves nothing half-written.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from lifelike_mj import checks
from lifelike_mj.errors import UserError
from lifelike_mj.io import atomic_path


class MP4Writer:
    """H.264 MP4 through imageio-ffmpeg; frames are ``(h, w, 3)`` uint8."""

    def __init__(self, path: Path, fps: float) -> None:
        import imageio.v2 as iio

        try:
            meta = _provenance_text()
            self._w = iio.get_writer(str(path), format="FFMPEG", mode="I", fps=fps, codec="libx264", quality=8,
                                     pixelformat="yuv420p", macro_block_size=2, ffmpeg_log_level="error",
                                     output_params=["-metadata", f"comment={meta}"])
        except (ImportError, RuntimeError, ValueError) as exc:
            raise UserError(f"cannot write MP4 ({exc.__class__.__name__}); install imageio-ffmpeg or write a "
                            ".gif.") from None

    def add(self, frame: np.ndarray) -> None:
        self._w.append_data(frame)

    def close(self) -> None:
        self._w.close()


class GIFWriter:
    """An animated GIF through Pillow (255 colours per frame, looping)."""

    def __init__(self, path: Path, fps: float) -> None:
        self.path, self.fps, self.frames = path, fps, []

    def add(self, frame: np.ndarray) -> None:
        from PIL import Image

        self.frames.append(Image.fromarray(frame).quantize(colors=255, method=Image.Quantize.MEDIANCUT))

    def close(self) -> None:
        if self.frames:
            ms = max(20, int(round(1000.0 / self.fps)))  # browsers treat < 20 ms as 100 ms
            self.frames[0].save(self.path, format="GIF", save_all=True, append_images=self.frames[1:], duration=ms,
                                loop=0, disposal=1, optimize=False, comment=_provenance_text().encode()[:255])


def _provenance_text() -> str:
    """``lifelike-mj VERSION; COMMAND``: what a video file records of where it came from."""
    from lifelike_mj.provenance import png_metadata

    meta = png_metadata()
    return f"{meta['Software']}; {meta['Description']}"


#: Writer class by file suffix.
WRITERS = {".mp4": MP4Writer, ".gif": GIFWriter}


def check_size(width: int, height: int, what: str) -> None:
    """A :class:`UserError` unless ``width`` and ``height`` are whole numbers of pixels in 8-4096."""
    for name, v in (("width", width), ("height", height)):
        if not checks.is_whole(v) or not 8 <= v <= 4096:
            raise UserError(f"{what} {name} must be a whole number of pixels between 8 and 4096, got {v!r}.")


def write_frames(out: Path, suffix: str, fps: float, n_frames: int, advance: Callable[[int], None],
                 draw: Callable[[int], np.ndarray], desc: str = "render", progress: bool = False) -> dict[str, float]:
    """Write ``n_frames`` frames to ``out`` (atomically; nothing left on an error): frame ``j`` is
    ``advance(j)`` (the simulation) then ``draw(j)`` (an RGB image), then encoding. Returns the wall
    seconds of each part: ``{"sim_s", "render_s", "encode_s"}``."""
    checks.work(f"a video of {n_frames:,} frames", n_frames, checks.MAX_FRAMES, "frames", "a shorter video or fewer "
                "frames per second")
    sim_s = render_s = encode_s = 0.0
    bar = None
    if progress:
        from lifelike_mj.progress import bar as progress_bar

        bar = progress_bar(n_frames, desc, unit="frame")
    try:
        with atomic_path(out) as tmp:
            writer = WRITERS[suffix](tmp, fps)
            try:
                for j in range(n_frames):
                    t0 = time.perf_counter()
                    advance(j)
                    t1 = time.perf_counter()
                    frame = draw(j)
                    t2 = time.perf_counter()
                    writer.add(frame)
                    sim_s += t1 - t0
                    render_s += t2 - t1
                    encode_s += time.perf_counter() - t2
                    if bar is not None:
                        bar.update(1)
            finally:
                t0 = time.perf_counter()
                writer.close()
                encode_s += time.perf_counter() - t0
    finally:
        if bar is not None:
            bar.close()
    return {"sim_s": sim_s, "render_s": render_s, "encode_s": encode_s}


def video_report(out: Path, n_frames: int, fps: float, width: int, height: int, camera: str, gl_backend: str,
                  times: dict[str, float], t_start: float, warm_s: float = 0.0) -> dict:
    """The keys every rendered video reports: the file, frames, size, camera, and the wall seconds of
    simulation (``warm_s`` of warm-up added), rendering and encoding (``times``: from
    :func:`write_frames`), the whole call since ``t_start`` (a ``time.perf_counter()``), and the
    rendering rate."""
    sim_s, render_s, encode_s = warm_s + times["sim_s"], times["render_s"], times["encode_s"]
    return {
        "path": str(out),
        "frames": n_frames,
        "fps": fps,
        "width": width,
        "height": height,
        "camera": camera,
        "seconds": n_frames / fps,
        "gl_backend": gl_backend,
        "sim_s": sim_s,
        "render_s": render_s,
        "encode_s": encode_s,
        "wall_s": time.perf_counter() - t_start,
        "render_fps": n_frames / render_s if render_s > 0 else float("inf"),
    }


def video_target(out_path: str | Path, width: int, height: int) -> tuple[Path, str]:
    """The video's path and its lower-case suffix (a key of ``WRITERS``); :class:`UserError` for another
    suffix, a size outside 8-4096 pixels, or an odd size for an MP4."""
    out = Path(out_path)
    suffix = out.suffix.lower()
    if suffix not in WRITERS:
        raise UserError(f"cannot write {out.name}: the video file must end in .mp4 or .gif.")
    check_size(width, height, "video")
    if suffix == ".mp4" and (width % 2 or height % 2):
        raise UserError(f"an MP4 video needs an even width and height, got {width}x{height}.")
    return out, suffix


def advance_to(stepper: Any, step: int) -> None:
    """Step ``stepper`` forward to step ``step`` (no-op if it is there) and :meth:`sync` it for drawing."""
    n = int(step) - int(stepper.steps)
    if n < 0:
        raise ValueError(f"cannot step backwards from step {stepper.steps} to {step}")
    if n:
        stepper.step(n)
    stepper.sync()


def film(out_path: str | Path, stepper: Any, frames: Sequence[int] | Sequence[Sequence[int]], renderer: Any,
         camera: Any, fps: float, camera_name: str = "", progress: bool = False, desc: str = "render") -> dict:
    """Film ``stepper`` into ``out_path`` (``.mp4`` or ``.gif``), one frame per entry of ``frames``.

    ``frames[j]`` is the step shown by frame ``j`` (non-decreasing), or a list of steps whose
    renders are averaged (motion blur). ``renderer``: an :class:`~lifelike_mj.render.offscreen.Offscreen`
    of ``stepper.model`` (the caller owns it and closes it); ``camera``: an ``MjvCamera``, or a
    function of the frame index returning one (a camera that follows something). Returns
    :func:`video_report`'s keys.
    """
    out, suffix = video_target(out_path, renderer.width, renderer.height)
    fps = checks.positive("fps", fps)
    checks.work(f"a video of {len(frames):,} frames", len(frames), checks.MAX_FRAMES, "frames",
                "a shorter video or fewer frames per second")
    t_start = time.perf_counter()
    steps = [list(f) if isinstance(f, (list, tuple, np.ndarray)) else [int(f)] for f in frames]

    def cam(j: int):
        return camera(j) if callable(camera) else camera

    def advance(j: int) -> None:  # a blurred frame steps inside draw(), between its renders
        if len(steps[j]) == 1:
            advance_to(stepper, steps[j][0])

    def draw(j: int) -> np.ndarray:
        if len(steps[j]) == 1:
            renderer.update(stepper.model, stepper.data, cam(j))
            return renderer.draw()
        acc = np.zeros((renderer.height, renderer.width, 3), dtype=np.float32)
        for s in steps[j]:
            advance_to(stepper, max(int(stepper.steps), int(s)))
            renderer.update(stepper.model, stepper.data, cam(j))
            acc += renderer.draw()
        return np.clip(acc / len(steps[j]) + 0.5, 0, 255).astype(np.uint8)

    times = write_frames(out, suffix, fps, len(steps), advance, draw, desc, progress)
    return video_report(out, len(steps), fps, renderer.width, renderer.height, camera_name, renderer.backend, times,
                        t_start)


def write_png(out_path: str | Path, image: np.ndarray) -> Path:
    """Write an RGB image (``(h, w, 3)`` uint8) as a PNG, atomically; return the path."""
    from PIL import Image

    out = Path(out_path)
    if out.suffix.lower() != ".png":
        raise UserError(f"cannot write {out.name}: an image is written as a .png file.")
    with atomic_path(out) as tmp:
        Image.fromarray(np.asarray(image, dtype=np.uint8)).save(tmp, format="PNG")
    return out
