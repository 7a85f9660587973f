"""Errors a user can cause: the CLI prints their message as one sentence and exits with 2."""


class UserError(ValueError):
    """Bad input from the user (unknown name, malformed file, unphysical value)."""
