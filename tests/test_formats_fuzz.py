"""Every file format against files made wrong in generated ways (hypothesis), from the formats' own descriptions
(their JSON Schemas, docs/schemas/): a value of the wrong type, a number just beyond a bound or far beyond it, a key
missing, an unknown or misspelt key, a list of the wrong length, deep nesting. Whatever the file, its loader either
builds the object or refuses it with one sentence (a ``UserError``), never another exception; and every file the
published schema rejects, the loader refuses. Checkpoints likewise: a real one tampered with (its JSON or its
arrays), then resumed.
"""

from __future__ import annotations

import copy
import json
import tempfile
from pathlib import Path

import numpy as np
import pytest

hypothesis = pytest.importorskip("hypothesis")
jsonschema = pytest.importorskip("jsonschema")
from hypothesis import HealthCheck, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

from lifelike_mj.errors import UserError  # noqa: E402
from lifelike_mj.paths import controllers_dir  # noqa: E402

DOCS = Path(__file__).resolve().parent.parent / "docs" / "schemas"
SETTINGS = settings(max_examples=120, deadline=None, derandomize=True,
                    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])


def _loaders():
    from lifelike_mj.boids.presets import load_grid
    from lifelike_mj.boids.presets import load_preset as boids_preset
    from lifelike_mj.butterfly.controllers import load
    from lifelike_mj.butterfly.flight3d.controllers import load_controller
    from lifelike_mj.cli.scene import check_scene
    from lifelike_mj.fish.params import load_preset as fish_preset

    return {"butterfly-controller": load, "butterfly3d-controller": load_controller, "fish-preset": fish_preset,
            "boids-preset": boids_preset, "boids-grid": load_grid, "scene": check_scene}


#: (format, a shipped file of it): the documents the mutations start from.
EXAMPLES = [("butterfly-controller", "butterfly/simple_rule.json"), ("butterfly-controller", "butterfly/ann_paper.json"),
            ("butterfly-controller", "butterfly/glide.json"), ("butterfly3d-controller", "butterfly3d/monarch.json"),
            ("fish-preset", "fish/B-D.json"), ("fish-preset", "fish/default.json"), ("boids-preset", "boids/5b.json"),
            ("boids-grid", "boids/fig2_grid.json"), ("scene", "examples/scenes/garden.json")]


def _example(name: str) -> Path:
    """A starting document: a shipped file, or the repository's example scene."""
    return DOCS.parent.parent / name if name.startswith("examples/") else controllers_dir() / name


def _schema(fmt: str) -> dict:
    return json.loads((DOCS / f"{fmt}.schema.json").read_text())


def _branches(schema: dict, doc) -> list[dict]:
    """``schema`` and the ``then`` of each ``allOf`` branch whose ``if`` ``doc`` satisfies (how the butterfly
    controller's parameters depend on its type)."""
    out = [schema]
    for sub in schema.get("allOf", []):
        if "if" in sub and jsonschema.Draft202012Validator(sub["if"]).is_valid(doc):
            out.append(sub.get("then", {}))
    return out


