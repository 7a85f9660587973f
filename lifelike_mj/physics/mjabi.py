"""Native access to MuJoCo's C structs for compiled (numba) callbacks and stepping loops.

MuJoCo calls a passive-force callback as ``void cb(const mjModel* m, mjData* d)``. A numba
``@cfunc`` receives those two raw pointers and must find ``d->qpos``, ``d->qfrc_passive`` ...
by itself. We compute the byte offset of every ``mjtNum*`` field of ``mjData`` from the header
that the installed ``mujoco`` wheel ships (``mujoco/include/mujoco/mjdata.h``): the pointer block
follows ``time``, ``energy[2]``, ``buffer`` and ``arena`` in declaration order. The offset of
``time`` is found in a live ``MjData``, and every offset we use is then verified against the
addresses of the arrays that the Python bindings expose; a mismatch (a MuJoCo version whose
layout we do not understand) raises instead of corrupting memory.

The same module declares MuJoCo's functions to numba (:data:`mj_step`, :data:`mj_applyFT`,
:data:`mj_objectVelocity`, :data:`mj_ray`, :data:`mj_fullM`, :data:`mj_rne`) as external functions
resolved by name in ``libmujoco``
(the very library the bindings loaded), so compiled code calls them without Python.

**Caching.** A compiled function is cached on disk (numba ``cache=True``) only if it holds nothing
that belongs to one process: the functions above are linked by name, not by address, and the
offsets are passed as an argument (:func:`offsets_tuple`), never baked in, so cached code stays right
when the MuJoCo version (and the layout of ``mjData``) changes. The one function that cannot take
them as an argument, the ``cfunc`` MuJoCo calls with ``(m, d)``, is a two-line trampoline that
passes the offsets to a cached kernel; it is cached under a name that carries a hash of the MuJoCo
version and the offsets (:func:`cached_cfunc`), so another layout compiles (and caches) its own.
"""

from __future__ import annotations

import ctypes
import functools
import glob
import hashlib
import os
import re
import types as pytypes

import mujoco
import numpy as np
from llvmlite import binding as llvm
from llvmlite import ir
from numba import carray, cfunc, njit, types
from numba.core import cgutils
from numba.extending import intrinsic

#: Fields of mjData that compiled code reads or writes.
USED_FIELDS = ("qpos", "qvel", "qfrc_passive", "userdata", "xpos", "xmat", "xipos", "ctrl")


@intrinsic
def voidptr_from_int(typingctx, address):
    """Numba intrinsic: integer address -> ``void*``."""
    sig = types.voidptr(address)

    def codegen(context, builder, signature, args):
        return builder.inttoptr(args[0], cgutils.voidptr_t)

    return sig, codegen


@intrinsic
def int_from_voidptr(typingctx, pointer):
    """Numba intrinsic: ``void*`` -> integer address (int64)."""
    sig = types.int64(pointer)

    def codegen(context, builder, signature, args):
        return builder.ptrtoint(args[0], ir.IntType(64))

    return sig, codegen


@njit(cache=True, inline="always")
def ptr_at(address):
    """Compiled: the pointer (as uint64) stored at ``address`` (e.g. an ``mjData`` field)."""
    return carray(voidptr_from_int(address), (1,), np.uint64)[0]


@njit(cache=True, inline="always")
def f64_at(address, n):
    """Compiled: a float64 array view of ``n`` values at ``address``."""
    return carray(voidptr_from_int(address), (n,), np.float64)


def _mujoco_dir() -> str:
    return os.path.dirname(mujoco.__file__)


