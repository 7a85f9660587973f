"""The motion leaving the project: a run's body poses (:func:`~lifelike_mj.export.poses.record_poses`) written
as animated glTF 2.0 (:func:`~lifelike_mj.export.gltf.write_gltf`) for Blender, game engines and the web.

Works on any simulation in the stepper shape (:class:`lifelike_mj.stepper.Stepper`): it reads only
``model``, ``data``, ``step``, ``sync`` and ``dt``.
"""

from __future__ import annotations

from pathlib import Path

from lifelike_mj.errors import UserError

#: Each format and the file endings it is written to.
FORMATS = {"glb": (".glb",), "gltf": (".gltf",), "usd": (".usda", ".usdc", ".usd", ".usdz"), "html": (".html",)}


def format_of(path: str | Path, fmt: str | None = None) -> str:
    """The format of ``path`` from its ending, checked against ``fmt`` where it is given."""
    suffix = Path(path).suffix.lower()
    found = next((f for f, ends in FORMATS.items() if suffix in ends), None)
    if fmt is not None and fmt not in FORMATS:
        raise UserError(f"the format is one of {', '.join(FORMATS)}, got {fmt!r}.")
    if found is None:
        want = FORMATS[fmt] if fmt else tuple(s for v in FORMATS.values() for s in v)
        raise UserError(f"the output file must end in {' or '.join(want)}, got {str(path)!r}.")
    if fmt is not None and fmt != found:
        raise UserError(f"format {fmt} is written to a file ending in {' or '.join(FORMATS[fmt])}, "
                        f"got {str(path)!r}.")
    return found


def write_poses(poses, path: str | Path, fmt: str | None = None, name: str = "lifelike-mj run",
                parameters: dict | None = None, rotations: str = "short", tolerance=(0.0005, 0.5),
                rigs: list | None = None) -> Path:
    """Write recorded poses (:class:`~lifelike_mj.export.poses.Poses`) in ``fmt`` (default: from the ending of
    ``path``; :data:`FORMATS`), atomically, with the provenance and ``parameters``; each body keyed within
    ``tolerance`` (m, deg) of every sample (:mod:`lifelike_mj.export.keys`); ``rigs``: the creatures as skinned
    meshes on skeletons (:mod:`lifelike_mj.export.rig`; glTF skins, UsdSkel), else the MJCF's geoms. Returns the path."""
    fmt = format_of(path, fmt)
    if fmt in ("glb", "gltf"):
        from lifelike_mj.export.gltf import write_gltf

        return write_gltf(poses, path, name, parameters, rotations, tolerance, rigs)
    if fmt == "usd":
        from lifelike_mj.export.usd import write_usd

        return write_usd(poses, path, name, parameters, tolerance, rigs)
    from lifelike_mj.export.html import write_html

    return write_html(poses, path, name, parameters, rotations, tolerance, rigs)