def _places(schema: dict, doc, path=()) -> list[tuple[tuple, dict, object]]:
    """Every place of ``doc`` with the schema that describes it: ``(path, subschema, value)``."""
    out = [(path, schema, doc)]
    if isinstance(doc, dict):
        props: dict = {}
        for b in _branches(schema, doc):
            props.update(b.get("properties", {}))
        for k, v in doc.items():
            sub = props.get(k)
            if isinstance(sub, dict):
                out += _places(sub, v, (*path, k))
    elif isinstance(doc, list) and isinstance(schema.get("items"), dict):
        for i in sorted({0, len(doc) // 2, len(doc) - 1}):
            if 0 <= i < len(doc):
                out += _places(schema["items"], doc[i], (*path, i))
    return out


JUNK = st.one_of(st.none(), st.booleans(), st.text(max_size=6), st.integers(-(10**40), 10**40),
                 st.floats(allow_nan=False, allow_infinity=False), st.lists(st.integers(-3, 3), max_size=3),
                 st.dictionaries(st.text(max_size=4), st.integers(), max_size=2), st.just(2.0), st.just("1e3"))


def _set(doc, path, value):
    node = doc
    for k in path[:-1]:
        node = node[k]
    node[path[-1]] = value


@st.composite
def mutated(draw, fmt: str, example: dict):
    """``example`` changed at one place chosen from its schema: a wrong value, a number beyond a bound, a key removed,
    an unknown or misspelt key added, a list shortened or lengthened, or a value nested deep."""
    doc = copy.deepcopy(example)
    places = _places(_schema(fmt), doc)
    path, sub, value = draw(st.sampled_from(places))
    kind = draw(st.sampled_from(["junk", "bound", "drop", "unknown", "length", "deep"]))
    if kind == "bound" and any(b in sub for b in ("minimum", "maximum", "exclusiveMinimum", "exclusiveMaximum")) and path:
        lo = sub.get("minimum", sub.get("exclusiveMinimum"))
        hi = sub.get("maximum", sub.get("exclusiveMaximum"))
        step = draw(st.sampled_from([1e-9, 1e-3, 1.0, 1e6, 1e300]))
        new = (hi + max(step, abs(hi) * 1e-12)) if hi is not None and (lo is None or draw(st.booleans())) \
            else lo - max(step, abs(lo) * 1e-12)
        _set(doc, path, new if sub.get("type") != "integer" else int(min(new, 2**63)) if abs(new) < 1e18 else 10**20)
    elif kind == "drop" and isinstance(value, dict) and value:
        value.pop(draw(st.sampled_from(sorted(value))))
    elif kind == "unknown" and isinstance(value, dict):
        keys = sorted(value) or ["x"]
        k = draw(st.sampled_from(keys))
        typo = draw(st.sampled_from([k[::-1], k + "_", k[:-1], k.upper(), "colour"]))
        if typo not in value:
            value[typo] = value.get(k, 1)
    elif kind == "length" and isinstance(value, list):
        if value and draw(st.booleans()):
            value.pop()
        else:
            value.append(value[-1] if value else 0)
    elif kind == "deep" and path:
        _set(doc, path, json.loads("[" * 400 + "]" * 400))
    elif path:
        _set(doc, path, draw(JUNK))
    else:
        doc = draw(JUNK)
    return doc


def _check(fmt: str, doc) -> None:
    """The loader of ``fmt`` builds ``doc`` or refuses it in one sentence; it refuses what the published schema
    rejects."""
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "file.json"
        path.write_text(json.dumps(doc))
        try:
            _loaders()[fmt](path)
        except UserError as exc:
            assert "\n" not in str(exc) and str(exc).endswith("."), str(exc)
            return
        jsonschema.validate(doc, _schema(fmt))  # accepted: so the published schema accepts it too


@pytest.mark.parametrize("fmt, example", EXAMPLES, ids=[e[1] for e in EXAMPLES])
def test_a_file_made_wrong_is_built_or_refused_in_one_sentence(fmt, example):
    doc = json.loads(_example(example).read_text())

    @SETTINGS
    @given(mutated(fmt, doc))
    def run(bad):
        _check(fmt, bad)

    run()


@pytest.mark.parametrize("fmt, example", EXAMPLES, ids=[e[1] for e in EXAMPLES])
def test_the_shipped_files_load_and_a_beyond_bound_number_is_refused(fmt, example):
    """The starting points load; and each bounded number of each, pushed just past its bound, is refused (so the
    generated cases above include refusals, and the schema's bounds are the loader's)."""
    doc = json.loads(_example(example).read_text())
    _loaders()[fmt](_example(example))
    pushed = 0
    for path, sub, _v in _places(_schema(fmt), doc):
        hi = sub.get("maximum")
        if hi is None or not path or sub.get("type") not in ("number", "integer"):
            continue
        bad = copy.deepcopy(doc)
        _set(bad, path, hi + 1 if sub.get("type") == "integer" else hi * (1 + 1e-9) + 1e-12)
        with tempfile.TemporaryDirectory() as tmp:
            p = Path(tmp) / "file.json"
            p.write_text(json.dumps(bad))
            with pytest.raises(UserError, match="must be"):
                _loaders()[fmt](p)
        pushed += 1
    assert pushed > 0 or "same_as" in doc  # a preset that names another holds no number


# ---- checkpoints ------------------------------------------------------------------------------------------------


def _checkpoint(tmp: Path, optimizer: str) -> Path:
    from lifelike_mj.evolve import optimize
    from lifelike_mj.evolve.testproblems import Sphere

    ckpt = tmp / f"{optimizer}.ckpt"
    optimize(Sphere(dim=3), optimizer, seed=1, population=6, generations=3, checkpoint=ckpt, progress=False)
    return ckpt


def _resume(ckpt: Path, optimizer: str) -> None:
    from lifelike_mj.evolve import optimize
    from lifelike_mj.evolve.testproblems import Sphere

    optimize(Sphere(dim=3), optimizer, seed=1, population=6, generations=3, checkpoint=ckpt, resume=True,
             progress=False)


def _read(ckpt: Path) -> tuple[dict, dict]:
    with np.load(ckpt, allow_pickle=False) as z:
        arrays = {k: z[k] for k in z.files if k != "meta"}
        return json.loads(z["meta"].tobytes().decode()), arrays


def _write(ckpt: Path, meta, arrays: dict) -> None:
    with open(ckpt, "wb") as fh:
        np.savez(fh, meta=np.frombuffer(json.dumps(meta).encode(), dtype=np.uint8), **arrays)


ARRAYS = st.one_of(st.builds(np.zeros, st.sampled_from([(0,), (1,), (2, 2), (6, 3), (3, 6), (6,), (7, 3), (3,),
                                                        (2, 3, 4)])),
                   st.builds(lambda s: np.full(s, np.nan), st.sampled_from([(6, 3), (6,), (3,)])),
                   st.builds(lambda s: np.ones(s, dtype=np.int8), st.sampled_from([(6, 3), (6,)])),
                   st.builds(lambda s: np.array(["a"] * s), st.sampled_from([3, 6])))


@pytest.fixture(scope="module")
def checkpoints(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("ckpt")
    return {opt: _read(_checkpoint(tmp, opt)) for opt in ("rcga", "cmaes", "crs2")}


@pytest.mark.parametrize("optimizer", ["rcga", "cmaes", "crs2"])
def test_a_tampered_checkpoint_resumes_or_is_refused_in_one_sentence(optimizer, checkpoints):
    from lifelike_mj.evolve.checkpoint import json_schema

    meta0, arrays0 = checkpoints[optimizer]
    schema = json_schema()
    refused = []

    @SETTINGS
    @given(st.data())
    def run(data):
        meta, arrays = copy.deepcopy(meta0), {k: v.copy() for k, v in arrays0.items()}
        if data.draw(st.booleans()) and arrays:  # an array of another shape or kind
            arrays[data.draw(st.sampled_from(sorted(arrays)))] = data.draw(ARRAYS)
        else:
            path, _sub, value = data.draw(st.sampled_from(_places(schema, meta)))
            kind = data.draw(st.sampled_from(["junk", "drop", "unknown", "missing array"]))
            if kind == "drop" and isinstance(value, dict) and value:
                value.pop(data.draw(st.sampled_from(sorted(value))))
            elif kind == "unknown" and isinstance(value, dict):
                value["extra"] = 1
            elif kind == "missing array" and path:
                _set(meta, path, {"__array__": "a99"})
            elif path:
                _set(meta, path, data.draw(JUNK))
            else:
                meta = data.draw(JUNK)
        with tempfile.TemporaryDirectory() as tmp:
            ckpt = Path(tmp) / "run.ckpt"
            _write(ckpt, meta, arrays)
            try:
                _resume(ckpt, optimizer)
            except UserError as exc:
                assert "\n" not in str(exc), str(exc)
                refused.append(str(exc))

    run()
    assert refused  # the tampering was seen, at least some of the time
