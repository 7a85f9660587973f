"""Errors a user can cause: the CLI prints their message as one sentence and exits with 2."""


class UserError(ValueError):
    """Bad input from the user (unknown name, malformed file, unphysical value)."""


class Diverged(UserError):
    """A simulation became unstable (a runaway speed, NaN): the message names the cause and the step.

    ``step`` is the step (counted from the start) at which it was detected."""

    def __init__(self, message: str, step: int) -> None:
        super().__init__(message)
        self.step = int(step)


class UnknownName(UserError, TypeError):
    """A misspelt or unknown name (an option, a parameter, a keyword argument): the message names the closest
    known one. A :class:`TypeError` too, as Python's own error for an unexpected keyword argument is."""


def unknown_name(what: str, name: object, known, tail: str = "") -> UnknownName:
    """The error for an unknown ``name`` among ``known``: ``"{what} 'nme' {tail} (did you mean 'name'?)."``, or
    the list of known names when none is close."""
    import difflib

    known = [str(k) for k in known]
    close = difflib.get_close_matches(str(name), known, n=1, cutoff=0.6)
    hint = f" (did you mean {close[0]!r}?)" if close else f"; known: {', '.join(known) or 'none'}"
    return UnknownName(f"{what} {name!r}{' ' + tail if tail else ''}{hint}.")


def check_names(given, known, what: str) -> None:
    """Raise :func:`unknown_name` for the first of ``given`` (names, or a mapping's keys) not in ``known``."""
    known = list(known)
    for name in given:
        if name not in known:
            raise unknown_name(what, name, known)