@functools.lru_cache(maxsize=1)
def libmujoco() -> ctypes.CDLL:
    """The shared ``libmujoco`` shipped in the ``mujoco`` wheel (already loaded by the bindings)."""
    candidates = sorted(glob.glob(os.path.join(_mujoco_dir(), "libmujoco.so*")))
    candidates += sorted(glob.glob(os.path.join(_mujoco_dir(), "libmujoco*.dylib")))
    candidates += sorted(glob.glob(os.path.join(_mujoco_dir(), "mujoco*.dll")))
    if not candidates:
        raise RuntimeError("could not find the libmujoco shared library inside the mujoco package")
    lib = ctypes.CDLL(candidates[0])
    vp, ci = ctypes.c_void_p, ctypes.c_int
    lib.mj_step.argtypes = [vp, vp]
    lib.mj_step.restype = None
    lib.mj_forward.argtypes = [vp, vp]
    lib.mj_forward.restype = None
    lib.mj_applyFT.argtypes = [vp, vp, vp, vp, vp, ci, vp]
    lib.mj_applyFT.restype = None
    lib.mj_objectVelocity.argtypes = [vp, vp, ci, ci, vp, ci]
    lib.mj_objectVelocity.restype = None
    lib.mj_kinematics.argtypes = [vp, vp]
    lib.mj_kinematics.restype = None
    lib.mj_fullM.argtypes = [vp, vp, vp]
    lib.mj_fullM.restype = None
    lib.mj_rne.argtypes = [vp, vp, ci, vp]
    lib.mj_rne.restype = None
    lib.mj_ray.argtypes = [vp, vp, vp, vp, vp, ctypes.c_ubyte, ci, vp, vp]  # ... flg_static, bodyexclude, geomid, normal
    lib.mj_ray.restype = ctypes.c_double
    return lib


@functools.lru_cache(maxsize=1)
def _pointer_field_order() -> tuple[str, ...]:
    header = os.path.join(_mujoco_dir(), "include", "mujoco", "mjdata.h")
    with open(header, encoding="utf-8") as fh:
        text = fh.read()
    start = text.index("struct mjData_ {")
    body = text[start : text.index("} mjData;", start)]
    after_arena = body[body.index("void*   arena;") :]
    names = []
    for line in after_arena.splitlines()[1:]:
        code = line.split("//")[0].strip()
        if not code:
            continue
        match = re.fullmatch(r"[A-Za-z_][A-Za-z0-9_]*\s*\*\s*([A-Za-z_][A-Za-z0-9_]*)\s*;", code)
        if match is None:
            break  # first non-pointer field ends the block
        names.append(match.group(1))
    return tuple(names)


@functools.lru_cache(maxsize=1)
def _time_offset() -> int:
    m = mujoco.MjModel.from_xml_string("<mujoco><worldbody/></mujoco>")
    d = mujoco.MjData(m)
    probe = 7.123456789012345e-3
    d.time = probe
    chunk = 4096  # doubles; mjData is ~160 kB in MuJoCo 3-4, the scan stops at the first hit
    for start in range(0, 1 << 20, chunk):
        raw = np.frombuffer((ctypes.c_double * chunk).from_address(d._address + 8 * start), dtype=np.float64)
        hits = np.nonzero(raw == probe)[0]
        if len(hits):
            return (start + int(hits[0])) * 8
    raise RuntimeError("could not locate mjData.time in this MuJoCo build")


@functools.lru_cache(maxsize=1)
def data_offsets() -> dict[str, int]:
    """Byte offsets of ``time`` and the pointer fields of ``mjData`` (see module docstring)."""
    offsets = {"time": _time_offset()}
    first_pointer = offsets["time"] + 8 * 3 + 8 * 2  # time, energy[2], buffer, arena
    for i, name in enumerate(_pointer_field_order()):
        offsets[name] = first_pointer + 8 * i
    return offsets


def verify_offsets(d: mujoco.MjData, fields=USED_FIELDS) -> None:
    """Raise ``RuntimeError`` unless each field's pointer in ``d`` equals the bound array's address."""
    offsets = data_offsets()
    for name in fields:
        array = getattr(d, name)
        if array.size == 0:
            continue
        stored = ctypes.c_uint64.from_address(d._address + offsets[name]).value
        if stored != array.ctypes.data:
            raise RuntimeError(f"mjData layout check failed for field {name!r}")
    t = d.time
    d.time = 0.0 if t else 1.0
    ok = ctypes.c_double.from_address(d._address + offsets["time"]).value == d.time
    d.time = t
    if not ok:
        raise RuntimeError("mjData layout check failed for field 'time'")


#: Positions of the fields in :func:`offsets_tuple`.
O_TIME, O_QPOS, O_QVEL, O_QFRC, O_UD, O_XPOS, O_XMAT, O_XIPOS, O_CTRL = range(9)


