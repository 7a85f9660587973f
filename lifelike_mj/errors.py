"""Errors a user can cause: the CLI prints their message as one sentence and exits with 2."""


class UserError(ValueError):
    """Bad input from the user (unknown name, malformed file, unphysical value)."""


class Diverged(UserError):
    """A simulation became unstable (a runaway speed, NaN): the message names the cause and the step.

    ``step`` is the step (counted from the start) at which it was detected."""

    def __init__(self, message: str, step: int) -> None:
        super().__init__(message)
        self.step = int(step)
