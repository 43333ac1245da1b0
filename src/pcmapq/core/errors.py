"""The two ways a run can fail, each with its exit code; the refusal of a map of another
place (an evaluation error whose verdict a table keeps) and of settings a map of its kind
cannot follow (bad input whatever the map holds)."""


class InputError(Exception):
    """Bad input or usage: a file that cannot be read or makes no sense. Exit code 2.

    The message is one line that names the file and the problem.
    """

    exit_code = 2


class EvaluationError(Exception):
    """The inputs were read but could not be evaluated (e.g. alignment failed). Exit code 1."""

    exit_code = 1


class Refused(EvaluationError):
    """A map that does not seem to show the truth's place, refused (exit code 1): its
    ``verdict`` ("another place") goes into a batch's row beside the one-line reason."""

    verdict = "another place"


class SettingsRefused(InputError):
    """Settings a map of its kind cannot follow (a footprint rule it has no cells or views
    for), whatever the map holds: bad input, exit code 2. A run that scores many maps of one
    kind (``pcmapq track``) stops at it, as ``pcmapq eval`` does, rather than noting it at
    each."""
