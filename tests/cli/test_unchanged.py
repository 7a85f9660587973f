"""Behaviour is unchanged by the reorganisation (issue 12): each recorded command line computes what
version 0.1.0 computed, bit for bit (``tests/golden_cases.py``; the records in
``tests/data/golden_cli.json`` were made on commit fd0b398), except the last bits of the boids' measures,
which BLAS computes differently on different processors (``golden_cases.BLAS_REL``)."""

from __future__ import annotations

import json

import pytest
from golden_cases import CASES, GOLDEN, differences, run_case


@pytest.fixture(scope="module")
def golden() -> dict:
    return json.loads(GOLDEN.read_text())


@pytest.mark.parametrize("name", sorted(CASES))
def test_case_computes_what_it_computed(golden, name):
    diff = differences(golden[name], run_case(name), name)
    assert not diff, "\n".join(diff[:20])


def test_differences_sees_a_changed_number():
    assert differences({"a": [1.0, {"b": 2.0}]}, {"a": [1.0, {"b": 2.0 + 2e-16 * 2}]})
    assert not differences({"a": 1.0}, {"a": 1.0, "new": 3})
    # the boids' measures (through BLAS): the last bits may differ, a change of 1e-10 may not
    assert not differences({"x": 0.037379307495051875}, {"x": 0.03737930749505196}, "boids_run/stdout/")
    assert differences({"x": 0.037379307495051875}, {"x": 0.037379307495051875 * (1 + 1e-10)}, "boids_run/stdout/")
    assert differences({"x": 0.5}, {"x": float("nan")}, "boids_run/stdout/")