@functools.lru_cache(maxsize=1)
def offsets_tuple() -> tuple[int, ...]:
    """Byte offsets in ``mjData`` of ``time, qpos, qvel, qfrc_passive, userdata, xpos, xmat, xipos, ctrl``
    (index with :data:`O_TIME` ...): the argument compiled kernels read ``mjData`` with."""
    o = data_offsets()
    return tuple(int(o[k]) for k in ("time", "qpos", "qvel", "qfrc_passive", "userdata", "xpos", "xmat", "xipos",
                                     "ctrl"))


def _external(name: str, sig):
    """MuJoCo's C function ``name`` for numba, linked by symbol name (cache-safe)."""
    llvm.add_symbol(name, ctypes.cast(getattr(libmujoco(), name), ctypes.c_void_p).value)
    return types.ExternalFunction(name, sig)


_vp_t, _i32 = types.voidptr, types.int32
#: ``void mj_step(const mjModel* m, mjData* d)``
mj_step = _external("mj_step", types.void(_vp_t, _vp_t))
#: ``void mj_applyFT(m, d, force[3], torque[3], point[3], int body, qfrc_target)``
mj_applyFT = _external("mj_applyFT", types.void(_vp_t, _vp_t, _vp_t, _vp_t, _vp_t, _i32, _vp_t))
#: ``void mj_objectVelocity(m, d, int objtype, int objid, res[6], int flg_local)``
mj_objectVelocity = _external("mj_objectVelocity", types.void(_vp_t, _vp_t, _i32, _i32, _vp_t, _i32))
#: ``void mj_fullM(m, d, mjtNum* dst)``: the dense ``nv x nv`` inertia matrix (row-major)
mj_fullM = _external("mj_fullM", types.void(_vp_t, _vp_t, _vp_t))
#: ``void mj_rne(m, d, int flg_acc, mjtNum* result)``: ``M qacc + c`` (``flg_acc = 0``: the bias ``c``)
mj_rne = _external("mj_rne", types.void(_vp_t, _vp_t, _i32, _vp_t))
#: ``mjtNum mj_ray(m, d, pnt[3], vec[3], geomgroup, mjtBool flg_static, int bodyexclude, geomid[1], normal[3])``
mj_ray = _external("mj_ray", types.float64(_vp_t, _vp_t, _vp_t, _vp_t, _vp_t, types.uint8, _i32, _vp_t, _vp_t))


def layout_tag() -> str:
    """A short hash of the MuJoCo version and the ``mjData`` offsets this process uses."""
    text = f"{mujoco.__version__}:{offsets_tuple()}"
    return hashlib.sha256(text.encode()).hexdigest()[:12]


def cached_cfunc(fn, name: str):
    """``numba.cfunc(void(void*, void*), cache=True)`` of the plain function ``fn(m, d)`` (a passive
    callback's trampoline, which reads this process's offsets from its module's globals), compiled
    under the name ``name + "_" + layout_tag()``: cached on disk, and never reused for another layout."""
    tagged = f"{name}_{layout_tag()}"
    copy = pytypes.FunctionType(fn.__code__, fn.__globals__, tagged, fn.__defaults__, fn.__closure__)
    copy.__qualname__ = tagged
    return cfunc(types.void(types.voidptr, types.voidptr), cache=True)(copy)


#: Filled in each copy of :func:`_passive_entry` by :func:`compiled_passive`.
_KERNEL = None
_OFFS: tuple[int, ...] = ()


def _passive_entry(m, d):
    # the trampoline MuJoCo calls: this process's offsets into the cached kernel (see compiled_passive)
    _KERNEL(m, d, _OFFS)


def compiled_passive(kernel, name: str):
    """The passive callback MuJoCo calls as ``cb(m, d)`` (a numba ``cfunc``; ``.ctypes`` is the pointer), made of the cached
    kernel ``kernel(m, d, offsets)``: a trampoline that passes this process's :func:`offsets_tuple`,
    cached under ``name`` and the layout's hash (:func:`cached_cfunc`)."""
    g = dict(_passive_entry.__globals__, _KERNEL=kernel, _OFFS=offsets_tuple())
    entry = pytypes.FunctionType(_passive_entry.__code__, g, "_passive_entry")
    return cached_cfunc(entry, f"passive_{name}")
