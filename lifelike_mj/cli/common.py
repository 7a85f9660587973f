"""What every creature's command line shares: the parser that turns usage errors into one sentence,
output as text or ``--json``, and checks of numbers given on the command line."""

from __future__ import annotations

import argparse

from lifelike_mj.errors import UserError


class Parser(argparse.ArgumentParser):
    """An argument parser whose errors are one sentence (exit status 2, no usage block)."""

    def error(self, message: str):  # one sentence, exit 2 (argparse prints usage otherwise)
        raise UserError(f"{message} (see '{self.prog} --help').")


def emit(args: argparse.Namespace, data: dict, human: str) -> None:
    """Print ``data`` as strict indented JSON with ``--json`` (NaN as ``null``, named under ``"undefined"``),
    else the sentence ``human``."""
    from lifelike_mj.io import dumps

    print(dumps(data) if getattr(args, "json", False) else human)


def add_json(p: argparse.ArgumentParser) -> None:
    p.add_argument("--json", action="store_true", help="print the results as JSON")


def seeds(text: str) -> list[int]:
    """``0-4`` or ``0,3,7`` as a list of seeds."""
    try:
        if "-" in text:
            a, b = (int(x) for x in text.split("-"))
            out = list(range(a, b + 1))
        else:
            out = [int(x) for x in text.split(",")]
    except ValueError:
        raise UserError(f"--seeds must look like 0-4 or 0,1,2, got {text!r}.") from None
    if not out or min(out) < 0:
        raise UserError(f"--seeds must name non-negative seeds, got {text!r}.")
    return out
